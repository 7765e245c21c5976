// Stroke -> updated preview latency, measured the way the editor works (EditSession):
// one stroke of ~20 dabs (radius 3 LPV cells, spacing radius/4, a straight line through
// the object's centre) followed by renderPreview(), which re-resamples only the touched
// cells and re-propagates. Each run paints a real change (the stroke's target material
// alternates between two albedos). For context, "full" is a frame whose whole material
// changed (every cell resampled, then propagation and shading) on a second renderer at
// the same settings, run alternately with the strokes: inc/full is how much the region
// path saves on this machine.
// The editor renders its preview on a worker thread: "ui" is what a stroke costs the UI
// thread that way (paint + requestPreview, which copies the set for the worker), "shown"
// is from the end of the stroke until its frame is finished. "total" (paint + a frame the
// caller waits for) is what the UI thread was blocked for when the preview rendered on it.
// "draft" is a mid-stroke draft frame (kDraftPreviewResolution³), request to arrival.
// Prints medians of --runs after --warmup runs.
// Usage: preview_latency [--examples DIR] [--runs N] [--warmup N] [--size PX]
//                        [--backend cpu|vulkan|both] [--grid 32|64|both]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "volume/eval/image_metrics.h"
#include "editor/edit_session.h"
#include "volume/core/error.h"

#if __has_include(<vulkan/vulkan.h>)
#include "gpu/vk/vk_check.h"
#define PREVIEW_BENCH_GPU_ERROR 1
#endif

#ifndef SSLPV_SOURCE_DIR
#define SSLPV_SOURCE_DIR "."
#endif

