#include "volume/lpv/frame_report.h"

#include <cstdio>
#include <sstream>

namespace sslpv {

void StageDirty::materialChanged(const std::optional<Bounds>& region) {
  const bool wholeAlready = dirty(Stage::Resample) && !region_;
  // The calibrated injection depth follows the material (1 / σt'), so injection reruns;
  // it costs about a millisecond.
  set({Stage::Resample, Stage::Injection, Stage::Propagation, Stage::Shading});
  if (wholeAlready || !region) {
    region_.reset();
    return;
  }
  // Two strokes before one frame: their union.
  if (region_) {
    region_->extend(region->min);
    region_->extend(region->max);
  } else {
    region_ = region;
  }
}

void StageDirty::settingsChanged(const LpvSettings& before, const LpvSettings& after) {
  if (before.resolution != after.resolution) {
    geometryChanged();
    return;
  }
  if (before.shadowMap != after.shadowMap) lightsChanged();
  // The step factors are derived with the material and the injection differs per scheme.
  if (before.scheme != after.scheme) {
    set({Stage::Resample, Stage::Injection, Stage::Propagation, Stage::Shading});
    region_.reset();
  }
  if (before.steps != after.steps || before.autoSteps != after.autoSteps)
    set({Stage::Propagation, Stage::Shading});
}

std::string formatTimings(const RenderReport& r) {
  char line[160];
  std::ostringstream out;
  const StageTimes& t = r.times;
  std::snprintf(line, sizeof line, "%s backend, grid %dx%dx%d (cell %.4g, %zu active cells), %d steps, %zu triangles\n",
                r.backend.c_str(), r.frame.dims.x, r.frame.dims.y, r.frame.dims.z, r.frame.cellSize, r.activeCells,
                r.propagation.stepsRun, r.triangles);
  out << line;
  if (r.coarseStart.levels > 0) {
    std::snprintf(line, sizeof line, "started from %d coarser grid%s: %d steps there, %.2f ms (in propagation)\n",
                  r.coarseStart.levels, r.coarseStart.levels > 1 ? "s" : "", r.coarseStart.steps, r.coarseStart.ms);
    out << line;
  }
  if (r.propagation.capped)
    out << "warning: --steps auto stopped at its cap of " << r.propagation.stepsRun
        << " steps before converging: the light is not converged\n";
  out << "stage                 ms\n";
  auto row = [&](const char* name, double ms, bool cached) {
    if (cached)
      std::snprintf(line, sizeof line, "%-18s %9s\n", name, "cached");
    else
      std::snprintf(line, sizeof line, "%-18s %9.2f\n", name, ms);
    out << line;
  };
  row("shadow map", t.shadowMap, t.cached(Stage::ShadowMap));
  row("injection", t.injection, t.cached(Stage::Injection));
  row("propagation", t.propagation, t.cached(Stage::Propagation));
  row("shading", t.shading, t.cached(Stage::Shading));
  row("total", t.frame(), false);
  if (r.wallMs > 0.0) row("frame wall clock", r.wallMs, false);
  out << "setup (once per object or material edit)\n";
  row("load", t.load, false);
  row("voxelize", t.voxelize, t.cached(Stage::Voxelize));
  row("resample", t.resample, t.cached(Stage::Resample));
  return out.str();
}

}  // namespace sslpv
