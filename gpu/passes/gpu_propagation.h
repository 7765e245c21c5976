#pragma once
// LPV propagation on the GPU: the twin of sslpv::propagate() (volume/cpu/propagate.cpp) with
// the same contract, steps, auto-step rule and per-step energy bookkeeping, run only over
// the occupied part of the grid, from host grids (run) or device-resident (runOnDevice,
// record) between GPU injection and GPU shading.
#include <cstdint>
#include <vector>

#include "gpu/vk/compute.h"
#include "gpu/vk/device.h"
#include "device_shared/lpv_shared.h"
#include "volume/lpv/lpv_stages.h"

namespace sslpv::gpu {

struct GpuPropagatorOptions {
  /// Rows along y of a work item's tile (tiles are SSLPV_TILE_X = 8 cells along x, one
  /// invocation per x column keeping the light gathered into its rows of 3 slices in
  /// registers). 0: 8 or 4, whichever the construction-time factors make cheaper (8
  /// re-reads fewer halo rows, 4 covers fewer empty cells around thin or curved objects;
  /// bench --rows measures both).
  int tileRows = 0;
  /// Most slices one work item marches through; longer runs of occupied slices are split
  /// (each piece re-reads 2 halo slices) so that every core of the device gets work.
  /// 0: from the number of occupied slices and the device's cores.
  int zChunk = 0;
  /// Steps recorded per submission (auto steps stop on the GPU within a submission).
  int stepsPerSubmission = 32;
  /// Go through staging buffers even where device memory is mappable (tests that path).
  bool forceStaging = false;
  /// Run the steps after the first as a c0 stencil where the factors keep cells isotropic
  /// (PropagationOptions::isotropicFastPath). Off only to measure the general kernel.
  bool isotropicSteps = true;
};

/// GPU time of the last run() or runOnDevice(), from timestamps (0 where the queue has
/// none).
struct GpuPropagationTimings {
  double uploadMs = 0.0;     ///< staging copies to the device (0 when mapped directly)
  double propagateMs = 0.0;  ///< the propagation kernel, all steps that ran
  double reduceMs = 0.0;     ///< the per-step power reductions
  double readbackMs = 0.0;   ///< staging copies back to the host
  int steps = 0;
  double propagateMsPerStep() const { return steps > 0 ? propagateMs / steps : 0.0; }
};

/// Runs propagation steps on the device. A light field there is 3 vec4 per cell (one per
/// channel: c0, c1x, c1y, c1z), x-fastest where other passes share it and tiled
/// (SSLPV_TILED_INDEX) in the propagator's own grids; step factors are (dc.rgb, active),
/// (linear.rgb, 0). From StepFactors::active the host lists work items: tiles of 8 x
/// tileRows cells marching through runs of slices holding active cells. Only those are
/// dispatched, so cost follows the occupied cells; every cell outside them holds no light
/// (injection only fills active cells) and stays zero. A step is one fused kernel
/// (normalize sources, gather, apply factors, accumulate every other step) plus a tiny
/// reduction of the per-step power sums that also decides auto steps, so a whole
/// submission of steps runs without the host.
class GpuPropagator {
 public:
  /// Allocates the grids of `frame` on `device` (which must outlive the propagator) and
  /// uploads `factors` (computeStepFactors() of the material on that frame). Throws
  /// ResourceError when a grid exceeds the device's buffer limits, GpuError when the
  /// device lacks the subgroup operations the kernel needs.
  GpuPropagator(const VulkanDevice& device, const GridFrame& frame, const StepFactors& factors,
                const GpuPropagatorOptions& options = {});

  /// Replaces the step factors (the material changed; same frame) and the work items.
  void setFactors(const StepFactors& factors);

  /// Same contract as sslpv::propagate(): `field` holds the injected light and receives
  /// the last step's light; every step, including the injected one, is added into
  /// `accumulated`. Both must be on the propagator's frame. Light in inactive cells is
  /// not propagated (injection never puts any there).
  PropagationResult run(ShGrid& field, ShGrid& accumulated, const PropagationOptions& options);

  // --- Device-resident use: injection writes sourceField(), shading reads accumulated().
  // Both are x-fastest grids (layout above); the propagator copies the injected light
  // into its private tiled grids in one pass and writes the accumulated light back in one
  // pass, so every step reads sequential memory.

  /// The step-0 source: GPU injection writes the injected light here, only into active
  /// cells. Propagation only reads it.
  const Buffer& sourceField() const { return linearSource_; }
  /// The accumulated light of the last device-resident run: the injected light plus every
  /// step, zero outside the medium.
  const Buffer& accumulated() const { return linearAccumulated_; }
  /// Propagates from sourceField() into accumulated() (overwritten, not added to),
  /// submitting batches of steps and reading back only the small control and power
  /// records. initialPower and energy come from the GPU's float sums (initialPower stays
  /// 0 when no step runs).
  PropagationResult runOnDevice(const PropagationOptions& options);
  /// Records the same work into `cmd` without submitting, for a frame's command buffer:
  /// barriers against earlier compute and transfer writes, and before any later read of
  /// accumulated(). Auto steps record options.maxAutoSteps steps, which are no-ops after
  /// the GPU decides to stop; stepsRun() tells how many ran once `cmd` has executed.
  /// No energy or timings are recorded.
  void record(VkCommandBuffer cmd, const PropagationOptions& options);
  /// Steps the last run executed, read from the device (valid once it has finished).
  int stepsRun() const;

