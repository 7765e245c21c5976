// Interface and shared pieces of the LPV step kernels (lpv_propagate.comp,
// lpv_accumulate.comp, lpv_import.comp): the bindings, the work items, cell indexing and
// fetches.
//
// Fields are 3 vec4 per cell (one per channel: c0, c1x, c1y, c1z). The propagator's own
// grids are tiled (SSLPV_TILED_INDEX); the injected light and the accumulated light that
// shading reads are x-fastest. Kernels read fields through uniform texel buffers and write
// them as storage buffers: on lavapipe a texel fetch is a vectorized gather, about half
// the cost of a storage-buffer load, which is a loop over the SIMD lanes.
#ifndef SSLPV_LPV_STEP_COMMON_GLSL
#define SSLPV_LPV_STEP_COMMON_GLSL

#include "device_shared/lpv_constants.h"
#include "device_shared/lpv_shared.h"

/// Tile rows along y (the tile is SSLPV_TILE_X wide).
layout(constant_id = 0) const int ROWS = 8;

layout(push_constant) uniform PushBlock { SSLPV_LPV_STEP_PUSH_FIELDS(SSLPV_DECLARE_FIELD) } push;

layout(binding = 0) uniform samplerBuffer sourceField;  // the tiled field this step reads
layout(std430, binding = 1) writeonly buffer DestinationField { vec4 destination[]; };  // tiled
layout(std430, binding = 2) writeonly buffer AccumulatedField { vec4 accumulated[]; };  // tiled
// The same memory as binding 2: each cell is read and then written by one invocation.
layout(binding = 3) uniform samplerBuffer accumulatedIn;
// Per cell, tiled: SSLPV_FACTOR_VEC4_PER_CELL vec4s (lpv_shared.h).
layout(binding = 4) uniform samplerBuffer factors;
layout(std430, binding = 5) readonly buffer Items { uvec4 items[]; };
layout(std430, binding = 6) writeonly buffer PartialSums { vec4 partials[]; };
layout(std430, binding = 7) readonly buffer Control { SSLPV_LPV_CONTROL_FIELDS(SSLPV_DECLARE_FIELD) } control;
// binding 8: step totals (reduction only).
layout(binding = 9) uniform samplerBuffer injectedField;  // x-fastest, written by injection
layout(std430, binding = 10) writeonly buffer OutputField { vec4 accumulatedOut[]; };  // x-fastest
layout(binding = 11) uniform samplerBuffer otherField;  // the tiled field the step writes (binding 1)

ivec3 dims;

struct Cell {
  vec4 c[3];
};

int cellIndex(int x, int y, int z) {
  return SSLPV_TILED_INDEX(x, y, z, (dims.x + SSLPV_TILE_X - 1) / SSLPV_TILE_X, ROWS, dims.z);
}
int linearIndex(int x, int y, int z) { return (z * dims.y + y) * dims.x + x; }
bool inGrid(int x, int y, int z) {
  return x >= 0 && x < dims.x && y >= 0 && y < dims.y && z >= 0 && z < dims.z;
}
bool interiorXY(int x, int y) { return x >= 1 && x < dims.x - 1 && y >= 1 && y < dims.y - 1; }

/// A cell of the source field as stored; zero outside the grid. Branch-free: lavapipe
/// runs both sides of every branch anyway, and a clamped index keeps the fetch in range.
Cell fetchSource(int x, int y, int z) {
  const bool valid = inGrid(x, y, z);
  const int i = valid ? cellIndex(x, y, z) : 0;
  Cell s;
  for (int ch = 0; ch < 3; ++ch) s.c[ch] = valid ? texelFetch(sourceField, 3 * i + ch) : vec4(0.0);
  return s;
}

#endif
