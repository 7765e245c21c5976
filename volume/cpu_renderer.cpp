#include "volume/cpu_renderer.h"

#include <chrono>
#include <cstdio>
#include <glm/mat4x4.hpp>
#include <sstream>

#include "volume/error.h"
#include "volume/material_set.h"
#include "volume/mesh.h"
#include "volume/ray_scene.h"
#include "volume/voxelize.h"

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

std::unique_ptr<MaterialField> makeMaterialField(const Scene& scene) {
  std::shared_ptr<const MaterialSet> set;
  double sigmaScale = 1.0;
  if (scene.material.vdb) {
    set = loadMaterialSet(*scene.material.vdb);
    const auto fileUnit = unitInMm(set->units);
    if (!fileUnit)
      throw InputError(scene.material.vdb->string() + ": unknown units '" + set->units +
                       "' in file metadata (expected mm, cm, m or in)");
    // σ per file unit -> σ per scene unit.
    sigmaScale = scene.unitInMm / *fileUnit;
  }
  return std::make_unique<MaterialField>(scene.material.base, set, glm::inverse(scene.transform.matrix()),
                                         sigmaScale);
}

}  // namespace

CpuRenderer::CpuRenderer(const Scene& scene) : scene_(scene) {
  Stopwatch watch;
  mesh_ = std::make_unique<TriangleMesh>(loadMesh(scene.mesh, scene.transform));
  requireClosedMesh(*mesh_);
  triangles_ = mesh_->triangles.size();
  bounds_ = mesh_->bounds();
  rays_ = std::make_unique<RayScene>(*mesh_);
  field_ = makeMaterialField(scene);
  loadMs_ = watch.lapMs();
}

CpuRenderer::~CpuRenderer() = default;

Image CpuRenderer::render(const LpvSettings& settings, RenderReport* reportOut) {
  RenderReport report;
  report.times.load = loadMs_;
  report.triangles = triangles_;
  Stopwatch watch;

  MaterialGrid material;
  material.frame = makeGridFrame(bounds_, settings.resolution);
  const GridFrame& frame = material.frame;
  material.coverage = voxelizeCoverage(*mesh_, frame);
  report.times.voxelize = watch.lapMs();
  resampleMaterial(*field_, material);
  const StepFactors factors = computeStepFactors(material);
  report.times.resample = watch.lapMs();
  for (unsigned char a : factors.active) report.activeCells += a;
  report.frame = frame;

  std::vector<SurfaceFluxSample> samples;
  for (const Light& light : scene_.lights) {
    ShadowMapStats stats;
    auto lightSamples = castShadowMap(light, *rays_, bounds_, settings.shadowMap, scene_.material.ior, &stats);
    samples.insert(samples.end(), lightSamples.begin(), lightSamples.end());
    report.lights.push_back(stats);
  }
  report.times.shadowMap = watch.lapMs();

  ShGrid field, accumulated;
  field.resize(frame);
  accumulated.resize(frame);
  report.injection = injectSamples(samples, material, field);
  report.times.injection = watch.lapMs();

  PropagationOptions options;
  options.steps = settings.steps;
  options.autoSteps = settings.autoSteps;
  report.propagation = propagate(material, factors, field, accumulated, options);
  report.times.propagation = watch.lapMs();

  Image image = shadeImage(scene_.camera, *rays_, material, accumulated, scene_.material.ior);
  report.times.shading = watch.lapMs();
  if (reportOut) *reportOut = std::move(report);
  return image;
}

std::string formatTimings(const RenderReport& r) {
  char line[160];
  std::ostringstream out;
  const StageTimes& t = r.times;
  std::snprintf(line, sizeof line, "grid %dx%dx%d (cell %.4g, %zu active cells), %d steps, %zu triangles\n",
                r.frame.dims.x, r.frame.dims.y, r.frame.dims.z, r.frame.cellSize, r.activeCells,
                r.propagation.stepsRun, r.triangles);
  out << line;
  out << "stage                 ms\n";
  auto row = [&](const char* name, double ms) {
    std::snprintf(line, sizeof line, "%-18s %9.2f\n", name, ms);
    out << line;
  };
  row("shadow map", t.shadowMap);
  row("injection", t.injection);
  row("propagation", t.propagation);
  row("shading", t.shading);
  row("total", t.frame());
  out << "setup (once per object or material edit)\n";
  row("load", t.load);
  row("voxelize", t.voxelize);
  row("resample", t.resample);
  return out.str();
}

}  // namespace sslpv
