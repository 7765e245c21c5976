#include "volume/lpv/staged_renderer.h"

#include <chrono>

namespace sslpv {

Image StagedRenderer::render(const LpvSettings& settings, RenderReport* reportOut) {
  const auto frameStart = std::chrono::steady_clock::now();
  if (lastSettings_) {
    dirty_.settingsChanged(*lastSettings_, settings);
    settingsChanging(*lastSettings_, settings);
  }
  lastSettings_ = settings;
  // A new grid invalidates everything that lives on it, a pending partial resample too.
  if (dirty_.dirty(Stage::Voxelize)) dirty_.everything();

  RenderReport& report = last_;
  report.backend = name();
  report.times = StageTimes{};
  report.resampledCells = 0;
  StageTimes& times = report.times;
  const auto run = [&](Stage stage, double& ms, auto&& hook) {
    if (dirty_.dirty(stage))
      ms = hook();
    else
      times.markCached(stage);
  };
  run(Stage::Voxelize, times.voxelize, [&] { return runVoxelize(settings, report); });
  run(Stage::Resample, times.resample, [&] { return runResample(settings, report); });
  run(Stage::ShadowMap, times.shadowMap, [&] { return runShadowMaps(settings, report); });
  run(Stage::Injection, times.injection, [&] { return runInjection(report); });
  run(Stage::Propagation, times.propagation, [&] { return runPropagation(settings, report); });
  run(Stage::Shading, times.shading, [&] { return runShading(image_); });
  dirty_.clear();
  // After the stages: a backend may add setup it did during the frame (pipelines).
  times.load = loadMs_;
  report.wallMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - frameStart).count();
  if (reportOut) *reportOut = report;
  return image_;
}

}  // namespace sslpv
