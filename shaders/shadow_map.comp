#version 460
// Shadow-map resolve, the GPU twin of the per-hit work of sslpv::castShadowMap
// (volume/cpu/shadow_map.cpp): per texel of every view, the texel ray (ShadowView::texelRay),
// its hit on the triangle it crosses (the rasterized one or, within the rasterizer's
// snapping of an edge, a neighbour: shaders/ray_triangle_pick.glsl; for a texel the
// rasterizer left empty, one its neighbouring texels rasterized), the outward
// geometric normal, the light arriving (I dω or E dA, nothing outside a spot's cone), Fresnel transmittance and
// the refracted direction, written as one GpuFluxSample (misses: all zero).
#extension GL_GOOGLE_include_directive : require
#include "device_shared/flux_sample_shared.h"
#include "shaders/fresnel.glsl"
#include "device_shared/shadow_map_shared.h"

layout(local_size_x = SSLPV_SHADOW_RESOLVE_GROUP, local_size_y = SSLPV_SHADOW_RESOLVE_GROUP) in;

layout(std430, set = 0, binding = 0) readonly buffer Positions { vec4 positions[]; };
layout(std430, set = 0, binding = 1) readonly buffer Indices { uint indices[]; };
layout(std430, set = 0, binding = 2) readonly buffer Views { GpuShadowView views[]; };
// 1-based, 0 = none: the triangle the texel's ray crosses.
layout(std430, set = 0, binding = 3) writeonly buffer Triangles { uint triangles[]; };
layout(std430, set = 0, binding = 4) writeonly buffer Samples { GpuFluxSample samples[]; };
layout(std430, set = 0, binding = 5) readonly buffer VertexFans { uint vertexFans[]; };
// 1-based, 0 = none: the nearest triangle the rasterizer found at each texel.
layout(std430, set = 0, binding = 6) readonly buffer RasterTriangles { uint rasterTriangles[]; };

#include "shaders/ray_triangle_pick.glsl"

void main() {
  const GpuShadowView view = views[gl_WorkGroupID.z];
  const uint size = view.texels.x;
  const uvec2 texel = gl_GlobalInvocationID.xy;
  if (texel.x >= size || texel.y >= size) return;
  const uint index = view.texels.y + texel.y * size + texel.x;

  GpuFluxSample s;
  s.positionValid = vec4(0.0);
  s.normal = vec4(0.0);
  s.direction = vec4(0.0);
  s.flux = vec4(0.0);
  // The texel ray, as ShadowView::texelRay computes it.
  vec3 origin = view.origin.xyz, dir;
  float weight;
  if (view.origin.w == SSLPV_SHADOW_PERSPECTIVE) {
    const float tanHalf = view.forward.w;
    const float u = (2.0 * (float(texel.x) + 0.5) / float(size) - 1.0) * tanHalf;
    const float v = (2.0 * (float(texel.y) + 0.5) / float(size) - 1.0) * tanHalf;
    const vec3 d = view.forward.xyz + u * view.right.xyz + v * view.up.xyz;
    const float len = length(d);
    const float cosTheta = 1.0 / len;
    dir = d / len;
    weight = view.right.w * cosTheta * cosTheta * cosTheta;
  } else {
    const float side = view.right.w, halfSize = view.forward.w;
    const float u = (float(texel.x) + 0.5) * side - halfSize, v = (float(texel.y) + 0.5) * side - halfSize;
    origin += u * view.right.xyz + v * view.up.xyz;
    dir = view.forward.xyz;
    weight = side * side;
  }
  const uint id = rasterTriangles[index];
  uint triangle = id != 0u ? pickCrossedTriangle(origin, dir, id - 1u) : SSLPV_NO_TRIANGLE;
  if (id == 0u) {
    // Just outside the silhouette as the rasterizer snapped it, the exact ray may still
    // cross a triangle (the CPU's ray caster then hits it): one that a neighbouring texel
    // rasterized, or one sharing a vertex with it (pickCrossedTriangle's search).
    float nearest = 3.0e38;
    for (int k = 0; k < 4; ++k) {
      const ivec2 n = ivec2(texel) + ivec2(k == 0 ? -1 : k == 1 ? 1 : 0, k == 2 ? -1 : k == 3 ? 1 : 0);
      if (n.x < 0 || n.y < 0 || n.x >= int(size) || n.y >= int(size)) continue;
      const uint neighbour = rasterTriangles[view.texels.y + uint(n.y) * size + uint(n.x)];
      if (neighbour == 0u) continue;
      const uint candidate = pickCrossedTriangle(origin, dir, neighbour - 1u);
      if (candidate == SSLPV_NO_TRIANGLE) continue;
      const uvec3 w = triangleVertices(candidate);
      const vec3 p0 = positions[w.x].xyz;
      const vec3 ng = cross(positions[w.y].xyz - p0, positions[w.z].xyz - p0);
      const float t = dot(p0 - origin, ng) / dot(dir, ng);
      if (t > 0.0 && t < nearest) {
        nearest = t;
        triangle = candidate;
      }
    }
  }
  triangles[index] = triangle == SSLPV_NO_TRIANGLE ? 0u : triangle + 1u;
  // A ray just outside the silhouette: read triangle 0's vertices harmlessly, inject nothing.
  const bool crossed = triangle != SSLPV_NO_TRIANGLE;
  if (!crossed) triangle = 0u;
  const vec3 v0 = positions[indices[3u * triangle]].xyz;
  const vec3 v1 = positions[indices[3u * triangle + 1u]].xyz;
  const vec3 v2 = positions[indices[3u * triangle + 2u]].xyz;
  // Embree's geometric normal, (v1 - v0) x (v2 - v0): outward for counter-clockwise
  // triangles seen from outside (RayHit::normal).
  const vec3 ng = cross(v1 - v0, v2 - v0);
  const vec3 n = normalize(ng);
  const float cosI = -dot(dir, n);
  // Grazing or from inside: no light enters here (also rejects degenerate triangles).
  const vec3 power = dot(dir, view.coneAxis.xyz) < view.power.w ? vec3(0.0) : view.power.rgb * weight;
  if (crossed && cosI > 0.0 && power != vec3(0.0)) {
    const float t = dot(v0 - origin, ng) / dot(dir, ng);
    const float eta = view.coneAxis.w;
    const float transmittance = 1.0 - fresnelReflectance(cosI, eta);
    s.positionValid = vec4(origin + t * dir, 1.0);
    s.normal = vec4(n, 0.0);
    s.direction = vec4(refractInto(dir, n, eta), 0.0);
    s.flux = vec4(power * transmittance, 0.0);
  }
  samples[index] = s;
}
