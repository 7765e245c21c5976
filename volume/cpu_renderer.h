#pragma once
// The CPU SSLPV backend: owns the object (mesh, ray-casting structure, material field)
// and renders frames stage by stage with per-stage timings.
#include <memory>
#include <string>
#include <vector>

#include "volume/image_io.h"
#include "volume/lpv_stages.h"
#include "volume/scene.h"

namespace sslpv {

class RayScene;
class MaterialField;

/// Wall-clock milliseconds of each stage. Scene setup (load, voxelize, resample) is paid
/// once per object or material edit; the rest once per frame.
struct StageTimes {
  double load = 0, voxelize = 0, resample = 0;
  double shadowMap = 0, injection = 0, propagation = 0, shading = 0;
  double frame() const { return shadowMap + injection + propagation + shading; }
};

struct RenderReport {
  StageTimes times;
  GridFrame frame;
  std::size_t activeCells = 0;
  std::size_t triangles = 0;
  std::vector<ShadowMapStats> lights;
  InjectionStats injection;
  PropagationResult propagation;
};

class CpuRenderer {
 public:
  /// Loads and checks the mesh (closed), builds the ray-casting structure and loads the
  /// material set. Throws InputError on bad input.
  explicit CpuRenderer(const Scene& scene);
  ~CpuRenderer();
  CpuRenderer(const CpuRenderer&) = delete;
  CpuRenderer& operator=(const CpuRenderer&) = delete;

  /// Renders one frame with the given LPV settings (they override the scene's).
  Image render(const LpvSettings& settings, RenderReport* report = nullptr);

  const Scene& scene() const { return scene_; }

 private:
  Scene scene_;
  double loadMs_ = 0;
  std::size_t triangles_ = 0;
  Bounds bounds_;
  std::unique_ptr<RayScene> rays_;
  std::unique_ptr<MaterialField> field_;
  std::unique_ptr<TriangleMesh> mesh_;
};

/// The seed-style timing table (shadow map, injection, propagation, shading, total, ms),
/// followed by the setup stages and the grid that was used.
std::string formatTimings(const RenderReport& report);

}  // namespace sslpv
