#include "volume/cpu/cpu_renderer.h"

#include "volume/calibration/lpv_calibration.h"
#include "volume/cpu/coarse_start.h"

#include <chrono>

#include "volume/core/error.h"
#include "volume/material/material_set.h"
#include "volume/scene/mesh.h"
#include "volume/scene/ray_scene.h"
#include "volume/cpu/shading_surface.h"
#include "volume/cpu/single_scattering.h"
#include "volume/lpv/voxelize_parity.h"
#include "volume/lpv/resample.h"
#include "volume/cpu/shadow_map.h"
#include "volume/cpu/inject.h"
#include "volume/cpu/propagate.h"
#include "volume/cpu/shade.h"

namespace sslpv {
namespace {

class Stopwatch {
 public:
  double lapMs() {
    const auto now = std::chrono::steady_clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - start_).count();
    start_ = now;
    return ms;
  }

 private:
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace

CpuRenderer::CpuRenderer(const Scene& scene) : scene_(scene), object_(scene_) {
  Stopwatch watch;
  rays_ = std::make_unique<RayScene>(object_.mesh());
  prepareCalibrationTables(scene_.material.ior);
  loadMs_ = object_.loadMs() + watch.lapMs();
}

CpuRenderer::~CpuRenderer() = default;

void CpuRenderer::setCamera(const Camera& camera) {
  scene_.camera = camera;
  dirty_.cameraChanged();
  surface_.reset();
  viewShadedOnce_ = false;
}


void CpuRenderer::setLights(const std::vector<Light>& lights) {
  scene_.lights = lights;
  dirty_.lightsChanged();
}

void CpuRenderer::setMaterialSet(std::shared_ptr<const MaterialSet> set, const std::optional<Bounds>& touched) {
  object_.setMaterialSet(std::move(set));
  dirty_.materialChanged(touched);
  // Strokes start cold for now: warm-started, the preview benchmark's marble stroke took
  // more steps than cold (175 against 145 at 32³) and its image differed from a cold frame
  // by up to 5e-2, so only light changes reuse the last frame's light (108 -> 22 steps on
  // the pebble). propagate() itself supports warm strokes (warm_start_test).
  warm_.clear();
  coarse_.materialChanged(touched);
}

void CpuRenderer::setTime(double t) {
  if (!object_.deformed()) return;
  object_.setTime(t);
  scene_.time = t;
  rays_ = std::make_unique<RayScene>(object_.mesh());
  dirty_.geometryChanged();
  surface_.reset();
  // The light may start the next run (any start converges to the new solution), but the
  // cells the stop rule watches follow the new surface.
  warm_.shell.clear();
}

void CpuRenderer::settingsChanging(const LpvSettings& before, const LpvSettings& after) {
  if (before.resolution != after.resolution || before.scheme != after.scheme || before.steps != after.steps ||
      before.autoSteps != after.autoSteps)
    warm_.clear();
}

double CpuRenderer::runVoxelize(const LpvSettings& settings, RenderReport& report) {
  Stopwatch watch;
  material_ = MaterialGrid{};
  material_.frame = makeGridFrame(object_.gridBounds(), settings.resolution);
  requireLpvMemory(material_.frame, estimateLpvBytes(material_.frame), "cpu");
  material_.meanChord = meanChordLength(object_.mesh());
  // The twin of the GPU voxelizer, so both backends see the same occupancy.
  material_.coverage = voxelizeCoverageParity(object_.mesh(), material_.frame);
  coarse_.geometryChanged();
  surface_.reset();
  viewShadedOnce_ = false;
  report.frame = material_.frame;
  report.triangles = object_.mesh().triangles.size();
  return watch.lapMs();
}

double CpuRenderer::runResample(const LpvSettings& settings, RenderReport& report) {
  Stopwatch watch;
  if (dirty_.resampleRegion()) {
    report.resampledCells = resampleMaterialRegion(object_.field(), material_, *dirty_.resampleRegion()).count();
  } else {
    resampleMaterial(object_.field(), material_);
    report.resampledCells = material_.frame.cellCount();
  }
  factors_ = computeStepFactors(material_, settings.scheme, scene_.material.ior);
  report.opticalThickness = factors_.opticalThickness;
  report.activeCells = 0;
  for (unsigned char a : factors_.active) report.activeCells += a;
  return watch.lapMs();
}

double CpuRenderer::runShadowMaps(const LpvSettings& settings, RenderReport& report) {
  Stopwatch watch;
  samples_.clear();
  entries_.clear();
  report.lights.clear();
  for (std::size_t l = 0; l < scene_.lights.size(); ++l) {
    const Light& light = scene_.lights[l];
    ShadowMapStats stats;
    // The entry maps are filled whatever the scheme, so that switching to the calibrated
    // one (the only reader) does not re-cast the maps.
    auto lightSamples = castShadowMap(light, *rays_, object_.bounds(), settings.shadowMap, scene_.material.ior,
                                      &stats, &entries_, int(l));
    samples_.insert(samples_.end(), lightSamples.begin(), lightSamples.end());
    report.lights.push_back(stats);
  }
  return watch.lapMs();
}

double CpuRenderer::runInjection(RenderReport& report) {
  Stopwatch watch;
  injected_.resize(material_.frame);
  report.injection =
      injectSamples(samples_, material_, injected_, factors_.scheme == LpvScheme::Calibrated ? &factors_ : nullptr);
  return watch.lapMs();
}

double CpuRenderer::runPropagation(const LpvSettings& settings, RenderReport& report) {
  Stopwatch watch;
  // Propagation consumes its source; the injected light is kept for the next re-run.
  ShGrid field = injected_;
  accumulated_.resize(material_.frame);
  PropagationOptions options;
  options.steps = settings.steps;
  options.autoSteps = settings.autoSteps;
  options.chebyshev = true;
  options.warmStart = &warm_;
  report.coarseStart = CoarseStartReport{};
  if (coarseStartEnabled_ && !warm_.holds(material_.frame))
    coarse_.start(object_, material_, factors_, settings.resolution, scene_.material.ior, samples_, options, warm_,
                  &report.coarseStart);
  report.propagation = propagate(material_, factors_, field, accumulated_, options);
  return watch.lapMs();
}

double CpuRenderer::runShading(Image& image) {
  Stopwatch watch;
  const bool calibrated = factors_.scheme == LpvScheme::Calibrated;
  const std::vector<EntryMap>* single = calibrated ? &entries_ : nullptr;
  // The camera rays and the cells each pixel reads depend on the camera and the
  // geometry only: a light move or a stroke re-shades without casting them again. A
  // view is kept only from its second frame on: storing it costs a one-shot render or
  // a camera drag (a new view every frame) more than tracing it (50 -> 150 ms at 512²).
  if (!surface_ && viewShadedOnce_)
    surface_ = std::make_unique<ShadingSurface>(traceShadingSurface(scene_.camera, *rays_, material_, scene_.material.ior));
  if (surface_)
    image = shadeSurface(*surface_, material_, accumulated_, scene_.material.ior, &factors_.exitGain,
                         &factors_.reducedAlbedo, single);
  else
    image = shadeImage(scene_.camera, *rays_, material_, accumulated_, scene_.material.ior, &factors_.exitGain,
                       &factors_.reducedAlbedo, single);
  viewShadedOnce_ = true;
  return watch.lapMs();
}

}  // namespace sslpv
