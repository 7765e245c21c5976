#include "backend/backends.h"

#include <utility>

#include "volume/cpu/cpu_renderer.h"
#include "volume/core/error.h"

#ifdef SSLPV_HAVE_VULKAN
#include "gpu/vk/device.h"
#include "gpu/vk/vk_check.h"
#include "gpu/vulkan_renderer.h"
#elif __has_include(<vulkan/vulkan.h>)
// GpuError is header-only: the promised exception type even without the GPU backend.
#include "gpu/vk/vk_check.h"
#define SSLPV_HAVE_GPU_ERROR
#endif

namespace sslpv {

BackendKind parseBackendKind(const std::string& text, const std::string& flag) {
  if (text == "auto") return BackendKind::Auto;
  if (text == "cpu") return BackendKind::Cpu;
  if (text == "vulkan") return BackendKind::Vulkan;
  throw InputError(flag + ": unknown backend '" + text + "' (auto, vulkan, cpu)");
}

#ifdef SSLPV_HAVE_VULKAN

/// The device Vulkan renderers render on: owned here, or borrowed from the caller.
struct Backends::Device {
  std::unique_ptr<gpu::VulkanDevice> owned;
  const gpu::VulkanDevice* device = nullptr;
};

namespace {

/// A Vulkan renderer that keeps its device alive (declared first, destroyed last).
class VulkanOnDevice final : public Renderer {
 public:
  VulkanOnDevice(std::shared_ptr<const void> keepAlive, const Scene& scene, const gpu::VulkanDevice& device)
      : keepAlive_(std::move(keepAlive)), renderer_(scene, device) {}
  Image render(const LpvSettings& settings, RenderReport* report) override { return renderer_.render(settings, report); }
  void setCamera(const Camera& camera) override { renderer_.setCamera(camera); }
  void setLights(const std::vector<Light>& lights) override { renderer_.setLights(lights); }
  void setMaterialSet(std::shared_ptr<const MaterialSet> set, const std::optional<Bounds>& touched) override {
    renderer_.setMaterialSet(std::move(set), touched);
  }
  void setTime(double t) override { renderer_.setTime(t); }
  std::string name() const override { return renderer_.name(); }

 private:
  std::shared_ptr<const void> keepAlive_;
  gpu::VulkanRenderer renderer_;
};

std::string vulkanRequired(const std::string& why) {
  return "--backend vulkan: " + why + " (--backend cpu needs no GPU)";
}

}  // namespace

Backends::Backends(BackendKind kind) : kind_(kind) {
  if (kind == BackendKind::Cpu) return;
  auto device = std::make_shared<Device>();
  try {
    device->owned = std::make_unique<gpu::VulkanDevice>();
  } catch (const GpuError& e) {
    // NoVulkanDeviceError included: the machine lacks what the GPU backend needs.
    if (kind == BackendKind::Vulkan) throw ResourceError(vulkanRequired(e.what()));
    note_ = std::string("--backend auto: no usable Vulkan device (") + e.what() + "); using the CPU backend";
    return;
  }
  if (kind == BackendKind::Auto && device->owned->runsOnCpu()) {
    note_ = "--backend auto: " + device->owned->name() +
            " is Vulkan on the CPU; the CPU backend is faster here (--backend vulkan to use it)";
    return;
  }
  device->device = device->owned.get();
  device_ = std::move(device);
  usesVulkan_ = true;
}

Backends::Backends(BackendKind kind, const gpu::VulkanDevice& device) : kind_(kind) {
  if (kind == BackendKind::Cpu) return;
  if (kind == BackendKind::Auto && device.runsOnCpu()) {
    note_ = "--backend auto: " + device.name() +
            " is Vulkan on the CPU; the CPU backend is faster here (--backend vulkan to use it)";
    return;
  }
  device_ = std::make_shared<Device>();
  device_->device = &device;
  usesVulkan_ = true;
}

Backends::~Backends() = default;

std::unique_ptr<Renderer> Backends::make(const Scene& scene) {
  if (!usesVulkan_) return std::make_unique<CpuRenderer>(scene);
  try {
    return std::make_unique<VulkanOnDevice>(device_, scene, *device_->device);
  } catch (const GpuError& e) {
    if (kind_ == BackendKind::Vulkan) throw ResourceError(vulkanRequired(e.what()));
    usesVulkan_ = false;
    note_ = std::string("--backend auto: the Vulkan backend cannot run here (") + e.what() + "); using the CPU backend";
    return std::make_unique<CpuRenderer>(scene);
  }
}

std::unique_ptr<Renderer> makeRenderer(const Scene& scene, BackendKind kind) {
  if (kind == BackendKind::Cpu) return std::make_unique<CpuRenderer>(scene);
  if (kind == BackendKind::Auto) return Backends(kind).make(scene);
  auto device = std::make_shared<gpu::VulkanDevice>();
  return std::make_unique<VulkanOnDevice>(device, scene, *device);
}

#else  // built without Vulkan: every choice renders on the CPU, or says why it cannot

struct Backends::Device {};

Backends::Backends(BackendKind kind) : kind_(kind) {
  if (kind == BackendKind::Vulkan)
    throw ResourceError("--backend vulkan: this sslpv was built without Vulkan (--backend cpu needs no GPU)");
  if (kind == BackendKind::Auto) note_ = "--backend auto: this sslpv was built without Vulkan; using the CPU backend";
}

Backends::Backends(BackendKind kind, const gpu::VulkanDevice&) : Backends(kind) {}

Backends::~Backends() = default;

std::unique_ptr<Renderer> Backends::make(const Scene& scene) { return std::make_unique<CpuRenderer>(scene); }

std::unique_ptr<Renderer> makeRenderer(const Scene& scene, BackendKind kind) {
  if (kind != BackendKind::Vulkan) return std::make_unique<CpuRenderer>(scene);
#if defined(SSLPV_HAVE_GPU_ERROR)
  throw NoVulkanDeviceError("the Vulkan backend is not available: this sslpv was built without Vulkan");
#else
  throw ResourceError("the Vulkan backend is not available: this sslpv was built without Vulkan");
#endif
}

#endif

}  // namespace sslpv
