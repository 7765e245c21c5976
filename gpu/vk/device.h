#pragma once
// The Vulkan device the backend computes on: a headless instance, optional validation
// whose messages are counted (tests assert none), and a physical device chosen by type
// (discrete > integrated > virtual > CPU, so lavapipe is the fallback) or by name.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "gpu/vk/vk_check.h"

namespace sslpv::gpu {

struct DeviceOptions {
  /// Enable VK_LAYER_KHRONOS_validation and count its warnings and errors; GpuError when
  /// the layer is not installed.
  bool validation = false;
  /// Pick the first device whose name contains this (case-insensitive) substring; unset:
  /// the SSLPV_VULKAN_DEVICE environment variable, and when that is unset too, by type.
  std::optional<std::string> deviceName;
  /// Instance extensions a window system needs to present (what glfwGetRequiredInstanceExtensions
  /// lists); empty: a headless instance.
  std::vector<std::string> instanceExtensions;
  /// Enable VK_KHR_swapchain for presenting to a window; GpuError when the device lacks it.
  bool swapchain = false;
};

/// One validation-layer (or loader) message of severity warning or error.
struct ValidationMessage {
  bool error = false;  ///< false: warning
  std::string text;
};

/// The messages validation reported, thread-safe. Shared, so that a test can still read
/// it after the device is gone (leak reports arrive while the device is destroyed).
class ValidationLog {
 public:
  void add(ValidationMessage message);
  std::size_t count() const;
  std::vector<ValidationMessage> messages() const;
  /// All messages, one per line (for test failure output).
  std::string text() const;

 private:
  mutable std::mutex mutex_;
  std::vector<ValidationMessage> messages_;
};

/// Instance, physical device, logical device and one compute queue. Not movable: the
/// debug messenger and every resource created on it refer to it.
class VulkanDevice {
 public:
  /// Throws NoVulkanDeviceError when Vulkan or a usable device is missing, GpuError when
  /// the requested device name matches none (the message lists the available ones).
  explicit VulkanDevice(const DeviceOptions& options = {});
  ~VulkanDevice();
  VulkanDevice(const VulkanDevice&) = delete;
  VulkanDevice& operator=(const VulkanDevice&) = delete;

  VkInstance instance() const { return instance_; }
  VkPhysicalDevice physicalDevice() const { return physicalDevice_; }
  VkDevice handle() const { return device_; }
  VkQueue queue() const { return queue_; }
  std::uint32_t queueFamily() const { return queueFamily_; }
  const VkPhysicalDeviceProperties& properties() const { return properties_; }
  const VkPhysicalDeviceMemoryProperties& memoryProperties() const { return memoryProperties_; }
  std::string name() const { return properties_.deviceName; }
  /// Vulkan implemented on the CPU (Mesa lavapipe): there the CPU backend, on the same
  /// cores without the JIT's overheads, renders several times faster (`--backend auto`).
  bool runsOnCpu() const { return properties_.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU; }
  /// Device memory is the host's memory (CPU and integrated devices): device-local
  /// buffers are mapped directly instead of going through staging copies.
  bool unifiedMemory() const;
  /// Nanoseconds per timestamp tick, and the valid bits of timestamps on the queue (0:
  /// timestamps unsupported).
  double timestampPeriodNs() const { return properties_.limits.timestampPeriod; }
  std::uint32_t timestampValidBits() const { return timestampValidBits_; }
  /// shaderBufferFloat32AtomicAdd (VK_EXT_shader_atomic_float) is enabled: float
  /// atomicAdd on storage buffers, which GPU injection needs. Enabled wherever offered.
  bool bufferFloatAtomicAdd() const { return bufferFloatAtomicAdd_; }

  bool validationEnabled() const { return messenger_ != VK_NULL_HANDLE; }
  /// Warnings and errors reported by validation since the instance was created.
  std::size_t validationMessageCount() const { return log_->count(); }
  std::shared_ptr<const ValidationLog> validationLog() const { return log_; }

  /// Submits to the compute queue (Vulkan queues need external synchronization).
  void submit(const VkSubmitInfo& submit, VkFence fence) const;
  /// vkQueuePresentKHR on the same queue, under the same lock as submit(): a window
  /// presents while a renderer thread submits. Needs DeviceOptions::swapchain.
  VkResult present(const VkPresentInfoKHR& info) const;

  /// Names of the physical devices Vulkan reports (empty when none or no Vulkan).
  static std::vector<std::string> availableDevices();

 private:
  void createInstance(const DeviceOptions& options);
  void selectPhysicalDevice(const DeviceOptions& options);
  void createDevice(bool swapchain);
  void release();

  std::shared_ptr<ValidationLog> log_;
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physicalDevice_ = VK_NULL_HANDLE;
  VkPhysicalDeviceProperties properties_{};
  VkPhysicalDeviceMemoryProperties memoryProperties_{};
  std::uint32_t queueFamily_ = 0;
  std::uint32_t timestampValidBits_ = 0;
  bool bufferFloatAtomicAdd_ = false;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  mutable std::mutex queueMutex_;
};

}  // namespace sslpv::gpu
