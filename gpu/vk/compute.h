#pragma once
// Compute building blocks: pipelines from embedded SPIR-V, descriptor sets of storage
// buffers, a command buffer recorded and submitted synchronously, and GPU timestamps.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

#include "gpu/vk/resources.h"
#include "shaders/spirv_library.h"

namespace sslpv::gpu {

/// Layout of `bindingCount` storage buffers at bindings 0..n-1 visible to `stages`; one
/// layout may serve a graphics and a compute pipeline of the same pass.
DescriptorSetLayout makeStorageBufferSetLayout(const VulkanDevice& device, std::uint32_t bindingCount,
                                               VkShaderStageFlags stages = VK_SHADER_STAGE_COMPUTE_BIT);

/// A compute pipeline with its shader module and layout (one descriptor set, optional
/// push constants). `specialization[i]` is the uint32 value of constant_id i.
class ComputePipeline {
 public:
  ComputePipeline() = default;
  ComputePipeline(const VulkanDevice& device, const spirv::SpirvCode& code, VkDescriptorSetLayout setLayout,
                  std::uint32_t pushConstantBytes, const std::vector<std::uint32_t>& specialization = {});

  VkPipeline pipeline() const { return pipeline_.get(); }
  VkPipelineLayout layout() const { return layout_.get(); }

  /// Binds the pipeline and `set`, and pushes `pushBytes` bytes of `push` (if any).
  void bind(VkCommandBuffer cmd, VkDescriptorSet set, const void* push = nullptr, std::uint32_t pushBytes = 0) const;

 private:
  ShaderModule module_;
  PipelineLayout layout_;
  Pipeline pipeline_;
};

/// `setCount` descriptor sets of one storage-buffer layout, from their own pool.
class StorageBufferSets {
 public:
  StorageBufferSets() = default;
  StorageBufferSets(const VulkanDevice& device, VkDescriptorSetLayout layout, std::uint32_t bindingCount,
                    std::uint32_t setCount);

  VkDescriptorSet set(std::size_t index) const { return sets_.at(index); }
  /// Points `binding` of set `index` at the whole of `buffer`.
  void write(std::size_t index, std::uint32_t binding, const Buffer& buffer) const;

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  DescriptorPool pool_;  // frees the sets with it
  std::vector<VkDescriptorSet> sets_;
};

/// One primary command buffer, recorded then submitted and waited for.
class CommandContext {
 public:
  explicit CommandContext(const VulkanDevice& device);
  /// Resets the command buffer and begins a one-time submission.
  VkCommandBuffer begin();
  /// Ends recording, submits to the device's queue and blocks until it has executed.
  void submitAndWait();

 private:
  const VulkanDevice* device_;
  CommandPool pool_;  // frees the command buffer with it
  Fence fence_;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
};

/// Makes compute-shader writes visible to later compute reads and writes.
void computeToComputeBarrier(VkCommandBuffer cmd);
/// Makes earlier transfer and compute writes (also from earlier submissions) visible to
/// later transfers and shaders: the first command of a submission that uses them.
void deviceWritesBarrier(VkCommandBuffer cmd);
/// Makes compute and transfer writes visible to the host after the fence.
void toHostBarrier(VkCommandBuffer cmd);

/// A pool of GPU timestamps written between commands, read back as milliseconds.
class TimestampQueries {
 public:
  TimestampQueries() = default;
  TimestampQueries(const VulkanDevice& device, std::uint32_t capacity);

  /// False where the queue has no timestamps: writes are skipped, times read as 0.
  bool supported() const { return bool(pool_); }
  std::uint32_t capacity() const { return capacity_; }
  void reset(VkCommandBuffer cmd);
  /// Timestamp `index` once all earlier commands have finished.
  void write(VkCommandBuffer cmd, std::uint32_t index);
  /// Milliseconds of the first `count` timestamps, relative to timestamp 0 (after the
  /// submission has completed).
  std::vector<double> readMilliseconds(std::uint32_t count) const;

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  QueryPool pool_;
  std::uint32_t capacity_ = 0;
  double periodNs_ = 1.0;
  std::uint64_t validMask_ = 0;
};

}  // namespace sslpv::gpu
