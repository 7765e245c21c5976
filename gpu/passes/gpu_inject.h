#pragma once
// Injection on the GPU: the twin of sslpv::injectSamples (volume/cpu/inject.cpp). Reads the
// GpuFluxSample records a shadow map wrote and adds clamped cosine lobes into the light
// field in GpuPropagator's device layout, with the same cells, weights and statistics.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

#include "gpu/vk/compute.h"
#include "gpu/vk/device.h"
#include "gpu/vk/resources.h"
#include "device_shared/cell_coverage_shared.h"
#include "device_shared/flux_sample_shared.h"
#include "volume/lpv/lpv_stages.h"

namespace sslpv::gpu {

/// The cell coverage buffer's values (device_shared/cell_coverage_shared.h): per cell, in
/// GridFrame::index order, the coverage when isActiveCell, else 0.
std::vector<float> cellCoverageValues(const MaterialGrid& material);

/// A new device storage buffer holding cellCoverageValues(material), for injection and
/// shading (binding SSLPV_CELL_COVERAGE_BINDING of shaders/cell_coverage.glsl). Written
/// through its mapping where device memory is mappable, else through a staging copy
/// (submitted and waited for).
Buffer uploadCellCoverage(const VulkanDevice& device, const MaterialGrid& material);

/// A new device storage buffer holding the calibrated scheme's injection record of
/// `factors` on `frame` (StepFactors::injectionDepth, ::obliqueGain and ::ior; layout at
/// SSLPV_CALIBRATED_INJECTION_VEC4 in device_shared/cell_coverage_shared.h). Throws GpuError when
/// the factors hold none (seed scheme) or another frame's.
Buffer uploadCalibratedInjection(const VulkanDevice& device, const StepFactors& factors, const GridFrame& frame);

/// A new device storage buffer holding `samples` (at least one record's worth of bytes),
/// e.g. for CPU shadow-map samples injected on the GPU, and for tests.
Buffer uploadFluxSamples(const VulkanDevice& device, const std::vector<GpuFluxSample>& samples);

/// The GPU record of a CPU sample (always valid: positionValid.w = 1).
GpuFluxSample toGpuFluxSample(const SurfaceFluxSample& sample);

/// Bytes of a light field of `frame` in GpuPropagator's layout (3 vec4 per cell).
VkDeviceSize lightFieldBytes(const GridFrame& frame);

struct GpuInjectorOptions {
  /// Upper bound on workgroups of SSLPV_INJECT_GROUP threads; larger sample counts are
  /// strided over them. It fixes the size of the partial-sum buffer.
  std::uint32_t maxWorkgroups = 1024;
};

/// Records the injection kernel. One injector serves one recording at a time: record()
/// rewrites its descriptor set and its statistics rows, so it must not be called again
/// until the previous recording has executed (submit every light's samples in one buffer).
class GpuInjector {
 public:
  /// Builds the pipeline on `device` (which must outlive the injector). Throws GpuError
  /// when the device lacks float atomic add on storage buffers (VK_EXT_shader_atomic_float
  /// shaderBufferFloat32AtomicAdd).
  explicit GpuInjector(const VulkanDevice& device, const GpuInjectorOptions& options = {});

  /// Records: fill `field` with zeros (when `clearField`), then add the lobes of the first
  /// `sampleCount` records of `samples` (misses, positionValid.w == 0, are skipped) into
  /// `field` (lightFieldBytes(frame) or more; transfer-dst usage too when cleared).
  /// `cellCoverage` is uploadCellCoverage() of the material on `frame`.
  /// `calibratedInjection` (uploadCalibratedInjection()) selects the calibrated scheme's
  /// isotropic sources at depth, scaled by the oblique-entry gain; null, the seed's lobes. Barriers before
  /// and after make earlier transfer/compute writes visible to the kernel, and its writes
  /// visible to later compute and transfer commands and, after the submission's fence, to
  /// the host (stats()).
  void record(VkCommandBuffer cmd, const Buffer& samples, std::uint32_t sampleCount, const Buffer& cellCoverage,
              const GridFrame& frame, const Buffer& field, bool clearField = true,
              const Buffer* calibratedInjection = nullptr);

  /// Injected and dropped flux of the last recording, once it has executed; summed in
  /// double from per-workgroup float partial sums.
  InjectionStats stats() const;

  /// record() into the injector's own command buffer, submit, wait; returns stats().
  InjectionStats run(const Buffer& samples, std::uint32_t sampleCount, const Buffer& cellCoverage,
                     const GridFrame& frame, const Buffer& field, bool clearField = true,
                     const Buffer* calibratedInjection = nullptr);

  /// GPU time of the last run() (clear + injection kernel), from timestamps; 0 without them.
  double lastRunMs() const { return lastRunMs_; }

 private:
  GpuInjectorOptions options_;
  DescriptorSetLayout setLayout_;
  ComputePipeline pipeline_;
  StorageBufferSets sets_;
  Buffer partials_;           ///< host-visible: SSLPV_INJECT_STATS_VEC4 vec4 per workgroup
  Buffer noCalibration_;           ///< bound at binding 4 in the seed scheme, never read
  std::uint32_t groups_ = 0;  ///< workgroups of the last recording
  CommandContext commands_;
  TimestampQueries timestamps_;
  double lastRunMs_ = 0.0;
};

}  // namespace sslpv::gpu
