#version 460
// GPU twin of the per-pixel work of sslpv::shadeImage (volume/cpu/shade.cpp), on the
// triangle the rasterizer found nearest at each pixel centre (shaders/shade.vert/.frag),
// or the neighbour the exact ray crosses (shaders/ray_triangle_pick.glsl):
// the pixel's camera ray meets the triangle's plane; the accumulated LPV is read half a
// cell inside the surface (a full cell when no active cell is near) with the
// coverage-weighted active trilinear weights of activeTrilinearWeights; radiance
// L = T(θo)/η² · (1/(Aπ)) ∫_H G h I(ω) dω per channel, G the cell's exit gain and h its
// exit angular shape (volume/calibration/exit_law.h; 1 in the seed scheme), plus the calibrated
// scheme's single-scattering term (volume/cpu/single_scattering.h) where it is bound.
// Output: one vec4 per pixel, row 0 at
// the top, (radiance, 1) on the surface (black where the ray leaves from inside or no
// active cell is near), (0, 0, 0, 0) for the background.
#extension GL_GOOGLE_include_directive : require
#include "device_shared/flux_sample_shared.h"
#include "shaders/fresnel.glsl"
#include "device_shared/shade_shared.h"
#include "device_shared/shadow_map_shared.h"
#include "device_shared/lpv_constants.h"

#define SSLPV_CELL_COVERAGE_BINDING 3
#include "shaders/cell_coverage.glsl"

layout(local_size_x = SSLPV_SHADE_GROUP_X, local_size_y = SSLPV_SHADE_GROUP_Y) in;

layout(std430, set = 0, binding = 0) readonly buffer Positions { vec4 positions[]; };
layout(std430, set = 0, binding = 1) readonly buffer Indices { uint indices[]; };
// The accumulated light field: 3 vec4 per cell, (c0, c1x, c1y, c1z) per channel.
layout(std430, set = 0, binding = 2) readonly buffer Field { vec4 field[]; };
// Per pixel, 1-based, 0 = none: the rasterized triangle in, the one the pixel's ray
// crosses out (GpuShader::readTriangles).
layout(std430, set = 0, binding = 4) buffer Triangles { uint triangles[]; };
layout(std430, set = 0, binding = 5) writeonly buffer Radiance { vec4 radiance[]; };
layout(std430, set = 0, binding = 6) readonly buffer VertexFans { uint vertexFans[]; };
// Per cell two vec4 (gpu::uploadExitFactors): (StepFactors::exitGain rgb, 0), the
// calibrated scheme's surface coupling, and (StepFactors::reducedAlbedo rgb, 1), or
// (0, 0, 0, 0) without an exit law (seed scheme).
layout(std430, set = 0, binding = 7) readonly buffer ExitFactors { vec4 exitFactors[]; };
// ExitLawTable::shape of the scene's η (gpu::uploadExitLaw).
layout(std430, set = 0, binding = 8) readonly buffer ExitLaw { float exitLaw[]; };
// The single-scattering term's inputs (volume/cpu/single_scattering.h), read only when
// push.gridDims.w (the number of shadow-map views) is above 0: per cell (σt' rgb, 0) and
// (σs' rgb, 0) (gpu::uploadReducedMedium), and the shadow mapper's views and texel records.
layout(std430, set = 0, binding = 9) readonly buffer Medium { vec4 medium[]; };
layout(std430, set = 0, binding = 10) readonly buffer ShadowViews { GpuShadowView shadowViews[]; };
layout(std430, set = 0, binding = 11) readonly buffer ShadowSamples { GpuFluxSample shadowSamples[]; };
layout(push_constant) uniform Push { GpuShadePush push; };

#include "shaders/ray_triangle_pick.glsl"

// Twin of sslpv::exitLawShape (volume/calibration/exit_law.cpp), line for line: bilinear in
// t = sqrt(1 - α') and μo; `j`/`fm` are the μo part, shared by a pixel's cells.
float exitLawShape(float albedo, int j, float fm) {
  const float t = sqrt(clamp(1.0 - albedo, 0.0, 1.0)) * float(SSLPV_EXIT_LAW_ALBEDO_INTERVALS);
  const int k = min(int(t), SSLPV_EXIT_LAW_ALBEDO_INTERVALS - 1);
  const float ft = t - float(k);
  const int low = k * (SSLPV_EXIT_LAW_MU_INTERVALS + 1) + j;
  const int high = low + (SSLPV_EXIT_LAW_MU_INTERVALS + 1);
  const float a = exitLaw[low] + fm * (exitLaw[low + 1] - exitLaw[low]);
  const float b = exitLaw[high] + fm * (exitLaw[high + 1] - exitLaw[high]);
  return a + ft * (b - a);
}

