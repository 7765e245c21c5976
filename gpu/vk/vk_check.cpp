#include "gpu/vk/vk_check.h"

namespace sslpv::gpu {

std::string resultName(VkResult result) {
  switch (result) {
#define SSLPV_RESULT_CASE(name) \
  case name:                    \
    return #name;
    SSLPV_RESULT_CASE(VK_SUCCESS)
    SSLPV_RESULT_CASE(VK_NOT_READY)
    SSLPV_RESULT_CASE(VK_TIMEOUT)
    SSLPV_RESULT_CASE(VK_EVENT_SET)
    SSLPV_RESULT_CASE(VK_EVENT_RESET)
    SSLPV_RESULT_CASE(VK_INCOMPLETE)
    SSLPV_RESULT_CASE(VK_ERROR_OUT_OF_HOST_MEMORY)
    SSLPV_RESULT_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    SSLPV_RESULT_CASE(VK_ERROR_INITIALIZATION_FAILED)
    SSLPV_RESULT_CASE(VK_ERROR_DEVICE_LOST)
    SSLPV_RESULT_CASE(VK_ERROR_MEMORY_MAP_FAILED)
    SSLPV_RESULT_CASE(VK_ERROR_LAYER_NOT_PRESENT)
    SSLPV_RESULT_CASE(VK_ERROR_EXTENSION_NOT_PRESENT)
    SSLPV_RESULT_CASE(VK_ERROR_FEATURE_NOT_PRESENT)
    SSLPV_RESULT_CASE(VK_ERROR_INCOMPATIBLE_DRIVER)
    SSLPV_RESULT_CASE(VK_ERROR_TOO_MANY_OBJECTS)
    SSLPV_RESULT_CASE(VK_ERROR_FORMAT_NOT_SUPPORTED)
    SSLPV_RESULT_CASE(VK_ERROR_FRAGMENTED_POOL)
    SSLPV_RESULT_CASE(VK_ERROR_UNKNOWN)
    SSLPV_RESULT_CASE(VK_ERROR_OUT_OF_POOL_MEMORY)
    SSLPV_RESULT_CASE(VK_ERROR_INVALID_EXTERNAL_HANDLE)
    SSLPV_RESULT_CASE(VK_ERROR_FRAGMENTATION)
    SSLPV_RESULT_CASE(VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS)
    SSLPV_RESULT_CASE(VK_PIPELINE_COMPILE_REQUIRED)
    SSLPV_RESULT_CASE(VK_ERROR_SURFACE_LOST_KHR)
    SSLPV_RESULT_CASE(VK_ERROR_NATIVE_WINDOW_IN_USE_KHR)
    SSLPV_RESULT_CASE(VK_SUBOPTIMAL_KHR)
    SSLPV_RESULT_CASE(VK_ERROR_OUT_OF_DATE_KHR)
    SSLPV_RESULT_CASE(VK_ERROR_VALIDATION_FAILED_EXT)
#undef SSLPV_RESULT_CASE
    default:
      return "VkResult(" + std::to_string(int(result)) + ")";
  }
}

void throwOnFailure(VkResult result, const char* expression, const char* file, int line) {
  if (result == VK_SUCCESS) return;
  // Paths relative to the repository read better than the build machine's absolute ones.
  std::string where = file;
  if (const std::size_t pos = where.rfind("/gpu/"); pos != std::string::npos) where = where.substr(pos + 1);
  throw GpuError(std::string(expression) + " failed: " + resultName(result) + " at " + where + ":" +
                 std::to_string(line));
}

}  // namespace sslpv::gpu
