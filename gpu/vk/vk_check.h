#pragma once
// Vulkan failures as exceptions: every VkResult is checked, and a failure names the call,
// the result and the place ("vkCreateBuffer(...) failed: VK_ERROR_OUT_OF_DEVICE_MEMORY at
// gpu/buffer.cpp:42").
#include <vulkan/vulkan.h>

#include <stdexcept>
#include <string>

namespace sslpv {

/// A Vulkan call failed or the Vulkan backend cannot run as asked.
class GpuError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// No usable Vulkan device (or no Vulkan at all) on this machine: callers fall back to
/// the CPU backend, and GPU tests skip.
class NoVulkanDeviceError : public GpuError {
 public:
  using GpuError::GpuError;
};

namespace gpu {

/// "VK_ERROR_OUT_OF_DEVICE_MEMORY" for a VkResult, or "VkResult(<n>)" when unknown.
std::string resultName(VkResult result);

/// Throws GpuError "<expression> failed: <result> at <file>:<line>" unless result is
/// VK_SUCCESS. Calls with other acceptable statuses (VK_INCOMPLETE...) check by hand.
void throwOnFailure(VkResult result, const char* expression, const char* file, int line);

}  // namespace gpu
}  // namespace sslpv

/// Evaluates a Vulkan call and throws sslpv::GpuError naming it when it does not succeed.
#define SSLPV_VK_CHECK(call) ::sslpv::gpu::throwOnFailure((call), #call, __FILE__, __LINE__)
