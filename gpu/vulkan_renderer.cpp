#include "gpu/vulkan_renderer.h"

#include "volume/calibration/lpv_calibration.h"

#include <chrono>

#include "gpu/passes/gpu_inject.h"
#include "gpu/passes/gpu_propagation.h"
#include "gpu/passes/gpu_shade.h"
#include "gpu/passes/gpu_shadow_map.h"
#include "gpu/passes/gpu_voxelize.h"
#include "gpu/passes/gpu_mesh.h"
#include "gpu/vk/graphics.h"
#include "volume/material/material_set.h"
#include "volume/lpv/resample.h"

namespace sslpv::gpu {
namespace {

double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

/// Peak bytes of a frame on this backend: the host's material grid and step factors
/// (estimateLpvBytes' first two terms), plus the device buffers, which lavapipe keeps in
/// host memory: the voxelizer's nearest-triangle and coverage words, the cell coverage,
/// the exit factors (8 floats), the reduced medium (2 vec4), the calibrated injection
/// records and the propagator's five light fields (source, accumulated, two ping-pong
/// tiles, tiled accumulated) and its factor texels. Measured peak RSS less a small
/// grid's (sphere, --steps auto, lavapipe): 667 B a cell at 64^3.
std::size_t vulkanLpvBytes(const GridFrame& frame) {
  constexpr std::size_t kFloat = sizeof(float), kVec4 = 4 * kFloat;
  constexpr std::size_t host = kFloat * (1 + 3 + 3 + 1) + kFloat * (9 * 3 + 3 * SSLPV_OBLIQUE_INTERVALS) + 1;
  constexpr std::size_t device = 2 * kFloat + kFloat + 8 * kFloat + 2 * kVec4 + SSLPV_CALIBRATED_INJECTION_VEC4 * kVec4 +
                                 SSLPV_FACTOR_VEC4_PER_CELL * kVec4;
  return frame.cellCount() * (host + device) + 5 * std::size_t(lightFieldBytes(frame));
}

}  // namespace

VulkanRenderer::VulkanRenderer(const Scene& scene, const VulkanDevice& device)
    : device_(device), scene_(scene), object_(scene_) {
  const auto start = std::chrono::steady_clock::now();
  mesh_ = std::make_unique<GpuMesh>(device_, object_.mesh());
  injector_ = std::make_unique<GpuInjector>(device_);
  prepareCalibrationTables(scene_.material.ior);
  loadMs_ = object_.loadMs() + msSince(start);
}

VulkanRenderer::~VulkanRenderer() = default;

std::string VulkanRenderer::name() const { return "vulkan (" + device_.name() + ")"; }

void VulkanRenderer::setCamera(const Camera& camera) {
  scene_.camera = camera;
  dirty_.cameraChanged();
}

void VulkanRenderer::setLights(const std::vector<Light>& lights) {
  scene_.lights = lights;
  lightsUploaded_ = false;
  dirty_.lightsChanged();
}

void VulkanRenderer::setMaterialSet(std::shared_ptr<const MaterialSet> set, const std::optional<Bounds>& touched) {
  object_.setMaterialSet(std::move(set));
  dirty_.materialChanged(touched);
}

void VulkanRenderer::setTime(double t) {
  if (!object_.deformed()) return;
  object_.setTime(t);
  scene_.time = t;
  mesh_->updatePositions(device_, object_.mesh().positions);
  // The shadow views are placed around the mesh's bounds.
  lightsUploaded_ = false;
  dirty_.geometryChanged();
}

double VulkanRenderer::runVoxelize(const LpvSettings& settings, RenderReport& report) {
  const GridFrame frame = makeGridFrame(object_.gridBounds(), settings.resolution);
  requireLpvMemory(frame, vulkanLpvBytes(frame), "vulkan");
  const bool sameFrame = voxelizer_ && voxelizer_->frame().dims == frame.dims &&
                         voxelizer_->frame().origin == frame.origin && voxelizer_->frame().cellSize == frame.cellSize;
  if (!sameFrame) voxelizer_ = std::make_unique<GpuVoxelizer>(device_, frame);
  // GpuMesh holds the vec4 positions and uint indices the voxelizer reads: one upload.
  const GpuVoxelizeTimings times = voxelizer_->run(mesh_->positions(), mesh_->indices(), mesh_->triangleCount());
  // The occupancy comes back to the host: the step factors and the brick list of the
  // propagation are built there, together with the resampled material.
  material_ = MaterialGrid{};
  material_.frame = frame;
  material_.meanChord = meanChordLength(object_.mesh());
  material_.coverage = voxelizer_->readCoverage();
  cellCoverage_ = std::make_unique<Buffer>(uploadCellCoverage(device_, material_));
  // On the same frame (a deformed object's grid spans all its poses) the propagator, its
  // pipelines and buffers stay: resample() hands it the new factors and active cells.
  if (!sameFrame) propagator_.reset();
  report.frame = frame;
  report.triangles = object_.mesh().triangles.size();
  return times.totalMs();
}

double VulkanRenderer::runResample(const LpvSettings& settings, RenderReport& report) {
  const auto start = std::chrono::steady_clock::now();
  if (dirty_.resampleRegion() && propagator_) {
    report.resampledCells = resampleMaterialRegion(object_.field(), material_, *dirty_.resampleRegion()).count();
  } else {
    resampleMaterial(object_.field(), material_);
    report.resampledCells = material_.frame.cellCount();
  }
  factors_ = computeStepFactors(material_, settings.scheme, scene_.material.ior);
  report.opticalThickness = factors_.opticalThickness;
  exitFactors_ = std::make_unique<Buffer>(uploadExitFactors(device_, factors_, material_.frame));
  reducedMedium_ = factors_.scheme == LpvScheme::Calibrated
                       ? std::make_unique<Buffer>(uploadReducedMedium(device_, material_))
                       : nullptr;
  calibratedInjection_ = factors_.scheme == LpvScheme::Calibrated
                         ? std::make_unique<Buffer>(uploadCalibratedInjection(device_, factors_, material_.frame))
                         : nullptr;
  report.activeCells = 0;
  for (unsigned char a : factors_.active) report.activeCells += a;
  if (propagator_) {
    propagator_->setFactors(factors_);
    return msSince(start);
  }
  const double resampleMs = msSince(start);
  // Pipeline creation and shader compilation happen once per grid: setup, not resampling.
  const auto created = std::chrono::steady_clock::now();
  propagator_ = std::make_unique<GpuPropagator>(device_, material_.frame, factors_);
  loadMs_ += msSince(created);
  return resampleMs;
}

std::vector<std::uint32_t> VulkanRenderer::readTriangles() const {
  return shader_ ? shader_->readTriangles() : std::vector<std::uint32_t>{};
}

double VulkanRenderer::runShadowMaps(const LpvSettings& settings, RenderReport& report) {
  if (!shadowMapper_ || shadowMapper_->size() != settings.shadowMap) {
    shadowMapper_ = std::make_unique<GpuShadowMapper>(device_, *mesh_, settings.shadowMap);
    lightsUploaded_ = false;
  }
  if (!lightsUploaded_) {
    shadowMapper_->setLights(scene_.lights, scene_.material.ior);
    lightsUploaded_ = true;
  }
  const double ms = shadowMapper_->run();
  // Texel counts and culling only: hits and flux would need every texel record read
  // back each frame (4 MB per 256² view); GpuShadowMapper::stats() gives them on demand.
  report.lights.clear();
  for (const GpuShadowLight& placed : shadowMapper_->lights()) {
    ShadowMapStats stats;
    stats.texels = placed.sampleCount;
    stats.culled = placed.culled;
    report.lights.push_back(stats);
  }
  return ms;
}

double VulkanRenderer::runInjection(RenderReport& report) {
  report.injection = injector_->run(shadowMapper_->samples(), shadowMapper_->sampleCount(), *cellCoverage_,
                                    material_.frame, propagator_->sourceField(), true, calibratedInjection_.get());
  return injector_->lastRunMs();
}

double VulkanRenderer::runPropagation(const LpvSettings& settings, RenderReport& report) {
  PropagationOptions options;
  options.steps = settings.steps;
  options.autoSteps = settings.autoSteps;
  options.chebyshev = true;
  report.propagation = propagator_->runOnDevice(options);
  const GpuPropagationTimings& t = propagator_->timings();
  return t.propagateMs + t.reduceMs;
}

double VulkanRenderer::runShading(Image& image) {
  if (!shader_ || shader_->width() != scene_.camera.width || shader_->height() != scene_.camera.height)
    shader_ = std::make_unique<GpuShader>(device_, *mesh_, scene_.camera.width, scene_.camera.height);
  // The scene's η is fixed for the renderer: one table (built once per process and η).
  if (!exitLaw_) exitLaw_ = std::make_unique<Buffer>(uploadExitLaw(device_, exitLawTable(scene_.material.ior)));
  GpuSingleScattering single;
  if (reducedMedium_) {
    single.medium = reducedMedium_.get();
    single.views = &shadowMapper_->viewRecords();
    single.samples = &shadowMapper_->samples();
    single.viewCount = std::uint32_t(shadowMapper_->views().size());
  }
  image = shader_->shade(scene_.camera, propagator_->accumulated(), *cellCoverage_, *exitFactors_, *exitLaw_,
                         material_.frame, scene_.material.ior, &single);
  return shader_->lastShadeMs();
}

}  // namespace sslpv::gpu
