#version 460
// GPU twin of the per-pixel work of sslpv::shadeImage (volume/shade.cpp), on the
// triangle the rasterizer found nearest at each pixel centre (shaders/shade.vert/.frag),
// or the neighbour the exact ray crosses (shaders/ray_triangle_pick.glsl):
// the pixel's camera ray meets the triangle's plane; the accumulated LPV is read half a
// cell inside the surface (a full cell when no active cell is near) with the
// coverage-weighted active trilinear weights of activeTrilinearWeights; radiance
// L = T(θo)/η² · (1/(Aπ)) ∫_H G h I(ω) dω per channel, G the cell's exit gain and h its
// exit angular shape (volume/exit_law.h; 1 in the seed scheme).
// Output: one vec4 per pixel, row 0 at
// the top, (radiance, 1) on the surface (black where the ray leaves from inside or no
// active cell is near), (0, 0, 0, 0) for the background.
#extension GL_GOOGLE_include_directive : require
#include "shaders/fresnel.glsl"
#include "shaders/shade_shared.h"
#include "volume/lpv_constants.h"

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
layout(push_constant) uniform Push { GpuShadePush push; };

#include "shaders/ray_triangle_pick.glsl"

// Twin of sslpv::exitLawShape (volume/exit_law.cpp), line for line: bilinear in
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
      const float scale = push.viewport.z * (1.0 - fresnelReflectance(cosOut, push.up.w));
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
        result[ch] = max(0.0, float(SSLPV_HEMI_Y00) * c.x + float(SSLPV_HEMI_Y1) * dot(c.yzw, n)) * scale;
      }
    }
  }
  radiance[index] = result;
}
