// Records shared verbatim by the C++ host code and the GLSL shaders: push constants and
// std430 buffer records. Every field is a 4-byte scalar, so C++ and std430/push-constant
// layout agree by construction (sequential, 4-byte aligned, no padding); the field lists
// are X-macros so tests/gpu/gpu_layout_test.cpp can check every field on both sides by name.
#ifndef SSLPV_LPV_SHARED_H
#define SSLPV_LPV_SHARED_H

#include "device_shared/lpv_constants.h"

#ifdef __cplusplus
#include <cstddef>
#include <cstdint>
#define SSLPV_UINT std::uint32_t
#else
#define SSLPV_UINT uint
#endif

#define SSLPV_DECLARE_FIELD(type, name) type name;

#ifdef __cplusplus
namespace sslpv::gpu {
#endif

/// Cells along x of one propagation tile: one invocation per column of the tile, so a
/// tile is exactly one workgroup and (where subgroups hold at least this many lanes) one
/// subgroup, whose x neighbours come from subgroup shuffles instead of memory.
#define SSLPV_TILE_X 8

/// Index of cell (x, y, z) in the propagator's private grids (ping-pong fields, factors,
/// accumulated light): tiles of SSLPV_TILE_X x rows cells in raster order, each tile's
/// slices contiguous. A tile's march then reads one sequential stream, which the CPU's
/// prefetchers follow (measured on lavapipe: 43 % less time per step than x-fastest rows,
/// whose 384-byte pieces 3 KiB apart made every fetch wait for memory). The grids that
/// injection writes and shading reads keep the x-fastest layout.
#define SSLPV_TILED_INDEX(x, y, z, tilesX, rows, dimsZ)                                              \
  ((((((y) / (rows)) * (tilesX) + (x) / SSLPV_TILE_X) * (dimsZ) + (z)) * (rows) + (y) % (rows)) *   \
       SSLPV_TILE_X +                                                                              \
   (x) % SSLPV_TILE_X)

/// vec4s of step factors per cell in the propagator's factor grid: (dc.rgb, active),
/// (linear.rgb, 0), (retention.rgb, 0), (freshGain.rgb, 0), (conductance.rgb, 0)
/// (StepFactors).
#define SSLPV_FACTOR_VEC4_PER_CELL 5

/// LpvStepPush::accumulate: what a step does with the accumulated grid.
#define SSLPV_ACCUMULATE_NONE 0          /* leaves it */
#define SSLPV_ACCUMULATE_ADD 1           /* accumulated += source + result */
#define SSLPV_ACCUMULATE_START_FRESH 2   /* accumulated = freshGain source + result (a device run's step 0) */
#define SSLPV_ACCUMULATE_START_RESULT 3  /* accumulated = result (step 0 before Chebyshev iterates: their y) */

/// LpvStepPush::chebyshev: the step's part in a Chebyshev semi-iteration.
#define SSLPV_CHEBYSHEV_NONE 0     /* plain steps */
#define SSLPV_CHEBYSHEV_PROBE 1    /* a plain linear step whose power ratio estimates the radius */
#define SSLPV_CHEBYSHEV_ITERATE 2  /* an iterate (for the accumulation: any Chebyshev run) */

/// Push constants of the propagation step, the per-step reduction and the accumulation.
#define SSLPV_LPV_STEP_PUSH_FIELDS(X)                                                       \
  X(int, dimsX)          /* grid cells per axis */                                        \
  X(int, dimsY)                                                                           \
  X(int, dimsZ)                                                                           \
  X(int, itemCount)      /* work items (runs of tile slices), one partial-sum row each */ \
  X(int, stepSlot)       /* row of the step-totals buffer this step writes */              \
  X(int, autoSteps)      /* 1: stop once a step adds < tolerance of accumulated power */  \
  X(float, autoTolerance)                                                                  \
  X(int, initPower)      /* 1: this step's source power starts the accumulated power */   \
  X(int, accumulate)     /* SSLPV_ACCUMULATE_* */                                          \
  X(int, leftoverParity) /* the accumulation kernel adds the last field if stepsRun % 2 is this */ \
  X(int, stepLimit)      /* ... once stepsRun reaches this or auto steps stopped */       \
  X(float, autoTailTolerance) /* and the estimated power still to come is below this */ \
  X(int, chebyshev)      /* SSLPV_CHEBYSHEV_* */

struct LpvStepPush {
  SSLPV_LPV_STEP_PUSH_FIELDS(SSLPV_DECLARE_FIELD)
};

/// std430 record shared by the step kernels: whether propagation has stopped (auto
/// steps), how many steps ran, and per channel the power accumulated so far (the
/// stopping rule's denominator), the power the last step left in the grid (its decay
/// ratio's denominator) and, once auto steps stop, the multiple of the last step's light
/// the accumulation adds for the steps not run. Written by the reduction, read by every
/// kernel. All zero is the state before the first step.
#define SSLPV_LPV_CONTROL_FIELDS(X) \
  X(int, stopped)                   \
  X(int, stepsRun)                  \
  X(float, accumulatedPowerR)       \
  X(float, accumulatedPowerG)       \
  X(float, accumulatedPowerB)       \
  X(float, previousInGridR)         \
  X(float, previousInGridG)         \
  X(float, previousInGridB)         \
  X(float, tailScaleR)              \
  X(float, tailScaleG)              \
  X(float, tailScaleB)              \
  X(SSLPV_UINT, pad0)               \
  X(float, rhoR)     /* Chebyshev: the probe's spectral radius estimate */ \
  X(float, rhoG)                    \
  X(float, rhoB)                    \
  X(float, omegaR)   /* the next iterate's weight */ \
  X(float, omegaG)                  \
  X(float, omegaB)                  \
  X(int, iterates)                  \
  X(float, lastChangeR) /* the last iterate's change */ \
  X(float, lastChangeG)             \
  X(float, lastChangeB)             \
  X(float, logShrinkR)  /* running mean of log(change / last change) */ \
  X(float, logShrinkG)              \
  X(float, logShrinkB)              \
  X(float, markChangeR) /* the change and total where the stall window began */ \
  X(float, markChangeG)             \
  X(float, markChangeB)             \
  X(float, markTotalR)              \
  X(float, markTotalG)              \
  X(float, markTotalB)              \
  X(int, sinceMarkR)    /* iterates since then */ \
  X(int, sinceMarkG)                \
  X(int, sinceMarkB)

struct LpvControl {
  SSLPV_LPV_CONTROL_FIELDS(SSLPV_DECLARE_FIELD)
};

/// One row of per-step power sums, per channel, as floats (5 vec4): the work-item
/// partial sums and the step totals share this layout. EMITTED and CLAMP_REMOVED are
/// power (W); GATHERED, ABSORBED, IN_GRID and SOURCE are sums of c0, which the host turns
/// into power with SSLPV_FLUX_PER_C0 (as the CPU does). Indices into a float[20] row:
#define SSLPV_ENERGY_EMITTED 0        // 3 floats: power the sources held (after the clamp)
#define SSLPV_ENERGY_CLAMP_REMOVED 3  // 3 floats: power the unnormalized clamp would add
#define SSLPV_ENERGY_GATHERED 6       // 3 floats: c0 arriving in active cells
#define SSLPV_ENERGY_ABSORBED 9       // 3 floats: c0 * (1 - dc) in active cells
#define SSLPV_ENERGY_IN_GRID 12       // 3 floats: c0 kept after the step
#define SSLPV_ENERGY_SOURCE 15        // 3 floats: c0 of the step's sources as stored
#define SSLPV_ENERGY_FLOATS 20        // padded to 5 vec4
#define SSLPV_ENERGY_VEC4S 5

/// One work item of the propagation kernels, a uvec4 in the item buffer: the tile's
/// first cell (x, y), and the slices [zBegin, zEnd) it marches through.
#define SSLPV_LPV_ITEM_FIELDS(X) \
  X(SSLPV_UINT, x)               \
  X(SSLPV_UINT, y)               \
  X(SSLPV_UINT, zBegin)          \
  X(SSLPV_UINT, zEnd)

struct LpvItem {
  SSLPV_LPV_ITEM_FIELDS(SSLPV_DECLARE_FIELD)
};

/// Threads of the one-workgroup reduction kernel.
#define SSLPV_REDUCE_GROUP 64

#ifdef __cplusplus
}  // namespace sslpv::gpu
static_assert(sizeof(sslpv::gpu::LpvStepPush) == 13 * 4, "LpvStepPush must be 4-byte scalars only");
static_assert(offsetof(sslpv::gpu::LpvStepPush, autoTolerance) == 6 * 4, "LpvStepPush field order");
static_assert(sizeof(sslpv::gpu::LpvControl) == 34 * 4, "LpvControl must be 4-byte scalars only");
static_assert(offsetof(sslpv::gpu::LpvControl, accumulatedPowerR) == 2 * 4, "LpvControl field order");
static_assert(sizeof(sslpv::gpu::LpvItem) == 4 * 4, "LpvItem is one uvec4");
#endif

#endif
