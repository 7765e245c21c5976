#pragma once
// Move-only owners of Vulkan objects, and buffers with their memory. Every object must
// be destroyed before the VulkanDevice it was created on.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <utility>

#include "gpu/vk/device.h"

namespace sslpv::gpu {

/// Owns one object released with `Destroy(device, handle, nullptr)` (vkDestroyBuffer,
/// vkFreeMemory, vkDestroyPipeline, ...).
template <typename Handle, void (*Destroy)(VkDevice, Handle, const VkAllocationCallbacks*)>
class DeviceObject {
 public:
  DeviceObject() = default;
  DeviceObject(VkDevice device, Handle handle) : device_(device), handle_(handle) {}
  ~DeviceObject() { reset(); }
  DeviceObject(DeviceObject&& other) noexcept
      : device_(other.device_), handle_(std::exchange(other.handle_, Handle(VK_NULL_HANDLE))) {}
  DeviceObject& operator=(DeviceObject&& other) noexcept {
    if (this != &other) {
      reset();
      device_ = other.device_;
      handle_ = std::exchange(other.handle_, Handle(VK_NULL_HANDLE));
    }
    return *this;
  }
  DeviceObject(const DeviceObject&) = delete;
  DeviceObject& operator=(const DeviceObject&) = delete;

  Handle get() const { return handle_; }
  explicit operator bool() const { return handle_ != VK_NULL_HANDLE; }
  void reset() {
    if (handle_ != VK_NULL_HANDLE) Destroy(device_, handle_, nullptr);
    handle_ = VK_NULL_HANDLE;
  }

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  Handle handle_ = VK_NULL_HANDLE;
};

using BufferHandle = DeviceObject<VkBuffer, vkDestroyBuffer>;
using MemoryHandle = DeviceObject<VkDeviceMemory, vkFreeMemory>;
using ShaderModule = DeviceObject<VkShaderModule, vkDestroyShaderModule>;
using DescriptorSetLayout = DeviceObject<VkDescriptorSetLayout, vkDestroyDescriptorSetLayout>;
using DescriptorPool = DeviceObject<VkDescriptorPool, vkDestroyDescriptorPool>;
using PipelineLayout = DeviceObject<VkPipelineLayout, vkDestroyPipelineLayout>;
using Pipeline = DeviceObject<VkPipeline, vkDestroyPipeline>;
using CommandPool = DeviceObject<VkCommandPool, vkDestroyCommandPool>;
using Fence = DeviceObject<VkFence, vkDestroyFence>;
using Semaphore = DeviceObject<VkSemaphore, vkDestroySemaphore>;
using QueryPool = DeviceObject<VkQueryPool, vkDestroyQueryPool>;

/// Where a buffer's memory lives.
enum class MemoryUse {
  /// Read and written by shaders. Mapped for direct host access where device memory is
  /// the host's (lavapipe, integrated GPUs); elsewhere it needs staging copies.
  Device,
  /// Host-visible and coherent, for uploads, readbacks and small control records.
  Host,
};

/// Index of a memory type allowed by `typeBits` with all `required` flags, preferring
/// one that also has `preferred`; GpuError when there is none.
std::uint32_t findMemoryType(const VkPhysicalDeviceMemoryProperties& memory, std::uint32_t typeBits,
                             VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred);

/// A VkBuffer bound to its own allocation, persistently mapped when host-visible.
class Buffer {
 public:
  Buffer() = default;
  Buffer(const VulkanDevice& device, VkDeviceSize size, VkBufferUsageFlags usage, MemoryUse use);
  Buffer(Buffer&& other) noexcept
      : memory_(std::move(other.memory_)),
        buffer_(std::move(other.buffer_)),
        size_(std::exchange(other.size_, 0)),
        mapped_(std::exchange(other.mapped_, nullptr)) {}
  Buffer& operator=(Buffer&& other) noexcept {
    buffer_ = std::move(other.buffer_);  // the buffer goes before the memory it is bound to
    memory_ = std::move(other.memory_);
    size_ = std::exchange(other.size_, 0);
    mapped_ = std::exchange(other.mapped_, nullptr);
    return *this;
  }

  VkBuffer handle() const { return buffer_.get(); }
  VkDeviceSize size() const { return size_; }
  /// Host address of the contents (coherent), or nullptr when not host-visible.
  void* mapped() const { return mapped_; }
  template <typename T>
  T* mappedAs() const {
    return static_cast<T*>(mapped_);
  }

 private:
  // Declared before the buffer so that the buffer is destroyed first.
  MemoryHandle memory_;
  BufferHandle buffer_;
  VkDeviceSize size_ = 0;
  void* mapped_ = nullptr;
};

}  // namespace sslpv::gpu
