#include "gpu/vk/device.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <iostream>

namespace sslpv::gpu {

void ValidationLog::add(ValidationMessage message) {
  std::lock_guard<std::mutex> lock(mutex_);
  messages_.push_back(std::move(message));
}

std::size_t ValidationLog::count() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return messages_.size();
}

std::vector<ValidationMessage> ValidationLog::messages() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return messages_;
}

std::string ValidationLog::text() const {
  std::string all;
  for (const ValidationMessage& m : messages()) all += (m.error ? "error: " : "warning: ") + m.text + "\n";
  return all;
}

namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
constexpr const char* kNoDevice = "no Vulkan device found (install mesa-vulkan-drivers for lavapipe)";

VKAPI_ATTR VkBool32 VKAPI_CALL onDebugMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                              VkDebugUtilsMessageTypeFlagsEXT /*types*/,
                                              const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  auto* log = static_cast<ValidationLog*>(user);
  ValidationMessage message{(severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) != 0,
                            data && data->pMessage ? data->pMessage : "(no message)"};
  // Printed as well as counted: a test that fails on the count shows what went wrong.
  std::cerr << "[vulkan " << (message.error ? "error" : "warning") << "] " << message.text << "\n";
  log->add(std::move(message));
  return VK_FALSE;  // never abort the call that triggered the message
}

VkDebugUtilsMessengerCreateInfoEXT messengerInfo(ValidationLog* log) {
  VkDebugUtilsMessengerCreateInfoEXT info{};
  info.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
  info.messageSeverity =
      VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                     VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  info.pfnUserCallback = onDebugMessage;
  info.pUserData = log;
  return info;
}

bool hasLayer(const char* name) {
  std::uint32_t count = 0;
  if (vkEnumerateInstanceLayerProperties(&count, nullptr) != VK_SUCCESS) return false;
  std::vector<VkLayerProperties> layers(count);
  if (vkEnumerateInstanceLayerProperties(&count, layers.data()) != VK_SUCCESS) return false;
  return std::any_of(layers.begin(), layers.end(),
                     [&](const VkLayerProperties& l) { return std::strcmp(l.layerName, name) == 0; });
}

std::string lowercase(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

/// Higher is preferred: real GPUs first, lavapipe (CPU) last.
int typeRank(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return 4;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return 3;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return 1;
    default:
      return 0;
  }
}

/// A queue family with compute, preferring one that also does graphics (the render
/// passes share it); nullopt when the device has no compute queue.
std::optional<std::uint32_t> computeQueueFamily(VkPhysicalDevice device, std::uint32_t* timestampBits) {
  std::uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, families.data());
  std::optional<std::uint32_t> best;
  for (std::uint32_t i = 0; i < count; ++i) {
    if (!(families[i].queueFlags & VK_QUEUE_COMPUTE_BIT)) continue;
    const bool graphics = families[i].queueFlags & VK_QUEUE_GRAPHICS_BIT;
    if (!best || (graphics && !(families[*best].queueFlags & VK_QUEUE_GRAPHICS_BIT))) best = i;
  }
  if (best && timestampBits) *timestampBits = families[*best].timestampValidBits;
  return best;
}

bool hasDeviceExtension(VkPhysicalDevice device, const char* name) {
  std::uint32_t count = 0;
  if (vkEnumerateDeviceExtensionProperties(device, nullptr, &count, nullptr) != VK_SUCCESS) return false;
  std::vector<VkExtensionProperties> extensions(count);
  if (vkEnumerateDeviceExtensionProperties(device, nullptr, &count, extensions.data()) != VK_SUCCESS) return false;
  return std::any_of(extensions.begin(), extensions.end(),
                     [&](const VkExtensionProperties& e) { return std::strcmp(e.extensionName, name) == 0; });
}

std::vector<VkPhysicalDevice> physicalDevices(VkInstance instance) {
  std::uint32_t count = 0;
  SSLPV_VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, nullptr));
  std::vector<VkPhysicalDevice> devices(count);
  if (count > 0) {
    const VkResult result = vkEnumeratePhysicalDevices(instance, &count, devices.data());
    if (result != VK_INCOMPLETE) SSLPV_VK_CHECK(result);
    devices.resize(count);
  }
  return devices;
}

}  // namespace

VulkanDevice::VulkanDevice(const DeviceOptions& options) : log_(std::make_shared<ValidationLog>()) {
  try {
    createInstance(options);
    selectPhysicalDevice(options);
    createDevice(options.swapchain);
  } catch (...) {
    release();  // the destructor does not run for a throwing constructor
    throw;
  }
}

VulkanDevice::~VulkanDevice() { release(); }

