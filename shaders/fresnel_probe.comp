#version 460
// Evaluates the GLSL Fresnel and Snell twins (shaders/fresnel.glsl) for the test that
// compares them with volume/core/fresnel.h: per case, input (unit incident direction, eta)
// against the normal +z, output (refracted direction, reflectance).
#extension GL_GOOGLE_include_directive : require
#include "shaders/fresnel.glsl"

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Cases { vec4 cases[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Results { vec4 results[]; };
layout(push_constant) uniform Push { uint count; } push;

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= push.count) return;
  const vec3 incident = cases[i].xyz;
  const float eta = cases[i].w;
  const vec3 normal = vec3(0.0, 0.0, 1.0);
  results[i] = vec4(refractInto(incident, normal, eta), fresnelReflectance(-dot(incident, normal), eta));
}