// Twin of reducedMediumAt (volume/cpu/single_scattering.cpp).
bool reducedMediumAt(CellGrid grid, vec3 q, out vec3 extinction, out vec3 scattering) {
  uint cells[8];
  float weights[8];
  const int used = activeTrilinearWeights(grid, q, cells, weights);
  extinction = vec3(0.0);
  scattering = vec3(0.0);
  for (int i = 0; i < used; ++i) {
    extinction += weights[i] * medium[2u * cells[i]].xyz;
    scattering += weights[i] * medium[2u * cells[i] + 1u].xyz;
  }
  return used > 0;
}

// Twin of texelThrough (volume/cpu/single_scattering.cpp): the texel record of view v whose
// ray passes through q (-1 where q is outside the view), and q's distance along that ray.
int texelThrough(uint v, vec3 q, out float along) {
  const GpuShadowView view = shadowViews[v];
  const vec3 d = q - view.origin.xyz;
  float u, w;
  along = 0.0;
  if (view.origin.w == SSLPV_SHADOW_ORTHOGRAPHIC) {
    u = dot(d, view.right.xyz) / view.forward.w;
    w = dot(d, view.up.xyz) / view.forward.w;
    along = dot(d, view.forward.xyz);
  } else {
    const float z = dot(d, view.forward.xyz);
    if (!(z > 0.0)) return -1;
    u = dot(d, view.right.xyz) / (z * view.forward.w);
    w = dot(d, view.up.xyz) / (z * view.forward.w);
    along = length(d);
  }
  if (!(abs(u) <= 1.0 && abs(w) <= 1.0)) return -1;
  const int size = int(view.texels.x);
  const int x = min(size - 1, int(0.5 * (u + 1.0) * float(size)));
  const int y = min(size - 1, int(0.5 * (w + 1.0) * float(size)));
  return int(view.texels.y) + y * size + x;
}

// Twin of the EntryTexel castShadowMap writes (volume/cpu/shadow_map.cpp) from a texel record
// of view v: E T cos θi / cos θt (0 for a miss), the hit's distance along the texel ray,
// cos θi / cos θt, and ∇P = −n / cos θt.
void entryOf(uint v, int record, out vec3 irradiance, out float distance, out float pathScale, out vec3 gradient) {
  const GpuShadowView view = shadowViews[v];
  const GpuFluxSample texel = shadowSamples[record];
  irradiance = vec3(0.0);
  distance = 0.0;
  pathScale = 0.0;
  gradient = vec3(0.0);
  if (texel.positionValid.w == 0.0) return;
  const bool orthographic = view.origin.w == SSLPV_SHADOW_ORTHOGRAPHIC;
  const vec3 toHit = texel.positionValid.xyz - view.origin.xyz;
  const vec3 rayDir = orthographic ? view.forward.xyz : normalize(toHit);
  distance = orthographic ? dot(toHit, view.forward.xyz) : length(toHit);
  const float cosI = -dot(rayDir, texel.normal.xyz);
  const float cosT = -dot(texel.direction.xyz, texel.normal.xyz);
  // The texel's cross-section at the hit (ShadowView::texelRay's weight, times the
  // distance squared for a perspective map).
  const float cosAxis = dot(rayDir, view.forward.xyz);
  const float across = orthographic ? view.right.w * view.right.w
                                    : view.right.w * cosAxis * cosAxis * cosAxis * distance * distance;
  pathScale = cosT > 0.0 ? cosI / cosT : 0.0;
  gradient = cosT > 0.0 ? -texel.normal.xyz / cosT : vec3(0.0);
  irradiance = texel.flux.rgb * (pathScale / across);
}

// Twin of meanDecay (volume/cpu/single_scattering.cpp): the mean of e^{-x u} over u in [0, 1].
float meanDecay(float x) { return abs(x) < 1e-2 ? 1.0 - x * (0.5 - x / 6.0) : (1.0 - exp(-x)) / x; }

// Twin of exponentialSegment (volume/cpu/single_scattering.cpp): ∫_a^b exp(−(c + r s)) ds.
float exponentialSegment(float c, float r, float a, float b) {
  if (!(b > a)) return 0.0;
  const float x = r * (b - a);
  return x >= 0.0 ? exp(-(c + r * a)) * (b - a) * meanDecay(x) : exp(-(c + r * b)) * (b - a) * meanDecay(-x);
}

