#pragma once
// LPV propagation on the GPU: the twin of sslpv::propagate() (volume/propagate.cpp) with
// the same contract, steps, auto-step rule and per-step energy bookkeeping.
#include <cstdint>

#include "gpu/compute.h"
#include "gpu/device.h"
#include "shaders/lpv_shared.h"
#include "volume/lpv_stages.h"

namespace sslpv::gpu {

struct GpuPropagatorOptions {
  /// Workgroup shape (x, y >= 4), the cross-section of the column a workgroup marches
  /// along z; 0: x as wide as the grid up to 64, y = max(4, 128 / x). Measured on
  /// lavapipe: 64x4 at 64^3 (37 ms a step on one thread, against 46 for 32x8, 50 for
  /// 16x16 and 49 for 8x8) and 32x4 at 32^3 (4.8 ms, against 5.4 for 32x8). Narrower
  /// where the device has less shared memory than the slice needs (19 KiB at 64x4).
  int groupX = 0, groupY = 0;
  /// Cells along z one workgroup marches through; 0 picks enough workgroups to keep
  /// the device's cores busy.
  int zChunk = 0;
  /// Steps recorded per submission (auto steps stop on the GPU within a submission).
  int stepsPerSubmission = 32;
  /// Go through staging buffers even where device memory is mappable (tests that path).
  bool forceStaging = false;
};

/// GPU time of the last run(), from timestamps (0 where the queue has none).
struct GpuPropagationTimings {
  double uploadMs = 0.0;     ///< staging copies to the device (0 when mapped directly)
  double propagateMs = 0.0;  ///< the propagation kernel, all steps that ran
  double reduceMs = 0.0;     ///< the per-step power reductions
  double readbackMs = 0.0;   ///< staging copies back to the host
  int steps = 0;
  double propagateMsPerStep() const { return steps > 0 ? propagateMs / steps : 0.0; }
};

/// Runs propagation steps on the device. The light field lives there as 3 vec4 per cell
/// (one per channel: c0, c1x, c1y, c1z; x fastest), converted from and to ShGrid's
/// planes on upload and readback; step factors as (dc.rgb, active), (linear.rgb, 0).
/// A step is one fused kernel (normalize sources, gather, apply factors) plus a tiny
/// reduction of the per-step power sums that also decides auto steps, so a whole
/// submission of steps runs without the host. The accumulated grid is updated every
/// other step with two steps' light at once (it is the largest buffer traffic).
class GpuPropagator {
 public:
  /// Allocates the grids of `frame` on `device` (which must outlive the propagator) and
  /// uploads `factors` (computeStepFactors() of the material on that frame). Throws
  /// ResourceError when a grid exceeds the device's storage-buffer range.
  GpuPropagator(const VulkanDevice& device, const GridFrame& frame, const StepFactors& factors,
                const GpuPropagatorOptions& options = {});

  /// Replaces the step factors (the material changed; same frame).
  void setFactors(const StepFactors& factors);

  /// Same contract as sslpv::propagate(): `field` holds the injected light and receives
  /// the last step's light; every step, including the injected one, is added into
  /// `accumulated`. Both must be on the propagator's frame.
  PropagationResult run(ShGrid& field, ShGrid& accumulated, const PropagationOptions& options);

  const GpuPropagationTimings& timings() const { return timings_; }
  const GridFrame& frame() const { return frame_; }
  int groupX() const { return options_.groupX; }
  int groupY() const { return options_.groupY; }
  int zChunk() const { return zChunk_; }

 private:
  void upload(const ShGrid& grid, const Buffer& target);
  void download(const Buffer& source, ShGrid& grid);
  LpvStepPush stepPush(const PropagationOptions& options) const;
  void recordSteps(VkCommandBuffer cmd, int firstStep, int count, const PropagationOptions& options);
  void accumulateLastStep(int stepsRun);

  const VulkanDevice& device_;
  GridFrame frame_;
  GpuPropagatorOptions options_;
  int zChunk_ = 0;
  std::uint32_t groups_[3] = {1, 1, 1};
  std::uint32_t partialRows_ = 0;
  bool staging_ = false;

  DescriptorSetLayout setLayout_;
  ComputePipeline propagatePipeline_, reducePipeline_, accumulatePipeline_;
  Buffer fields_[2];  ///< ping-pong: step k reads fields_[k % 2]
  Buffer accumulated_, factors_, partials_, control_, stepTotals_;
  Buffer stagingBuffer_;    ///< host copy of one field-sized buffer when not mapped
  StorageBufferSets sets_;  ///< set k % 2 reads fields_[k % 2] and writes the other
  CommandContext commands_;
  TimestampQueries timestamps_;
  GpuPropagationTimings timings_;
};

}  // namespace sslpv::gpu
