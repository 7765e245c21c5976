// The two backends behind the preview's one interface. The editor never branches on the
// backend; this file is the only place that knows both.
#include <memory>
#include <string>

#include "editor/edit_session.h"
#include "volume/cpu_renderer.h"
#include "volume/error.h"

#ifdef SSLPV_HAVE_VULKAN
#include "gpu/device.h"
#include "gpu/vk_check.h"
#include "gpu/vulkan_renderer.h"
#elif __has_include(<vulkan/vulkan.h>)
// GpuError is header-only: the promised exception type even without the GPU backend.
#include "gpu/vk_check.h"
#define SSLPV_HAVE_GPU_ERROR
#endif

namespace sslpv {
namespace {

class CpuPreview final : public PreviewRenderer {
 public:
  explicit CpuPreview(const Scene& scene) : renderer_(scene) {}
  Image render(const LpvSettings& settings, RenderReport* report) override {
    return renderer_.render(settings, report);
  }
  void setCamera(const Camera& camera) override { renderer_.setCamera(camera); }
  void setMaterialSet(std::shared_ptr<const MaterialSet> set, const std::optional<Bounds>& touched) override {
    renderer_.setMaterialSet(std::move(set), touched);
  }
  std::string name() const override { return "cpu"; }

 private:
  CpuRenderer renderer_;
};

#ifdef SSLPV_HAVE_VULKAN
class VulkanPreview final : public PreviewRenderer {
 public:
  // The device is created first and, declared first, destroyed last: the renderer's
  // resources live on it.
  explicit VulkanPreview(const Scene& scene)
      : device_(std::make_unique<gpu::VulkanDevice>()), renderer_(scene, *device_) {}
  Image render(const LpvSettings& settings, RenderReport* report) override {
    return renderer_.render(settings, report);
  }
  void setCamera(const Camera& camera) override { renderer_.setCamera(camera); }
  void setMaterialSet(std::shared_ptr<const MaterialSet> set, const std::optional<Bounds>& touched) override {
    renderer_.setMaterialSet(std::move(set), touched);
  }
  std::string name() const override { return "vulkan (" + device_->name() + ")"; }

 private:
  std::unique_ptr<gpu::VulkanDevice> device_;
  gpu::VulkanRenderer renderer_;
};
#endif

}  // namespace

std::unique_ptr<PreviewRenderer> makePreviewRenderer(const Scene& scene, PreviewBackendKind backend) {
  if (backend == PreviewBackendKind::Cpu) return std::make_unique<CpuPreview>(scene);
#ifdef SSLPV_HAVE_VULKAN
  return std::make_unique<VulkanPreview>(scene);
#elif defined(SSLPV_HAVE_GPU_ERROR)
  throw NoVulkanDeviceError("the Vulkan preview is not available: this sslpv was built without Vulkan");
#else
  throw ResourceError("the Vulkan preview is not available: this sslpv was built without Vulkan");
#endif
}

}  // namespace sslpv