namespace {

using namespace sslpv;
using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

double ms(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double, std::milli>(b - a).count(); }

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct Run {
  double paint = 0, preview = 0, total = 0;
  double ui = 0, shown = 0;  ///< the asynchronous stroke: UI-thread time, end of stroke to frame
  double draft = 0;          ///< mid-stroke: request to finished draft frame
  double resample = 0, propagation = 0, shading = 0, other = 0;
  double cells = 0, voxels = 0, dabs = 0, steps = 0;
};

struct Row {
  std::string scene, backend;
  int grid = 0;
  bool autoSteps = false;
  Run med;
  double full = 0, fullResample = 0, fullPropagation = 0, fullSteps = 0, cold = 0;
  double maxDifference = 0;  ///< incremental vs full frame, largest over all runs
  std::size_t gridCells = 0;
};


template <class F>
double medianOf(const std::vector<Run>& runs, F field) {
  std::vector<double> v;
  for (const Run& r : runs) v.push_back(field(r));
  return median(v);
}

Row measure(const fs::path& scenePath, BackendKind backend, int grid, bool autoSteps, int size, int warmup,
            int runs) {
  const Scene scene = loadScene(scenePath);
  PreviewOptions options;
  options.backend = backend;
  options.longestSide = size;
  LpvSettings lpv = scene.lpv;
  lpv.resolution = grid;
  lpv.autoSteps = autoSteps;
  if (!autoSteps) lpv.steps = 8;
  options.lpv = lpv;
  EditSession session(scenePath, options);

  Row row;
  row.scene = scenePath.stem().string();
  row.backend = session.previewBackendName();
  row.grid = grid;
  row.autoSteps = autoSteps;

  RenderReport report;
  Clock::time_point t0 = Clock::now();
  session.renderPreview(&report);
  row.cold = ms(t0, Clock::now());
  row.gridCells = report.frame.cellCount();

  // ~20 dabs: a segment of length 19 r/4 gets 19 dabs after the first point's one.
  const double radius = 3.0 * report.frame.cellSize;
  const Bounds bounds = session.worldMesh().bounds();
  const glm::dvec3 centre = 0.5 * (bounds.min + bounds.max);
  const glm::dvec3 half(0.5 * 19.0 * radius / 4.0, 0.0, 0.0);
  const std::vector<glm::dvec3> points{centre - half, centre + half};

  // The same frame with the whole material changed, on its own renderer. Its runs are
  // interleaved with the session's, so both see the same load on a shared machine.
  Scene fullScene = scene;
  fullScene.camera = session.previewCamera();
  fullScene.material.vdb.reset();
  std::unique_ptr<Renderer> full = makeRenderer(fullScene, backend);
  full->setMaterialSet(session.engine().materialSet(), std::nullopt);
  full->render(session.previewSettings(), nullptr);
  std::vector<double> fullMs, fullResample, fullPropagation, fullSteps;

  std::vector<Run> samples;
  for (int i = 0; i < warmup + runs; ++i) {
    Brush brush;
    brush.channel = BrushChannel::AlbedoMfp;
    brush.mode = BrushMode::Set;
    brush.albedo = i % 2 ? glm::dvec3(0.95, 0.9, 0.8) : glm::dvec3(0.3, 0.5, 0.7);
    brush.meanFreePath = glm::dvec3(report.frame.cellSize);
    brush.radius = radius;
    brush.falloff = BrushFalloff::Smooth;

    Run run;
    t0 = Clock::now();
    session.beginStroke(brush);
    session.addPoints(points);
    const StrokeResult stroke = session.endStroke();
    const Clock::time_point t1 = Clock::now();
    RenderReport frame;
    const Image preview = session.renderPreview(&frame);
    const Clock::time_point t2 = Clock::now();
    run.paint = ms(t0, t1);
    run.preview = ms(t1, t2);
    run.total = ms(t0, t2);
    run.resample = frame.times.resample;
    run.propagation = frame.times.propagation;
    run.shading = frame.times.shading;
    run.other = frame.times.voxelize + frame.times.shadowMap + frame.times.injection;
    run.cells = double(frame.resampledCells);
    run.voxels = double(stroke.voxelsChanged);
    run.dabs = double(stroke.dabs);
    run.steps = frame.propagation.stepsRun;
    if (stroke.voxelsChanged == 0) std::fprintf(stderr, "warning: a stroke changed nothing (run %d)\n", i);

    RenderReport fullFrame;
    const Clock::time_point t3 = Clock::now();
    full->setMaterialSet(session.engine().materialSet(), std::nullopt);
    const Image fullImage = full->render(session.previewSettings(), &fullFrame);
    const double fullWall = ms(t3, Clock::now());
    row.maxDifference = std::max(row.maxDifference, maxRelativeDifference(preview, fullImage));

    // The same stroke as the editor now runs it: the UI thread paints and hands the state
    // over, the frame follows on the worker. A third target, so that this stroke and the
    // next run's each change every voxel they reach as much as the strokes above.
    brush.albedo = glm::dvec3(0.6, 0.7, 0.9);
    const Clock::time_point a0 = Clock::now();
    session.beginStroke(brush);
    session.addPoints(points);
    session.endStroke();
    session.requestPreview(PreviewQuality::Full);
    const Clock::time_point a1 = Clock::now();
    session.waitForPreview();
    run.ui = ms(a0, a1);
    run.shown = ms(a1, Clock::now());

    // What the editor shows during a stroke: a draft (kDraftPreviewResolution³) after a dab.
    session.beginStroke(brush);
    session.addPoints(points);
    const Clock::time_point d0 = Clock::now();
    session.requestPreview(PreviewQuality::Draft);
    session.waitForPreview();
    run.draft = ms(d0, Clock::now());
    session.endStroke();
    if (i < warmup) continue;
    samples.push_back(run);
    fullMs.push_back(fullWall);
    fullResample.push_back(fullFrame.times.resample);
    fullPropagation.push_back(fullFrame.times.propagation);
    fullSteps.push_back(fullFrame.propagation.stepsRun);
  }
  Run& m = row.med;
  m.paint = medianOf(samples, [](const Run& r) { return r.paint; });
  m.preview = medianOf(samples, [](const Run& r) { return r.preview; });
  m.total = medianOf(samples, [](const Run& r) { return r.total; });
  m.resample = medianOf(samples, [](const Run& r) { return r.resample; });
  m.propagation = medianOf(samples, [](const Run& r) { return r.propagation; });
  m.shading = medianOf(samples, [](const Run& r) { return r.shading; });
  m.other = medianOf(samples, [](const Run& r) { return r.other; });
  m.cells = medianOf(samples, [](const Run& r) { return r.cells; });
  m.voxels = medianOf(samples, [](const Run& r) { return r.voxels; });
  m.dabs = medianOf(samples, [](const Run& r) { return r.dabs; });
  m.steps = medianOf(samples, [](const Run& r) { return r.steps; });
  m.ui = medianOf(samples, [](const Run& r) { return r.ui; });
  m.shown = medianOf(samples, [](const Run& r) { return r.shown; });
  m.draft = medianOf(samples, [](const Run& r) { return r.draft; });

  row.full = median(fullMs);
  row.fullResample = median(fullResample);
  row.fullPropagation = median(fullPropagation);
  row.fullSteps = median(fullSteps);
  return row;
}

void printRow(const Row& r) {
  std::printf(
      "%-18s %-7s %4d %5s %5.0f %4.0f %8.0f %7.0f/%-7zu | %8.2f | %8.2f %7.2f %8.2f %7.2f %6.2f | %8.2f | %8.2f "
      "(%7.2f %8.2f %5.0f) %8.2f | %6.3f %6.3f %8.1e | %7.2f %8.2f %7.2f\n",
      r.scene.c_str(), r.backend.substr(0, r.backend.find(' ')).c_str(), r.grid, r.autoSteps ? "auto" : "8",
      r.med.steps, r.med.dabs, r.med.voxels, r.med.cells, r.gridCells, r.med.paint, r.med.preview, r.med.resample,
      r.med.propagation, r.med.shading, r.med.other, r.med.total, r.full, r.fullResample, r.fullPropagation, r.fullSteps, r.cold,
      r.med.preview / r.full, r.med.total / r.full, r.maxDifference, r.med.ui, r.med.shown, r.med.draft);
}

}  // namespace