// Twin of singleScatteringIntegral (volume/cpu/single_scattering.cpp); `end` < 0 stands for ∞.
float singleScatteringIntegral(float sigma, float p0, float k, float end) {
  if (!(sigma > 0.0) || end == 0.0) return 0.0;
  bool infinite = end < 0.0;
  if (infinite && k < 0.0 && p0 >= 0.0) {
    end = p0 / -k;
    infinite = false;
  }
  const float kink = k != 0.0 ? -p0 / k : -1.0;
  float total = 0.0, from = 0.0;
  for (int piece = 0; piece < 2; ++piece) {
    const bool last = piece == 1 || !(kink > 0.0 && (infinite || kink < end));
    const bool toInfinity = last && infinite;
    const float to = last ? end : kink;
    if (!toInfinity && !(to > from)) continue;
    const float inside = toInfinity ? from + 1.0 : 0.5 * (from + to);
    const bool lit = p0 + k * inside > 0.0;
    const float c = lit ? sigma * p0 : 0.0, r = lit ? sigma * (1.0 + k) : sigma;
    total += toInfinity ? exp(-(c + r * from)) / r : exponentialSegment(c, r, from, to);
    from = to;
    if (last) break;
  }
  return total;
}

// Twin of viewRayExit (volume/cpu/single_scattering.cpp); -1 for ∞.
float viewRayExit(CellGrid grid, vec3 p, vec3 into, float extinction) {
  const int across = max(grid.dims.x, max(grid.dims.y, grid.dims.z));
  const int steps = int(min(float(across), ceil(float(SSLPV_SINGLE_SCATTERING_EXIT_DEPTH) / (extinction * grid.cellSize))));
  for (int i = 1; i <= steps; ++i) {
    const ivec3 c = ivec3(floor((p + (float(i) * grid.cellSize) * into - grid.origin) / grid.cellSize));
    if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, grid.dims)) || !(sslpvCellCoverage[cellIndex(grid, c)] > 0.0))
      return (float(i) - 0.5) * grid.cellSize;
  }
  return -1.0;
}

// Twin of singleScatteredRadiance (volume/cpu/single_scattering.cpp).
vec3 singleScatteredRadiance(CellGrid grid, vec3 p, vec3 inward, vec3 into) {
  const float cellSize = grid.cellSize;
  vec3 q = p + 0.5 * cellSize * inward;
  vec3 extinction, scattering;
  if (!reducedMediumAt(grid, q, extinction, scattering)) return vec3(0.0);
  float clearest = 3.0e38, densest = 0.0;
  for (int ch = 0; ch < 3; ++ch)
    if (extinction[ch] > 0.0) {
      clearest = min(clearest, extinction[ch]);
      densest = max(densest, extinction[ch]);
    }
  if (clearest == 3.0e38) return vec3(0.0);
  const float exitAt = viewRayExit(grid, p, into, clearest);
  // An optically thin chord: its light is read at its middle (singleScatteredRadiance).
  if (exitAt >= 0.0 && densest * exitAt < 1.0) q = p + 0.5 * exitAt * into;
  const uint views = uint(push.gridDims.w);
  vec3 sum = vec3(0.0);
  uint lastLight = 0xffffffffu;
  for (uint v = 0u; v < views; ++v) {
    if (shadowViews[v].texels.z == lastLight) continue;  // a cube map's other faces
    float along;
    const int record = texelThrough(v, q, along);
    if (record < 0) continue;
    lastLight = shadowViews[v].texels.z;
    vec3 irradiance, gradient;
    float distance, pathScale;
    entryOf(v, record, irradiance, distance, pathScale, gradient);
    const float below = along - distance;
    if (irradiance == vec3(0.0) || below < -cellSize) continue;
    const float path = max(0.0, below) * pathScale;
    // Where the planar estimate's entry point is not on the surface the light's map sees,
    // q gets none of this light (singleScatteredRadiance).
    const vec3 start = q - path * shadowSamples[record].direction.xyz;
    float startAlong;
    const int entry = texelThrough(v, start, startAlong);
    if (entry < 0) continue;
    vec3 entryIrradiance, entryGradient;
    float entryDistance, entryScale;
    entryOf(v, entry, entryIrradiance, entryDistance, entryScale, entryGradient);
    if (entryIrradiance == vec3(0.0)) continue;
    const float tolerance = max(1.5 * cellSize, 0.5 * below);
    const float onSurface = clamp(2.0 - length(start - shadowSamples[entry].positionValid.xyz) / tolerance, 0.0, 1.0);
    if (!(onSurface > 0.0)) continue;
    const float p0 = dot(p - shadowSamples[record].positionValid.xyz, gradient);
    const float k = dot(gradient, into);
    for (int ch = 0; ch < 3; ++ch)
      sum[ch] += onSurface * irradiance[ch] * scattering[ch] * singleScatteringIntegral(extinction[ch], p0, k, exitAt);
  }
  return sum / (4.0 * float(SSLPV_PI));
}

