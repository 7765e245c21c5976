#pragma once
// What every SSLPV backend offers a caller (the CLI, the viewer, the editor's preview,
// the benchmarks): one frame at a time, re-running only the stages whose inputs changed.
// CpuRenderer (volume/cpu/) and gpu::VulkanRenderer implement it, both on the frame
// skeleton of volume/lpv/staged_renderer.h; backend/backends.h is the one place that
// chooses between them.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "volume/lpv/frame_report.h"
#include "volume/core/image_io.h"
#include "volume/scene/mesh.h"
#include "volume/scene/scene.h"

namespace sslpv {

struct MaterialSet;

class Renderer {
 public:
  virtual ~Renderer() = default;
  /// One frame with these LPV settings (they override the scene's).
  virtual Image render(const LpvSettings& settings, RenderReport* report = nullptr) = 0;
  /// The next frame re-shades only.
  virtual void setCamera(const Camera& camera) = 0;
  /// The next frame re-runs shadow maps onwards.
  virtual void setLights(const std::vector<Light>& lights) = 0;
  /// A painted material set: the next frame re-resamples the cells overlapping `touched`
  /// (world bounds; everything when absent) and re-propagates.
  virtual void setMaterialSet(std::shared_ptr<const MaterialSet> set, const std::optional<Bounds>& touched) = 0;
  /// Poses a deforming scene at time t (a no-op without deformers); InputError, renderer
  /// unchanged, when the pose folds the mesh.
  virtual void setTime(double t) = 0;
  /// "cpu" or "vulkan (<device name>)", for reports and status lines.
  virtual std::string name() const = 0;
};

}  // namespace sslpv
