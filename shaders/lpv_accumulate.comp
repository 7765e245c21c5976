#version 460
// Adds the last step's light to the accumulated grid when that step did not: the
// propagation kernels accumulate two steps at a time (every other step).
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;

#include "shaders/lpv_step_common.glsl"

void main() {
  dims = ivec3(push.dimsX, push.dimsY, push.dimsZ);
  const uint index = gl_GlobalInvocationID.x;
  const uint cellCount = uint(dims.x * dims.y * dims.z);
  if (index >= cellCount) return;
  const ivec3 cell = ivec3(int(index) % dims.x, (int(index) / dims.x) % dims.y, int(index) / (dims.x * dims.y));
  // Only interior cells change during propagation (inactive ones hold zero).
  if (!interior(cell)) return;
  for (int ch = 0; ch < 3; ++ch) accumulated[3 * index + ch] += source[3 * index + ch];
}