void main() {
  const uvec2 pixel = gl_GlobalInvocationID.xy;
  const uint width = uint(push.viewport.x), height = uint(push.viewport.y);
  if (pixel.x >= width || pixel.y >= height) return;
  const uint index = pixel.y * width + pixel.x;
  const uint id = triangles[index];
  if (id == 0u) {
    radiance[index] = vec4(0.0);
    return;
  }
  vec4 result = vec4(0.0, 0.0, 0.0, 1.0);
  const float u = (2.0 * (float(pixel.x) + 0.5) / push.viewport.x - 1.0) * push.forward.w;
  const float v = (1.0 - 2.0 * (float(pixel.y) + 0.5) / push.viewport.y) * push.right.w;
  const vec3 dir = normalize(push.forward.xyz + u * push.right.xyz + v * push.up.xyz);
  // Within the rasterizer's snapping of an edge, the neighbour the exact ray crosses.
  const uint triangle = pickCrossedTriangle(push.eye.xyz, dir, id - 1u);
  if (triangle == SSLPV_NO_TRIANGLE) {
    triangles[index] = 0u;
    radiance[index] = vec4(0.0);
    return;
  }
  triangles[index] = triangle + 1u;
  const uint first = 3u * triangle;
  const vec3 v0 = positions[indices[first]].xyz;
  const vec3 v1 = positions[indices[first + 1u]].xyz;
  const vec3 v2 = positions[indices[first + 2u]].xyz;
  // Embree's geometric normal, (v1 - v0) x (v2 - v0), as RayHit::normal.
  const vec3 n = normalize(cross(v1 - v0, v2 - v0));
  const float cosOut = -dot(dir, n);
  // Seen from inside (or a degenerate triangle's NaN normal): black.
  if (cosOut > 0.0) {
    const vec3 p = push.eye.xyz + (dot(n, v0 - push.eye.xyz) / dot(n, dir)) * dir;
    const CellGrid grid = CellGrid(push.gridOrigin.xyz, push.gridOrigin.w, push.gridDims.xyz);
    const float cellSize = push.gridOrigin.w;
    uint cells[8];
    float weights[8];
    int used = activeTrilinearWeights(grid, p - 0.5 * cellSize * n, cells, weights);
    if (used == 0) used = activeTrilinearWeights(grid, p - cellSize * n, cells, weights);
    if (used > 0) {
      const float eta = push.up.w;
      const float transmittance = 1.0 - fresnelReflectance(cosOut, eta);
      if (push.gridDims.w > 0 && (1.0 - cosOut * cosOut) / (eta * eta) < 1.0)
        result.rgb = singleScatteredRadiance(grid, p, -n, refract(dir, n, 1.0 / eta)) * (transmittance / (eta * eta));
      const float scale = push.viewport.z * transmittance;
      const float m = clamp(cosOut, 0.0, 1.0) * float(SSLPV_EXIT_LAW_MU_INTERVALS);
      const int j = min(int(m), SSLPV_EXIT_LAW_MU_INTERVALS - 1);
      const float fm = m - float(j);
      for (int ch = 0; ch < 3; ++ch) {
        vec4 c = vec4(0.0);
        for (int i = 0; i < used; ++i) {
          const vec4 gain = exitFactors[2u * cells[i]], albedo = exitFactors[2u * cells[i] + 1u];
          float s = weights[i] * gain[ch];
          if (albedo.w != 0.0) s *= exitLawShape(albedo[ch], j, fm);
          c += s * field[3u * cells[i] + uint(ch)];
        }
        result[ch] += max(0.0, float(SSLPV_HEMI_Y00) * c.x + float(SSLPV_HEMI_Y1) * dot(c.yzw, n)) * scale;
      }
    }
  }
  radiance[index] = result;
}