  /// Writes a host grid into sourceField() or accumulated(); `activeOnly` zeroes cells
  /// that are not active, as injection leaves them.
  void uploadField(const ShGrid& grid, const Buffer& target, bool activeOnly = false);
  /// Reads sourceField() or accumulated() into a host grid on the propagator's frame.
  void downloadField(const Buffer& source, ShGrid& grid);
  /// Reads the last step's light of the last run (after it has finished).
  void downloadLastField(ShGrid& grid);

  const GpuPropagationTimings& timings() const { return timings_; }
  const GridFrame& frame() const { return frame_; }
  int tileRows() const { return options_.tileRows; }
  int zChunk() const { return zChunk_; }
  /// Work items per step, the cells they cover (the work a step does), the active cells.
  std::size_t itemCount() const { return itemCount_; }
  std::size_t coveredCells() const { return coveredCells_; }
  std::size_t activeCells() const { return activeCells_; }

 private:
  enum class Mode { Host, Device };
  using BufferView = DeviceObject<VkBufferView, vkDestroyBufferView>;

  void buildItems(const StepFactors& factors);
  void writeDescriptors();
  std::size_t tiledIndex(int x, int y, int z) const;
  /// Copies between a host grid and a device grid in either layout (through staging
  /// where device memory is not mappable).
  void transfer(const ShGrid* from, ShGrid* to, const Buffer& device, bool tiled, bool activeOnly);
  LpvStepPush stepPush(const PropagationOptions& options) const;
  void recordSteps(VkCommandBuffer cmd, Mode mode, int firstStep, int count, const PropagationOptions& options,
                   bool timestamps);
  /// Does this run take the Chebyshev iterates (device-resident auto steps on factors
  /// that keep cells isotropic, PropagationOptions::chebyshev)?
  bool chebyshevRun(Mode mode, const PropagationOptions& options) const;
  /// The variants of lpv_propagate.comp: the general step, the isotropic stencil, the
  /// Chebyshev iterate (its specialization constants ISOTROPIC and CHEBYSHEV).
  enum class StepKernel { General, Isotropic, Chebyshev };
  /// The pipeline of a step; the isotropic and Chebyshev ones are built on first use, so
  /// a propagator compiles only the kernels its runs take (each is a JIT on lavapipe).
  const ComputePipeline& stepPipeline(StepKernel kernel, bool accumulate);
  void recordFinish(VkCommandBuffer cmd, Mode mode, int stepLimit, const PropagationOptions& options);
  void prepareDeviceRun(VkCommandBuffer cmd);
  PropagationResult execute(Mode mode, const PropagationOptions& options);

  const VulkanDevice& device_;
  GridFrame frame_;
  GpuPropagatorOptions options_;
  int zChunk_ = 0, tilesX_ = 0, tilesY_ = 0;
  std::size_t itemCount_ = 0, coveredCells_ = 0, activeCells_ = 0;
  std::vector<LpvItem> items_;
  std::vector<unsigned char> active_;  ///< for uploads that keep only active cells
  std::array<std::vector<float>, 3> freshGain_;  ///< StepFactors::freshGain, for run()'s start
  bool staging_ = false;
  bool tiledAccumulatedClean_ = false;   ///< zero outside the work items
  bool linearAccumulatedClean_ = false;  ///< zero outside the work items

  DescriptorSetLayout setLayout_;
  DescriptorPool pool_;
  VkDescriptorSet sets_[2] = {VK_NULL_HANDLE, VK_NULL_HANDLE};  ///< set k reads tiled_[k]
  ComputePipeline propagatePipelines_[2];   ///< without and with accumulation
  /// The same for the steps after the first where the factors keep cells isotropic
  /// (keepsCellsIsotropic), and the Chebyshev iterates; built by stepPipeline on first use.
  ComputePipeline isotropicPipelines_[2];
  ComputePipeline chebyshevPipeline_;
  bool isotropicSteps_ = false;
  ComputePipeline finishPipelines_[2];      ///< into tiled_ / linear accumulated light
  ComputePipeline reducePipeline_, importPipeline_;
  Buffer linearSource_, linearAccumulated_;  ///< x-fastest, shared with injection and shading
  Buffer tiled_[2];                          ///< ping-pong: step k reads tiled_[k % 2]
  Buffer tiledAccumulated_, factors_, itemBuffer_, partials_, control_, stepTotals_;
  BufferView tiledViews_[2], tiledAccumulatedView_, factorsView_, linearSourceView_;
  Buffer stagingBuffer_;  ///< host copy of one field-sized buffer when not mapped
  CommandContext commands_;
  TimestampQueries timestamps_;
  GpuPropagationTimings timings_;
};

}  // namespace sslpv::gpu
