#pragma once
// The CPU SSLPV backend: owns the object (mesh, ray-casting structure, material field)
// and the results of every stage, so a frame re-runs only the stages whose inputs
// changed (a camera move re-shades, a brush stroke re-resamples its region).
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "volume/cpu/coarse_start.h"
#include "volume/lpv/frame_report.h"
#include "volume/core/image_io.h"
#include "volume/lpv/lpv_stages.h"
#include "volume/lpv/staged_renderer.h"
#include "volume/scene/scene.h"
#include "volume/material/scene_object.h"
#include "volume/cpu/single_scattering.h"

namespace sslpv {

struct ShadingSurface;

class RayScene;

class CpuRenderer final : public StagedRenderer {
 public:
  /// Loads and checks the mesh (closed), builds the ray-casting structure and loads the
  /// material set. Throws InputError on bad input.
  explicit CpuRenderer(const Scene& scene);
  ~CpuRenderer() override;
  CpuRenderer(const CpuRenderer&) = delete;
  CpuRenderer& operator=(const CpuRenderer&) = delete;

  /// The next frame re-shades only. `camera` must be valid (as the scene loader checks).
  void setCamera(const Camera& camera) override;
  /// The next frame re-runs shadow maps onwards.
  void setLights(const std::vector<Light>& lights) override;
  /// A painted material set: the next frame re-resamples the cells overlapping
  /// `touched` (world bounds; everything when absent) and re-propagates.
  void setMaterialSet(std::shared_ptr<const MaterialSet> set, const std::optional<Bounds>& touched) override;

  /// Poses a deforming scene (Scene::deformers) at time `t`: the next frame re-voxelizes,
  /// re-resamples through the new inverse and re-runs everything after. The last frame's
  /// light starts the propagation only where the grid frame is unchanged (the deformed
  /// bounds decide the frame, so a bending object mostly gets a new one and a coarse
  /// start instead). InputError, renderer unchanged, when the pose folds the mesh; no-op
  /// without deformers.
  void setTime(double t) override;
  std::string name() const override { return "cpu"; }

  /// The next propagation starts cold, as the first frame's does, instead of from the
  /// last frame's converged light (benchmarks of whole frames, comparisons).
  void resetPropagation() { warm_.clear(); }
  /// Whether a cold calibrated propagation starts from a solve on a coarser grid
  /// (volume/cpu/coarse_start.h; on by default). Off, it starts from the injected light.
  void setCoarseStart(bool enabled) { coarseStartEnabled_ = enabled; }

  const Scene& scene() const { return scene_; }

 private:
  void settingsChanging(const LpvSettings& before, const LpvSettings& after) override;
  double runVoxelize(const LpvSettings& settings, RenderReport& report) override;
  double runResample(const LpvSettings& settings, RenderReport& report) override;
  double runShadowMaps(const LpvSettings& settings, RenderReport& report) override;
  double runInjection(RenderReport& report) override;
  double runPropagation(const LpvSettings& settings, RenderReport& report) override;
  double runShading(Image& image) override;

  Scene scene_;
  SceneObject object_;
  std::unique_ptr<RayScene> rays_;

  // Results kept between frames.
  MaterialGrid material_;
  StepFactors factors_;
  std::vector<SurfaceFluxSample> samples_;
  std::vector<EntryMap> entries_;  ///< the shadow maps' texels for the single-scattering term
  ShGrid injected_, accumulated_;
  /// The last converged light, the start of the next propagation after a stroke or a light
  /// change. Dropped where the problem is new: another grid, scheme or step setting, or
  /// a whole new material set (so a full frame is a cold one).
  PropagationWarmStart warm_;
  CoarseStart coarse_;
  std::unique_ptr<ShadingSurface> surface_;  ///< null: the camera or the geometry changed
  bool viewShadedOnce_ = false;               ///< the current view was shaded before: keep it
  bool coarseStartEnabled_ = true;
};

}  // namespace sslpv
