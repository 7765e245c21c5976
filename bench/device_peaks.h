#pragma once
// The Vulkan device's own limits, measured in the benchmark's run: FMA rate
// (shaders/lpv_peak_fma.comp) and copy bandwidth (the vec4 STREAM triad of
// lpv_peak_triad.comp, as storage buffers and as texel buffers), and the propagation
// kernel's work per active cell and step, so that benchmarks print a roofline ratio.
// The counting is explained in bench/gpu_propagation_bench.cpp's header comment.
#include <algorithm>
#include <vector>

#include "gpu/vk/compute.h"
#include "gpu/vk/device.h"
#include "gpu/vk/resources.h"
#include "shaders/spirv_library.h"

namespace sslpv::bench {

inline constexpr double kFlopsPerCellStep = 3 * (169 + 7 + 24) + 3 * 24 + 42 + 12;
inline constexpr double kBytesPerCellStep = 48 + 32 + 48 + 48;
/// The calibrated scheme's isotropic steps (gpu_propagation_bench's header): same bytes.
inline constexpr double kIsotropicFlopsPerCellStep = 3 * (4 + 24 + 2 + 13 + 4);

/// Mean flop per active cell-step of a run of `steps` in the calibrated scheme (the first
/// step general, the rest isotropic; the semi-iteration's few extra adds not counted) or
/// the seed's (all general).
inline double propagationFlopsPerCellStep(bool calibrated, int steps) {
  if (!calibrated || steps < 2) return kFlopsPerCellStep;
  return (kFlopsPerCellStep + (steps - 1) * kIsotropicFlopsPerCellStep) / steps;
}

inline double medianOf(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

struct Peaks {
  double fmaGflops = 0.0, ssboGBs = 0.0, texelGBs = 0.0;
  double bandwidth() const { return std::max(ssboGBs, texelGBs); }
};

/// Median GPU milliseconds of `record` over `repeats` submissions after a warm-up.
template <typename Record>
inline double timeDispatch(gpu::CommandContext& commands, gpu::TimestampQueries& stamps, int repeats, Record record) {
  std::vector<double> ms;
  for (int r = 0; r <= repeats; ++r) {
    VkCommandBuffer cmd = commands.begin();
    stamps.reset(cmd);
    stamps.write(cmd, 0);
    record(cmd);
    stamps.write(cmd, 1);
    commands.submitAndWait();
    if (r > 0) ms.push_back(stamps.readMilliseconds(2)[1]);
  }
  return medianOf(ms);
}

/// The device's own peaks, measured again next to every case: on a shared machine the
/// cores' speed changes with the other load, and the roofline must be the one the case
/// actually ran under.
class PeakProbe {
 public:
  explicit PeakProbe(const gpu::VulkanDevice& device)
      : commands_(device), stamps_(device, 2), fmaResult_(device, kFmaGroups * 64 * 16, kUsage, gpu::MemoryUse::Device) {
    using namespace gpu;
    fmaLayout_ = makeStorageBufferSetLayout(device, 1);
    fma_ = ComputePipeline(device, spirv::lpv_peak_fma_comp(), fmaLayout_.get(), sizeof(int));
    fmaSets_ = StorageBufferSets(device, fmaLayout_.get(), 1, 1);
    fmaSets_.write(0, 0, fmaResult_);
    for (Buffer& b : triadBuffers_) b = Buffer(device, kTriadBytes, kUsage, MemoryUse::Device);
    // Storage buffers at bindings 0..2, texel views of b and c at 3 and 4.
    VkDescriptorSetLayoutBinding bindings[5]{};
    for (std::uint32_t i = 0; i < 5; ++i)
      bindings[i] = {i, i < 3 ? VK_DESCRIPTOR_TYPE_STORAGE_BUFFER : VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, 1,
                     VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
    VkDescriptorSetLayoutCreateInfo layoutInfo{};
    layoutInfo.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    layoutInfo.bindingCount = 5;
    layoutInfo.pBindings = bindings;
    VkDescriptorSetLayout rawLayout = VK_NULL_HANDLE;
    SSLPV_VK_CHECK(vkCreateDescriptorSetLayout(device.handle(), &layoutInfo, nullptr, &rawLayout));
    triadLayout_ = DescriptorSetLayout(device.handle(), rawLayout);
    const VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 3},
                                           {VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, 2}};
    VkDescriptorPoolCreateInfo poolInfo{};
    poolInfo.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
    poolInfo.maxSets = 1;
    poolInfo.poolSizeCount = 2;
    poolInfo.pPoolSizes = sizes;
    VkDescriptorPool rawPool = VK_NULL_HANDLE;
    SSLPV_VK_CHECK(vkCreateDescriptorPool(device.handle(), &poolInfo, nullptr, &rawPool));
    pool_ = DescriptorPool(device.handle(), rawPool);
    VkDescriptorSetAllocateInfo allocate{};
    allocate.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
    allocate.descriptorPool = rawPool;
    allocate.descriptorSetCount = 1;
    allocate.pSetLayouts = &rawLayout;
    SSLPV_VK_CHECK(vkAllocateDescriptorSets(device.handle(), &allocate, &triadSet_));
    for (int k = 0; k < 2; ++k) {
      VkBufferViewCreateInfo viewInfo{};
      viewInfo.sType = VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO;
      viewInfo.buffer = triadBuffers_[1 + k].handle();
      viewInfo.format = VK_FORMAT_R32G32B32A32_SFLOAT;
      viewInfo.range = VK_WHOLE_SIZE;
      VkBufferView view = VK_NULL_HANDLE;
      SSLPV_VK_CHECK(vkCreateBufferView(device.handle(), &viewInfo, nullptr, &view));
      views_[k] = BufferView(device.handle(), view);
    }
    VkDescriptorBufferInfo infos[3];
    for (int k = 0; k < 3; ++k) infos[k] = {triadBuffers_[k].handle(), 0, VK_WHOLE_SIZE};
    const VkBufferView rawViews[2] = {views_[0].get(), views_[1].get()};
    VkWriteDescriptorSet writes[5]{};
    for (std::uint32_t i = 0; i < 5; ++i) {
      writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
      writes[i].dstSet = triadSet_;
      writes[i].dstBinding = i;
      writes[i].descriptorCount = 1;
      writes[i].descriptorType = bindings[i].descriptorType;
      if (i < 3) writes[i].pBufferInfo = &infos[i];
      else writes[i].pTexelBufferView = &rawViews[i - 3];
    }
    vkUpdateDescriptorSets(device.handle(), 5, writes, 0, nullptr);
    for (std::uint32_t texel = 0; texel < 2; ++texel)
      triads_[texel] = ComputePipeline(device, spirv::lpv_peak_triad_comp(), rawLayout, sizeof(TriadPush), {texel});
  }

  Peaks measure(int repeats) {
    Peaks peaks;
    const int iterations = kFmaIterations;
    const double fmaMs = timeDispatch(commands_, stamps_, repeats, [&](VkCommandBuffer cmd) {
      fma_.bind(cmd, fmaSets_.set(0), &iterations, sizeof(iterations));
      vkCmdDispatch(cmd, kFmaGroups, 1, 1);
    });
    peaks.fmaGflops = double(kFmaGroups) * 64 * kFmaIterations * 128 / (fmaMs * 1e6);  // 16 vec4 FMA chains a lane
    const TriadPush push{int(kTriadBytes / 16), 0.5f};
    for (int texel = 0; texel < 2; ++texel) {
      const double ms = timeDispatch(commands_, stamps_, repeats, [&](VkCommandBuffer cmd) {
        triads_[texel].bind(cmd, triadSet_, &push, sizeof(push));
        vkCmdDispatch(cmd, std::uint32_t(push.count / 64), 1, 1);
      });
      (texel ? peaks.texelGBs : peaks.ssboGBs) = 3.0 * double(kTriadBytes) / (ms * 1e6);
    }
    return peaks;
  }

 private:
  using BufferView = gpu::DeviceObject<VkBufferView, vkDestroyBufferView>;
  struct TriadPush {
    int count;
    float scale;
  };
  static constexpr std::uint32_t kFmaGroups = 1024;
  static constexpr int kFmaIterations = 500;
  static constexpr VkDeviceSize kTriadBytes = VkDeviceSize(16) << 21;  // 32 MiB a buffer: far beyond the caches
  static constexpr VkBufferUsageFlags kUsage =
      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT;

  gpu::CommandContext commands_;
  gpu::TimestampQueries stamps_;
  gpu::Buffer fmaResult_;
  gpu::DescriptorSetLayout fmaLayout_, triadLayout_;
  gpu::ComputePipeline fma_, triads_[2];
  gpu::StorageBufferSets fmaSets_;
  gpu::Buffer triadBuffers_[3];
  gpu::DescriptorPool pool_;
  VkDescriptorSet triadSet_ = VK_NULL_HANDLE;
  BufferView views_[2];
};

}  // namespace sslpv::bench
