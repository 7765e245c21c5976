#pragma once
// The one place that knows both SSLPV backends and chooses between them: the CLI, the
// viewer, the editor's preview and the benchmarks ask here for a Renderer. "auto" takes
// the Vulkan backend on a real GPU only: on Mesa lavapipe (Vulkan run on the CPU) the
// CPU backend renders the same frame faster (docs/performance.md).
#include <memory>
#include <string>

#include "volume/lpv/renderer.h"
#include "volume/scene/scene.h"

namespace sslpv {

namespace gpu {
class VulkanDevice;
}

enum class BackendKind { Auto, Cpu, Vulkan };

/// "auto", "cpu" or "vulkan"; InputError naming `flag` otherwise.
BackendKind parseBackendKind(const std::string& text, const std::string& flag = "--backend");

/// Builds renderers on one chosen backend. Vulkan renderers render on one device: the
/// one given (the viewer's, which also presents) or one opened here and kept alive by
/// every renderer made on it.
class Backends {
 public:
  /// Opens a Vulkan device unless `kind` is Cpu. Vulkan without a usable device (or in a
  /// build without Vulkan): ResourceError "--backend vulkan: ...". Auto without one, or
  /// on a CPU device: the CPU backend, with note() saying why.
  explicit Backends(BackendKind kind);
  /// Renders Vulkan frames on `device`, which must outlive every renderer made here.
  Backends(BackendKind kind, const gpu::VulkanDevice& device);
  ~Backends();
  Backends(const Backends&) = delete;
  Backends& operator=(const Backends&) = delete;

  /// A renderer for `scene`; InputError on a bad scene. A Vulkan renderer that cannot be
  /// built (a device without what it needs): ResourceError when Vulkan was asked for;
  /// under auto, the CPU backend from then on, with note() saying why.
  std::unique_ptr<Renderer> make(const Scene& scene);
  /// Whether make() builds Vulkan renderers (it may stop, see make()).
  bool usesVulkan() const { return usesVulkan_; }
  /// Why auto renders on the CPU ("" when it does not).
  const std::string& note() const { return note_; }

 private:
  struct Device;
  [[maybe_unused]] BackendKind kind_;  // read only where Vulkan is built
  std::shared_ptr<Device> device_;
  bool usesVulkan_ = false;
  std::string note_;
};

/// A renderer for `scene` on `kind`, on a Vulkan device of its own: the editor's previews,
/// one per open scene. Vulkan unavailable: NoVulkanDeviceError or another GpuError
/// (gpu/vk/vk_check.h), so a caller can fall back; auto falls back by itself.
std::unique_ptr<Renderer> makeRenderer(const Scene& scene, BackendKind kind);

}  // namespace sslpv