int main(int argc, char** argv) {
  fs::path examples = fs::path(SSLPV_SOURCE_DIR) / "examples";
  int runs = 9, warmup = 2, size = 256;
  std::string backends = "both";
  std::string grids = "both";
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--examples"))
      examples = argv[i + 1];
    else if (!std::strcmp(argv[i], "--runs"))
      runs = std::max(1, std::atoi(argv[i + 1]));
    else if (!std::strcmp(argv[i], "--warmup"))
      warmup = std::max(0, std::atoi(argv[i + 1]));
    else if (!std::strcmp(argv[i], "--size"))
      size = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--backend"))
      backends = argv[i + 1];
    else if (!std::strcmp(argv[i], "--grid"))
      grids = argv[i + 1];
    else {
      std::fprintf(stderr,
                   "usage: preview_latency [--examples DIR] [--runs N] [--warmup N] [--size PX] "
                   "[--backend cpu|vulkan|both] [--grid 32|64|both]\n");
      return 2;
    }
  }
  if (argc % 2 == 0 || (backends != "cpu" && backends != "vulkan" && backends != "both") ||
      (grids != "32" && grids != "64" && grids != "both")) {
    std::fprintf(stderr, "usage: preview_latency [--examples DIR] [--runs N] [--warmup N] [--size PX] "
                         "[--backend cpu|vulkan|both] [--grid 32|64|both]\n");
    return 2;
  }
  std::printf("preview_latency:");
  for (int i = 0; i < argc; ++i) std::printf(" %s", argv[i]);
  std::printf("\nmedian of %d runs after %d warm-up runs; preview %d px longest side; times in ms\n", runs, warmup,
              size);
  std::printf("stroke: ~20 dabs, radius 3 LPV cells, smooth falloff, albedo_mfp set (alternating targets)\n");
  std::printf("paint = beginStroke..endStroke; preview = renderPreview (stages: resample, propagate, shade, other =\n"
              "voxelize+shadow+inject, should be 0); full = whole-material frame (resample all + propagate + shade);\n"
              "ran = the preview's propagation steps (cpu --steps auto: from the last frame's light), full steps =\n"
              "the full frame's (from scratch); cold = the session's first frame (everything, incl. one-time\n"
              "setup); inc/full = preview/full, "
              "tot/full = (paint+preview)/full;\n"
              "maxdiff = largest relative pixel difference, incremental preview vs the full frame (all runs);\n"
              "ui = the same stroke as the editor runs it: paint + requestPreview (the UI thread's share; total is\n"
              "what it was with the frame rendered on the UI thread); shown = end of that stroke to its frame;\n"
              "draft = mid-stroke, a draft frame's request to its arrival\n\n");
  std::printf("%-18s %-7s %4s %5s %5s %4s %8s %15s | %8s | %8s %7s %8s %7s %6s | %8s | %8s (%7s %8s %5s) %8s | %6s %6s %8s | %7s %8s %7s\n",
              "scene", "backend", "grid", "steps", "ran", "dabs", "voxels", "cells resampled", "paint", "preview",
              "resamp", "propag", "shade", "other", "total", "full", "resamp", "propag", "steps", "cold", "inc/f", "tot/f",
              "maxdiff", "ui", "shown", "draft");

  std::vector<BackendKind> kinds;
  if (backends != "vulkan") kinds.push_back(BackendKind::Cpu);
  if (backends != "cpu") kinds.push_back(BackendKind::Vulkan);
  bool vulkanMissing = false;
  for (const char* name : {"marble_pebble.json", "jade_slab_backlit.json"})
    for (BackendKind kind : kinds)
      for (int grid : {32, 64})
        for (bool autoSteps : {true, false}) {
          if (kind == BackendKind::Vulkan && vulkanMissing) continue;
          if (grids != "both" && std::to_string(grid) != grids) continue;
          try {
            printRow(measure(examples / name, kind, grid, autoSteps, size, warmup, runs));
            std::fflush(stdout);
#ifdef PREVIEW_BENCH_GPU_ERROR
          } catch (const GpuError& e) {
            if (kind != BackendKind::Vulkan) throw;
            vulkanMissing = true;
            std::printf("SKIPPED vulkan rows: %s\n", e.what());
#endif
          } catch (const ResourceError& e) {
            // Built without the Vulkan backend.
            if (kind != BackendKind::Vulkan) throw;
            vulkanMissing = true;
            std::printf("SKIPPED vulkan rows: %s\n", e.what());
          } catch (const InputError& e) {
            std::fprintf(stderr, "preview_latency: %s\n", e.what());
            return 2;
          }
        }
  return 0;
}
