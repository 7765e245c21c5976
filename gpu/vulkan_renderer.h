#pragma once
// The Vulkan SSLPV backend: the same frame as CpuRenderer, every per-frame stage on the
// GPU (voxelization, shadow maps by rasterization, injection, propagation, shading by
// rasterization), with the same dirty flags so a frame re-runs only what changed.
// Resampling the painted material set stays on the CPU (OpenVDB) and is uploaded.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "gpu/vk/device.h"
#include "volume/lpv/frame_report.h"
#include "volume/core/image_io.h"
#include "volume/lpv/lpv_stages.h"
#include "volume/lpv/staged_renderer.h"
#include "volume/scene/scene.h"
#include "volume/material/scene_object.h"

namespace sslpv::gpu {

class GpuMesh;
class GpuVoxelizer;
class GpuShadowMapper;
class GpuInjector;
class GpuPropagator;
class GpuShader;
class Buffer;

/// Stage times in a frame's report are GPU times from timestamps (wall-clock for the CPU
/// resampling and where the device has no timestamps).
class VulkanRenderer final : public StagedRenderer {
 public:
  /// Loads the object as the CPU backend does (InputError on bad input) and uploads the
  /// mesh to `device`, which must outlive the renderer.
  VulkanRenderer(const Scene& scene, const VulkanDevice& device);
  ~VulkanRenderer() override;
  VulkanRenderer(const VulkanRenderer&) = delete;
  VulkanRenderer& operator=(const VulkanRenderer&) = delete;

  void setCamera(const Camera& camera) override;
  void setLights(const std::vector<Light>& lights) override;
  void setMaterialSet(std::shared_ptr<const MaterialSet> set, const std::optional<Bounds>& touched) override;
  /// Poses a deforming scene at time `t` (as CpuRenderer::setTime): new vertex positions
  /// on the device, then voxelization onwards. Each frame propagates cold, as every
  /// frame of this backend does.
  void setTime(double t) override;
  /// "vulkan (<device name>)".
  std::string name() const override;

  const Scene& scene() const { return scene_; }
  /// Per pixel of the last shaded frame, the 1-based index of the triangle seen there
  /// (0: background): picking, and comparing with the CPU backend in tests.
  std::vector<std::uint32_t> readTriangles() const;
  /// The material grid of the last frame (occupancy from the GPU voxelizer).
  const MaterialGrid& material() const { return material_; }

 private:
  double runVoxelize(const LpvSettings& settings, RenderReport& report) override;
  double runResample(const LpvSettings& settings, RenderReport& report) override;
  double runShadowMaps(const LpvSettings& settings, RenderReport& report) override;
  double runInjection(RenderReport& report) override;
  double runPropagation(const LpvSettings& settings, RenderReport& report) override;
  double runShading(Image& image) override;

  const VulkanDevice& device_;
  Scene scene_;
  SceneObject object_;
  std::unique_ptr<GpuMesh> mesh_;

  bool lightsUploaded_ = false;
  MaterialGrid material_;
  StepFactors factors_;
  std::unique_ptr<Buffer> exitFactors_;  ///< factors_' exit gain and reduced albedo on the device, for shading
  /// factors_' reduced σt' and σs' for the single-scattering term (calibrated scheme), else null
  std::unique_ptr<Buffer> reducedMedium_;
  std::unique_ptr<Buffer> calibratedInjection_;  ///< factors_' injection record (calibrated scheme), else null
  std::unique_ptr<Buffer> exitLaw_;      ///< exitLawTable(scene_.material.ior), uploaded at the first shading
  std::unique_ptr<GpuVoxelizer> voxelizer_;
  std::unique_ptr<Buffer> cellCoverage_;
  std::unique_ptr<GpuShadowMapper> shadowMapper_;
  std::unique_ptr<GpuInjector> injector_;
  std::unique_ptr<GpuPropagator> propagator_;
  std::unique_ptr<GpuShader> shader_;
};

}  // namespace sslpv::gpu
