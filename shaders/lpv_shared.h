// Records shared verbatim by the C++ host code and the GLSL shaders: push constants and
// std430 buffer records. Every field is a 4-byte scalar, so C++ and std430/push-constant
// layout agree by construction (sequential, 4-byte aligned, no padding); the field lists
// are X-macros so tests/gpu_layout_test.cpp can check every field on both sides by name.
#ifndef SSLPV_LPV_SHARED_H
#define SSLPV_LPV_SHARED_H

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

/// Push constants of the propagation step and the per-step reduction.
#define SSLPV_LPV_STEP_PUSH_FIELDS(X)                                                       \
  X(int, dimsX)          /* grid cells per axis */                                        \
  X(int, dimsY)                                                                           \
  X(int, dimsZ)                                                                           \
  X(int, zChunk)         /* cells along z that one workgroup marches through */           \
  X(int, partialRows)    /* rows of partial power sums the propagation step wrote */     \
  X(int, stepSlot)       /* row of the step-totals buffer this step writes */              \
  X(int, autoSteps)      /* 1: stop once a step adds < tolerance of accumulated power */  \
  X(float, autoTolerance)                                                                  \
  X(int, accumulate)     /* 1: add this step's sources and results to the accumulated grid */ \
  X(SSLPV_UINT, pad0)

struct LpvStepPush {
  SSLPV_LPV_STEP_PUSH_FIELDS(SSLPV_DECLARE_FIELD)
};

/// std430 record shared by the step kernels: whether propagation has stopped (auto
/// steps), how many steps ran, and the power accumulated so far (the stopping rule's
/// denominator, per channel). Written by the reduction, read by both kernels.
#define SSLPV_LPV_CONTROL_FIELDS(X) \
  X(int, stopped)                   \
  X(int, stepsRun)                  \
  X(float, accumulatedPowerR)       \
  X(float, accumulatedPowerG)       \
  X(float, accumulatedPowerB)       \
  X(SSLPV_UINT, pad0)               \
  X(SSLPV_UINT, pad1)               \
  X(SSLPV_UINT, pad2)

struct LpvControl {
  SSLPV_LPV_CONTROL_FIELDS(SSLPV_DECLARE_FIELD)
};

/// One row of per-step power sums, per channel, as floats (4 vec4): the workgroup
/// partial sums and the step totals share this layout. EMITTED and CLAMP_REMOVED are
/// power (W); GATHERED, ABSORBED and IN_GRID are sums of c0, which the host turns into
/// power with SSLPV_FLUX_PER_C0 (as the CPU does). Indices into a float[16] row:
#define SSLPV_ENERGY_EMITTED 0        // 3 floats: power the sources held (after the clamp)
#define SSLPV_ENERGY_CLAMP_REMOVED 3  // 3 floats: power the unnormalized clamp would add
#define SSLPV_ENERGY_GATHERED 6       // 3 floats: c0 arriving in active cells
#define SSLPV_ENERGY_ABSORBED 9       // 3 floats: c0 * (1 - dc) in active cells
#define SSLPV_ENERGY_IN_GRID 12       // 3 floats: c0 kept after the step
#define SSLPV_ENERGY_FLOATS 16        // padded to 4 vec4

/// Threads of the one-workgroup reduction kernel.
#define SSLPV_REDUCE_GROUP 256

#ifdef __cplusplus
}  // namespace sslpv::gpu
static_assert(sizeof(sslpv::gpu::LpvStepPush) == 10 * 4, "LpvStepPush must be 4-byte scalars only");
static_assert(offsetof(sslpv::gpu::LpvStepPush, autoTolerance) == 7 * 4, "LpvStepPush field order");
static_assert(sizeof(sslpv::gpu::LpvControl) == 8 * 4, "LpvControl must be 4-byte scalars only");
static_assert(offsetof(sslpv::gpu::LpvControl, accumulatedPowerR) == 2 * 4, "LpvControl field order");
#endif

#endif
