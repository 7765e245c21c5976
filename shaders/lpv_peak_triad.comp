#version 460
// Peak copy bandwidth of the device for bench/gpu_propagation_bench.cpp: the STREAM triad
// a = b + s c over vec4 buffers (2 loads and 1 store, 48 bytes per lane). TEXEL = 1 reads
// b and c through uniform texel buffers, as the propagation kernel reads its fields.
layout(local_size_x = 64) in;
layout(constant_id = 0) const int TEXEL = 0;

layout(push_constant) uniform PushBlock { int count; float scale; } push;
layout(std430, binding = 0) writeonly buffer A { vec4 a[]; };
layout(std430, binding = 1) readonly buffer B { vec4 b[]; };
layout(std430, binding = 2) readonly buffer C { vec4 c[]; };
layout(binding = 3) uniform samplerBuffer bTexels;
layout(binding = 4) uniform samplerBuffer cTexels;

void main() {
  const int i = int(gl_GlobalInvocationID.x);
  if (i >= push.count) return;
  if (TEXEL == 1)
    a[i] = texelFetch(bTexels, i) + push.scale * texelFetch(cTexels, i);
  else
    a[i] = b[i] + push.scale * c[i];
}
