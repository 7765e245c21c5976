#version 460
// Shadow-map rasterization, one view of device_shared/shadow_map_shared.h per draw: vertices
// pulled from the mesh buffers (3 per triangle, non-indexed), projected so that pixel
// centres are exactly the texel rays of sslpv::ShadowView::texelRay.
#extension GL_GOOGLE_include_directive : require
#include "device_shared/shadow_map_shared.h"

layout(std430, set = 0, binding = 0) readonly buffer Positions { vec4 positions[]; };
layout(std430, set = 0, binding = 1) readonly buffer Indices { uint indices[]; };
layout(std430, set = 0, binding = 2) readonly buffer Views { GpuShadowView views[]; };
layout(push_constant) uniform Push { ShadowRasterPush push; };

layout(location = 0) flat out uint triangleId;

void main() {
  const GpuShadowView view = views[push.viewIndex];
  const vec3 p = positions[indices[gl_VertexIndex]].xyz - view.origin.xyz;
  const float a = dot(p, view.right.xyz), b = dot(p, view.up.xyz), c = dot(p, view.forward.xyz);
  // A texel's ray has (a, b) / c = (u, v) (perspective) or (a, b) = (u, v) (orthographic),
  // u, v = (2 (i + 0.5) / size - 1) * extent: dividing by the extent gives the pixel centre
  // in normalized device coordinates. Depth is reversed: nearer is larger.
  const float extent = view.forward.w;
  if (view.origin.w == SSLPV_SHADOW_PERSPECTIVE)
    gl_Position = vec4(a / extent, b / extent, view.up.w, c);
  else
    gl_Position = vec4(a / extent, b / extent, 1.0 - c / view.up.w, 1.0);
  // 0 stays "no surface" in the cleared image.
  triangleId = uint(gl_VertexIndex) / 3u + 1u;
}
