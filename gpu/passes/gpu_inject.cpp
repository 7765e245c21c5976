#include "gpu/passes/gpu_inject.h"

#include <algorithm>
#include <cstring>
#include <string>

namespace sslpv::gpu {
namespace {

constexpr std::uint32_t kBindings = 5;  // see the bindings of shaders/lpv_inject.comp
constexpr VkDeviceSize kVec4 = 4 * sizeof(float);
constexpr VkBufferUsageFlags kStorage =
    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;

/// A device storage buffer holding `bytes` of `data`; mapped where possible, else staged.
Buffer uploadBytes(const VulkanDevice& device, const void* data, VkDeviceSize bytes) {
  // Zero-sized buffers are invalid; a one-vec4 buffer stands in for empty data.
  Buffer buffer(device, std::max(bytes, kVec4), kStorage, MemoryUse::Device);
  if (buffer.mapped()) {
    if (bytes > 0) std::memcpy(buffer.mapped(), data, bytes);
    return buffer;
  }
  if (bytes == 0) return buffer;
  Buffer staging(device, bytes, kStorage, MemoryUse::Host);
  std::memcpy(staging.mapped(), data, bytes);
  CommandContext commands(device);
  VkCommandBuffer cmd = commands.begin();
  const VkBufferCopy region{0, 0, bytes};
  vkCmdCopyBuffer(cmd, staging.handle(), buffer.handle(), 1, &region);
  commands.submitAndWait();
  return buffer;
}

/// The injection's writes (field, partial sums) become visible to later compute and
/// transfer commands of the queue, and to the host once the submission's fence signals.
void injectionDoneBarrier(VkCommandBuffer cmd) {
  VkMemoryBarrier barrier{};
  barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                          VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(
      cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_HOST_BIT, 0, 1,
      &barrier, 0, nullptr, 0, nullptr);
}

void requireBytes(const Buffer& buffer, VkDeviceSize bytes, const char* what) {
  if (buffer.size() < bytes)
    throw GpuError(std::string("GpuInjector::record: ") + what + " buffer holds " + std::to_string(buffer.size()) +
                   " bytes, " + std::to_string(bytes) + " needed");
}

}  // namespace

std::vector<float> cellCoverageValues(const MaterialGrid& material) {
  const GridFrame& f = material.frame;
  if (material.coverage.size() != f.cellCount())
    throw GpuError("cellCoverageValues: the material's coverage does not match its frame");
  std::vector<float> values(f.cellCount(), 0.0f);
  for (int z = 0; z < f.dims.z; ++z)
    for (int y = 0; y < f.dims.y; ++y)
      for (int x = 0; x < f.dims.x; ++x)
        if (isActiveCell(material, x, y, z)) values[f.index(x, y, z)] = material.coverage[f.index(x, y, z)];
  return values;
}

Buffer uploadCellCoverage(const VulkanDevice& device, const MaterialGrid& material) {
  const std::vector<float> values = cellCoverageValues(material);
  return uploadBytes(device, values.data(), values.size() * sizeof(float));
}

Buffer uploadCalibratedInjection(const VulkanDevice& device, const StepFactors& factors, const GridFrame& frame) {
  static_assert(kObliqueIntervals == 4, "one vec4 holds a channel's oblique-entry gain nodes");
  const std::size_t cells = frame.cellCount();
  for (int ch = 0; ch < 3; ++ch)
    if (factors.injectionDepth[ch].size() != cells || factors.obliqueGain[ch].size() != cells * kObliqueIntervals ||
        factors.entryCoupling[ch].size() != cells)
      throw GpuError("uploadCalibratedInjection: the step factors hold no calibrated injection for this grid frame");
  constexpr std::size_t kFloats = 4 * SSLPV_CALIBRATED_INJECTION_VEC4;
  std::vector<float> values(cells * kFloats, 0.0f);
  const auto iorSquared = float(factors.ior * factors.ior);
  for (std::size_t i = 0; i < cells; ++i) {
    float* record = &values[kFloats * i];
    for (int ch = 0; ch < 3; ++ch) {
      record[ch] = factors.injectionDepth[ch][i];
      for (int k = 0; k < kObliqueIntervals; ++k)
        record[4 * (1 + ch) + k] = factors.obliqueGain[ch][i * kObliqueIntervals + std::size_t(k)];
      record[16 + ch] = factors.entryCoupling[ch][i];
    }
    record[3] = iorSquared;
  }
  return uploadBytes(device, values.data(), values.size() * sizeof(float));
}

Buffer uploadFluxSamples(const VulkanDevice& device, const std::vector<GpuFluxSample>& samples) {
  return uploadBytes(device, samples.data(), samples.size() * sizeof(GpuFluxSample));
}

GpuFluxSample toGpuFluxSample(const SurfaceFluxSample& s) {
  return GpuFluxSample{glm::vec4(s.position, 1.0f), glm::vec4(s.normal, 0.0f), glm::vec4(s.direction, 0.0f),
                       glm::vec4(s.flux, 0.0f)};
}

VkDeviceSize lightFieldBytes(const GridFrame& frame) { return VkDeviceSize(frame.cellCount()) * 3 * kVec4; }

GpuInjector::GpuInjector(const VulkanDevice& device, const GpuInjectorOptions& options)
    : options_(options), commands_(device) {
  if (!device.bufferFloatAtomicAdd())
    throw GpuError(
        "GPU injection needs float atomic add on storage buffers (VK_EXT_shader_atomic_float "
        "shaderBufferFloat32AtomicAdd), which the Vulkan device \"" +
        device.name() + "\" does not offer");
  options_.maxWorkgroups =
      std::clamp<std::uint32_t>(options_.maxWorkgroups, 1, device.properties().limits.maxComputeWorkGroupCount[0]);
  setLayout_ = makeStorageBufferSetLayout(device, kBindings);
  pipeline_ = ComputePipeline(device, spirv::lpv_inject_comp(), setLayout_.get(), sizeof(InjectPush));
  sets_ = StorageBufferSets(device, setLayout_.get(), kBindings, 1);
  partials_ =
      Buffer(device, VkDeviceSize(options_.maxWorkgroups) * SSLPV_INJECT_STATS_VEC4 * kVec4, kStorage, MemoryUse::Host);
  sets_.write(0, 3, partials_);
  noCalibration_ = Buffer(device, kVec4, kStorage, MemoryUse::Device);
  timestamps_ = TimestampQueries(device, 2);
}

void GpuInjector::record(VkCommandBuffer cmd, const Buffer& samples, std::uint32_t sampleCount,
                         const Buffer& cellCoverage, const GridFrame& frame, const Buffer& field, bool clearField,
                         const Buffer* calibratedInjection) {
  const std::size_t cells = frame.cellCount();
  if (cells == 0) throw GpuError("GpuInjector::record: the grid frame has no cells");
  // Field offsets are 12 * cell as 32-bit indices in the shader.
  if (cells > std::size_t(0xffffffffu) / 12) throw GpuError("GpuInjector::record: the grid has too many cells");
  requireBytes(samples, VkDeviceSize(sampleCount) * sizeof(GpuFluxSample), "sample");
  requireBytes(cellCoverage, VkDeviceSize(cells) * sizeof(float), "cell coverage");
  requireBytes(field, lightFieldBytes(frame), "light field");
  if (calibratedInjection != nullptr)
    requireBytes(*calibratedInjection, VkDeviceSize(cells) * SSLPV_CALIBRATED_INJECTION_VEC4 * kVec4,
                 "calibrated injection");

  // Rewritten every recording, hence one recording in flight per injector (see the class).
  sets_.write(0, 0, samples);
  sets_.write(0, 1, cellCoverage);
  sets_.write(0, 2, field);
  sets_.write(0, 4, calibratedInjection != nullptr ? *calibratedInjection : noCalibration_);

  InjectPush push{};
  push.gridOriginX = float(frame.origin.x);
  push.gridOriginY = float(frame.origin.y);
  push.gridOriginZ = float(frame.origin.z);
  push.gridCellSize = float(frame.cellSize);
  push.gridDimsX = frame.dims.x;
  push.gridDimsY = frame.dims.y;
  push.gridDimsZ = frame.dims.z;
  push.sampleCount = sampleCount;
  push.calibrated = calibratedInjection != nullptr ? 1u : 0u;

  deviceWritesBarrier(cmd);  // samples, coverage or field written earlier on the queue
  if (clearField) {
    vkCmdFillBuffer(cmd, field.handle(), 0, VK_WHOLE_SIZE, 0);
    deviceWritesBarrier(cmd);
  }
  groups_ =
      std::min<std::uint32_t>(options_.maxWorkgroups, (sampleCount + SSLPV_INJECT_GROUP - 1) / SSLPV_INJECT_GROUP);
  if (groups_ > 0) {
    pipeline_.bind(cmd, sets_.set(0), &push, sizeof(push));
    vkCmdDispatch(cmd, groups_, 1, 1);
  }
  injectionDoneBarrier(cmd);
}

InjectionStats GpuInjector::stats() const {
  InjectionStats stats;
  const float* rows = partials_.mappedAs<const float>();
  for (std::uint32_t g = 0; g < groups_; ++g) {
    const float* row = rows + std::size_t(g) * SSLPV_INJECT_STATS_VEC4 * 4;
    for (int ch = 0; ch < 3; ++ch) {
      stats.injectedFlux[ch] += row[ch];
      stats.droppedFlux[ch] += row[4 + ch];
    }
  }
  return stats;
}

InjectionStats GpuInjector::run(const Buffer& samples, std::uint32_t sampleCount, const Buffer& cellCoverage,
                                const GridFrame& frame, const Buffer& field, bool clearField,
                                const Buffer* calibratedInjection) {
  VkCommandBuffer cmd = commands_.begin();
  timestamps_.reset(cmd);
  timestamps_.write(cmd, 0);
  record(cmd, samples, sampleCount, cellCoverage, frame, field, clearField, calibratedInjection);
  timestamps_.write(cmd, 1);
  commands_.submitAndWait();
  lastRunMs_ = timestamps_.readMilliseconds(2)[1];
  return stats();
}

}  // namespace sslpv::gpu