void VulkanDevice::release() {
  if (device_ != VK_NULL_HANDLE) {
    vkDeviceWaitIdle(device_);
    vkDestroyDevice(device_, nullptr);
    device_ = VK_NULL_HANDLE;
  }
  if (messenger_ != VK_NULL_HANDLE) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(instance_, messenger_, nullptr);
    messenger_ = VK_NULL_HANDLE;
  }
  if (instance_ != VK_NULL_HANDLE) {
    vkDestroyInstance(instance_, nullptr);
    instance_ = VK_NULL_HANDLE;
  }
}

void VulkanDevice::createInstance(const DeviceOptions& options) {
  const bool validation = options.validation;
  std::uint32_t version = VK_API_VERSION_1_0;
  if (vkEnumerateInstanceVersion(&version) != VK_SUCCESS || version < VK_API_VERSION_1_2)
    throw NoVulkanDeviceError(std::string(kNoDevice) + ": the Vulkan loader is older than 1.2");
  if (validation && !hasLayer(kValidationLayer))
    throw GpuError(std::string("Vulkan validation requested but ") + kValidationLayer +
                   " is not installed (install vulkan-validationlayers)");

  VkApplicationInfo app{};

  app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  app.pApplicationName = "sslpv";
  app.pEngineName = "sslpv";
  // 1.3 where the device has it: the raster passes use dynamic rendering (core in 1.3).
  app.apiVersion = VK_API_VERSION_1_3;
  // Headless unless a window asks for its surface extensions.
  std::vector<const char*> extensions, layers;
  for (const std::string& name : options.instanceExtensions) extensions.push_back(name.c_str());
  if (validation) {
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    layers.push_back(kValidationLayer);
  }
  // Chained into the instance too, so messages from vkCreateInstance/vkDestroyInstance count.
  const VkDebugUtilsMessengerCreateInfoEXT debugInfo = messengerInfo(log_.get());
  VkInstanceCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
  info.pNext = validation ? &debugInfo : nullptr;
  info.pApplicationInfo = &app;
  info.enabledExtensionCount = std::uint32_t(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  info.enabledLayerCount = std::uint32_t(layers.size());
  info.ppEnabledLayerNames = layers.data();
  const VkResult result = vkCreateInstance(&info, nullptr, &instance_);
  if (result == VK_ERROR_INCOMPATIBLE_DRIVER) throw NoVulkanDeviceError(kNoDevice);
  SSLPV_VK_CHECK(result);

  if (validation) {
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
    if (!create) throw GpuError("Vulkan validation requested but vkCreateDebugUtilsMessengerEXT is unavailable");
    SSLPV_VK_CHECK(create(instance_, &debugInfo, nullptr, &messenger_));
  }
}

void VulkanDevice::selectPhysicalDevice(const DeviceOptions& options) {
  const std::vector<VkPhysicalDevice> devices = physicalDevices(instance_);
  if (devices.empty()) throw NoVulkanDeviceError(kNoDevice);

  std::string wanted, source;
  if (options.deviceName) {
    wanted = *options.deviceName;
    source = "requested Vulkan device";
  } else if (const char* env = std::getenv("SSLPV_VULKAN_DEVICE"); env && *env) {
    wanted = env;
    source = "SSLPV_VULKAN_DEVICE";
  }

  std::string available;
  int bestRank = -1;
  for (VkPhysicalDevice device : devices) {
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(device, &props);
    available += std::string(available.empty() ? "" : ", ") + "\"" + props.deviceName + "\"";
    if (!wanted.empty() && lowercase(props.deviceName).find(lowercase(wanted)) == std::string::npos) continue;
    std::uint32_t timestampBits = 0;
    const std::optional<std::uint32_t> family = computeQueueFamily(device, &timestampBits);
    const bool usable = family && props.apiVersion >= VK_API_VERSION_1_2;
    if (!usable && !wanted.empty())
      throw GpuError(source + " \"" + wanted + "\" (" + props.deviceName +
                     ") cannot run the backend: it needs Vulkan 1.2 and a compute queue");
    if (!usable) continue;
    const int rank = typeRank(props.deviceType);
    if (rank > bestRank) {
      bestRank = rank;
      physicalDevice_ = device;
      properties_ = props;
      queueFamily_ = *family;
      timestampValidBits_ = timestampBits;
    }
  }
  if (physicalDevice_ == VK_NULL_HANDLE) {
    if (!wanted.empty())
      throw GpuError(source + "=\"" + wanted + "\" matches no Vulkan device (available: " + available + ")");
    throw NoVulkanDeviceError(std::string(kNoDevice) + ": none of " + available +
                              " supports Vulkan 1.2 with a compute queue");
  }
  vkGetPhysicalDeviceMemoryProperties(physicalDevice_, &memoryProperties_);
}

void VulkanDevice::createDevice(bool swapchain) {
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queueInfo{};
  queueInfo.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
  queueInfo.queueFamilyIndex = queueFamily_;
  queueInfo.queueCount = 1;
  queueInfo.pQueuePriorities = &priority;
  // Float atomics let GPU injection add overlapping lobes from many samples; enabled
  // wherever offered, and GpuInjector refuses a device without them.
  std::vector<const char*> extensions;
  VkPhysicalDeviceShaderAtomicFloatFeaturesEXT atomicFloat{};
  atomicFloat.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_ATOMIC_FLOAT_FEATURES_EXT;
  if (hasDeviceExtension(physicalDevice_, VK_EXT_SHADER_ATOMIC_FLOAT_EXTENSION_NAME)) {
    VkPhysicalDeviceFeatures2 features{};
    features.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    features.pNext = &atomicFloat;
    vkGetPhysicalDeviceFeatures2(physicalDevice_, &features);
    bufferFloatAtomicAdd_ = atomicFloat.shaderBufferFloat32AtomicAdd == VK_TRUE;
  }
  VkPhysicalDeviceShaderAtomicFloatFeaturesEXT enabledAtomicFloat{};
  enabledAtomicFloat.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_ATOMIC_FLOAT_FEATURES_EXT;
  enabledAtomicFloat.shaderBufferFloat32AtomicAdd = VK_TRUE;
  if (bufferFloatAtomicAdd_) extensions.push_back(VK_EXT_SHADER_ATOMIC_FLOAT_EXTENSION_NAME);
  if (swapchain) {
    if (!hasDeviceExtension(physicalDevice_, VK_KHR_SWAPCHAIN_EXTENSION_NAME))
      throw GpuError(std::string("Vulkan device \"") + properties_.deviceName + "\" cannot present to a window (no " +
                     VK_KHR_SWAPCHAIN_EXTENSION_NAME + ")");
    extensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
  }

  VkDeviceCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
  info.pNext = bufferFloatAtomicAdd_ ? &enabledAtomicFloat : nullptr;
  // Dynamic rendering (core, and required of every Vulkan 1.3 device) for the raster passes.
  VkPhysicalDeviceVulkan13Features features13{};
  features13.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES;
  features13.pNext = const_cast<void*>(info.pNext);
  features13.dynamicRendering = VK_TRUE;
  if (properties_.apiVersion >= VK_API_VERSION_1_3) info.pNext = &features13;
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &queueInfo;
  info.enabledExtensionCount = std::uint32_t(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  SSLPV_VK_CHECK(vkCreateDevice(physicalDevice_, &info, nullptr, &device_));
  vkGetDeviceQueue(device_, queueFamily_, 0, &queue_);
}

bool VulkanDevice::unifiedMemory() const {
  if (properties_.deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU &&
      properties_.deviceType != VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU)
    return false;
  const VkMemoryPropertyFlags mappable =
      VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT | VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  for (std::uint32_t i = 0; i < memoryProperties_.memoryTypeCount; ++i)
    if ((memoryProperties_.memoryTypes[i].propertyFlags & mappable) == mappable) return true;
  return false;
}

void VulkanDevice::submit(const VkSubmitInfo& submit, VkFence fence) const {
  std::lock_guard<std::mutex> lock(queueMutex_);
  SSLPV_VK_CHECK(vkQueueSubmit(queue_, 1, &submit, fence));
}

VkResult VulkanDevice::present(const VkPresentInfoKHR& info) const {
  std::lock_guard<std::mutex> lock(queueMutex_);
  return vkQueuePresentKHR(queue_, &info);
}

std::vector<std::string> VulkanDevice::availableDevices() {
  std::vector<std::string> names;
  VkApplicationInfo app{};
  app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  app.apiVersion = VK_API_VERSION_1_2;
  VkInstanceCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
  info.pApplicationInfo = &app;
  VkInstance instance = VK_NULL_HANDLE;
  if (vkCreateInstance(&info, nullptr, &instance) != VK_SUCCESS) return names;
  try {
    for (VkPhysicalDevice device : physicalDevices(instance)) {
      VkPhysicalDeviceProperties props;
      vkGetPhysicalDeviceProperties(device, &props);
      names.emplace_back(props.deviceName);
    }
  } catch (const GpuError&) {
    names.clear();
  }
  vkDestroyInstance(instance, nullptr);
  return names;
}

}  // namespace sslpv::gpu
