// GLSL twin of sslpv::activeTrilinearWeights (volume/cpu/inject.cpp), reading the cell
// coverage buffer of device_shared/cell_coverage_shared.h. Used by injection and shading, which
// must pick the same cells with the same weights as the CPU backend.
//
// Usage: define SSLPV_CELL_COVERAGE_BINDING (and SSLPV_CELL_COVERAGE_SET, default 0) to
// the coverage buffer's binding, include this file, then
//   CellGrid grid = SSLPV_CELL_GRID_FROM(push);   // push block with SSLPV_CELL_GRID_FIELDS
//   uint cells[8]; float weights[8];
//   int used = activeTrilinearWeights(grid, worldPoint, cells, weights);
//
// Precision: the CPU computes grid coordinates in double, this in float (off by ~1e-6
// cells at 32³). Renormalizing over the active corners divides that by their total raw
// weight W, small at the edge of the active region, so weights there differ from the
// CPU's by ~1e-6/W (tests/gpu/gpu_inject_test.cpp bounds this per coefficient).
#ifndef SSLPV_CELL_COVERAGE_GLSL
#define SSLPV_CELL_COVERAGE_GLSL

#include "device_shared/cell_coverage_shared.h"

#ifndef SSLPV_CELL_COVERAGE_BINDING
#error "define SSLPV_CELL_COVERAGE_BINDING before including shaders/cell_coverage.glsl"
#endif
#ifndef SSLPV_CELL_COVERAGE_SET
#define SSLPV_CELL_COVERAGE_SET 0
#endif

layout(std430, set = SSLPV_CELL_COVERAGE_SET, binding = SSLPV_CELL_COVERAGE_BINDING) readonly buffer SslpvCellCoverage {
  float sslpvCellCoverage[];  // coverage if the cell is active, else 0 (see cell_coverage_shared.h)
};

/// The GridFrame: world position of cell (0,0,0)'s min corner, cubic cell size, cells per axis.
struct CellGrid {
  vec3 origin;
  float cellSize;
  ivec3 dims;
};

/// A CellGrid from any block that declares SSLPV_CELL_GRID_FIELDS.
#define SSLPV_CELL_GRID_FROM(block)                                                    \
  CellGrid(vec3(block.gridOriginX, block.gridOriginY, block.gridOriginZ), block.gridCellSize, \
           ivec3(block.gridDimsX, block.gridDimsY, block.gridDimsZ))

/// Index of cell c in the coverage buffer and the LPV (GridFrame::index: x fastest).
uint cellIndex(CellGrid grid, ivec3 c) { return uint((c.z * grid.dims.y + c.y) * grid.dims.x + c.x); }

/// Trilinear weights of the 8 cells around world point p (continuous cell coordinates,
/// cell centres at half-integers) times each cell's coverage, restricted to active cells
/// inside the grid and renormalized to sum to 1. Returns the number of cells used; only
/// the first `used` entries of `cells` and `weights` are written (0: no active cell nearby).
int activeTrilinearWeights(CellGrid grid, vec3 p, out uint cells[8], out float weights[8]) {
  const vec3 g = (p - grid.origin) / grid.cellSize - 0.5;
  // No cell of the grid is among the 8 corners; also keeps far (or NaN) points away
  // from the float-to-int conversion below, which is undefined out of range.
  if (!all(greaterThanEqual(g, vec3(-1.0))) || !all(lessThan(g, vec3(grid.dims)))) return 0;
  const ivec3 base = ivec3(floor(g));
  const vec3 t = g - vec3(base);
  int used = 0;
  float total = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const ivec3 c = base + ivec3(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
    if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, grid.dims))) continue;
    const uint index = cellIndex(grid, c);
    // Inactive cells (outside the object or on the outer ring) hold 0 in the buffer.
    // Weighting by coverage fades a barely-touched cell in instead of switching it on,
    // which would show as contour rings across curved surfaces (as on the CPU).
    const float coverage = sslpvCellCoverage[index];
    if (!(coverage > 0.0)) continue;
    const float w = ((corner & 1) != 0 ? t.x : 1.0 - t.x) * ((corner & 2) != 0 ? t.y : 1.0 - t.y) *
                    ((corner & 4) != 0 ? t.z : 1.0 - t.z) * coverage;
    if (w <= 0.0) continue;
    cells[used] = index;
    weights[used] = w;
    total += w;
    ++used;
  }
  for (int i = 0; i < used; ++i) weights[i] /= total;
  return used;
}

#endif
