// The per-cell coverage buffer every GPU pass that reads or writes the LPV uses to find
// the cells that take part in light transport, and the grid-frame fields that address it.
// Shared verbatim by C++ and GLSL.
//
// Cell coverage buffer (std430 `float[]`, one float per LPV cell, x fastest, then y, then
// z: GridFrame::index order): the cell's coverage when it is active (isActiveCell in
// volume/lpv/lpv_grid.h: coverage > 0 and not on the outer ring), 0 otherwise. Folding the
// ring into the values means a shader tests activity with one load: `coverage > 0`.
// Built by sslpv::gpu::cellCoverageValues / uploadCellCoverage (gpu/passes/gpu_inject.h).
//
// Every field below is a 4-byte scalar, so C++ and std430/push-constant layout agree by
// construction (sequential, 4-byte aligned, no padding), as in device_shared/lpv_shared.h.
#ifndef SSLPV_CELL_COVERAGE_SHARED_H
#define SSLPV_CELL_COVERAGE_SHARED_H

#ifdef __cplusplus
#include <cstddef>
#include <cstdint>
#define SSLPV_CC_UINT std::uint32_t
#else
#define SSLPV_CC_UINT uint
#endif

#define SSLPV_CC_DECLARE_FIELD(type, name) type name;

#ifdef __cplusplus
namespace sslpv::gpu {
#endif

/// The LPV grid frame as push-constant fields (GridFrame: origin of cell (0,0,0)'s min
/// corner in world units, cubic cell size, cells per axis). Other passes' push blocks
/// start with these fields so that they can call activeTrilinearWeights the same way.
#define SSLPV_CELL_GRID_FIELDS(X) \
  X(float, gridOriginX)           \
  X(float, gridOriginY)           \
  X(float, gridOriginZ)           \
  X(float, gridCellSize)          \
  X(int, gridDimsX)               \
  X(int, gridDimsY)               \
  X(int, gridDimsZ)

/// The calibrated scheme's per-cell injection record (binding 4 of shaders/lpv_inject.comp,
/// built by sslpv::gpu::uploadCalibratedInjection), x-fastest, this many vec4 per cell:
/// (injection depth rgb, ior²), then per channel r, g, b a vec4 of the oblique-entry gain
/// at its SSLPV_OBLIQUE_INTERVALS nodes (StepFactors::obliqueGain), then (entry coupling
/// rgb, unused) (StepFactors::entryCoupling).
#define SSLPV_CALIBRATED_INJECTION_VEC4 5

/// Push constants of shaders/lpv_inject.comp.
#define SSLPV_INJECT_PUSH_FIELDS(X) \
  SSLPV_CELL_GRID_FIELDS(X)         \
  X(SSLPV_CC_UINT, sampleCount) /* GpuFluxSample records to read */ \
  X(SSLPV_CC_UINT, calibrated)  /* 1: isotropic sources at the injection depths (binding 4) */

struct InjectPush {
  SSLPV_INJECT_PUSH_FIELDS(SSLPV_CC_DECLARE_FIELD)
};

/// Threads per workgroup of the injection kernel; each workgroup writes one row of
/// SSLPV_INJECT_STATS_VEC4 vec4 partial sums: (injected flux rgb, 0), (dropped flux rgb, 0).
#define SSLPV_INJECT_GROUP 64
#define SSLPV_INJECT_STATS_VEC4 2

#ifdef __cplusplus
}  // namespace sslpv::gpu
static_assert(sizeof(sslpv::gpu::InjectPush) == 9 * 4, "InjectPush must be 4-byte scalars only");
static_assert(offsetof(sslpv::gpu::InjectPush, gridDimsX) == 4 * 4, "InjectPush field order");
static_assert(offsetof(sslpv::gpu::InjectPush, sampleCount) == 7 * 4, "InjectPush field order");
#endif

#endif
