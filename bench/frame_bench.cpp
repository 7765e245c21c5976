// Whole-frame benchmark of both backends: per-stage milliseconds (median of repeated
// frames after warm-up), propagation throughput, a camera-only re-render, swept one
// setting at a time around a baseline (32³ grid, 8 steps, 256² shadow map, ~110K
// triangles, 1 light, 512² image). Prints a table; not a test.
//
//   frame_bench [--repeats 7] [--warmup 2] [--backend both|cpu|vulkan] [--quick] [--no-big] [--only SWEEP]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "bench/bench_meshes.h"
#include "bench/device_peaks.h"
#include "gpu/vk/device.h"
#include "gpu/vulkan_renderer.h"
#include "volume/cpu/cpu_renderer.h"
#include "volume/scene/material.h"
#include "volume/scene/scene.h"

namespace {
using namespace sslpv;

struct Case {
  std::string sweep;
  int grid = 32;
  int steps = 8;  ///< 0: auto
  int shadowMap = 256;
  std::size_t triangles = 110'000;
  int lights = 1;
};

struct Options {
  int repeats = 7, warmup = 2;
  bool cpu = true, vulkan = true, quick = false, big = true;
  bool coarseStart = true;  ///< --no-coarse-start: cold CPU frames start from the injected light
  std::string only;  ///< run only the cases of this sweep (empty: all)
};

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

Scene sceneFor(const Case& c, const std::shared_ptr<const TriangleMesh>& mesh) {
  const char* json = R"({
    "mesh": {"primitive": "sphere", "center": [0, 0, 0], "radius": 1},
    "material": {"base": {"preset": "marble"}, "ior": 1.5},
    "lights": [
      {"type": "spot", "position": [-105.0, 65.0, 25.0], "direction": [0.833360, -0.515889, -0.198419],
       "fov_deg": 40, "intensity": [30000, 28500, 26000]},
      {"type": "point", "position": [70.0, 15.0, -90.0], "intensity": [7000, 7500, 8000]}],
    "camera": {"position": [0.0, 35.0, 85.0], "target": [0.0, 0.0, 0.0], "fov_y_deg": 35,
               "width": 512, "height": 512}
  })";
  Scene scene = parseScene(json, "frame_bench.json");
  scene.mesh.kind = MeshSource::Kind::InMemory;
  scene.mesh.mesh = mesh;
  scene.lights.resize(std::size_t(c.lights));
  scene.lpv.resolution = c.grid;
  scene.lpv.steps = c.steps > 0 ? c.steps : 8;
  scene.lpv.autoSteps = c.steps == 0;
  scene.lpv.shadowMap = c.shadowMap;
  return scene;
}

struct Row {
  double voxelize = 0, resample = 0, shadow = 0, inject = 0, propagate = 0, shade = 0, total = 0, wall = 0;
  double cameraOnly = 0;
  double nudge = 0;     ///< wall clock of a frame after a small light move (CPU: warm-started)
  int steps = 0, nudgeSteps = 0;
  int coarseSteps = 0;  ///< steps on the coarser grids that started a cold CPU frame
  std::size_t activeCells = 0;
};

/// A full frame starts its propagation cold; the GPU's always does.
void startCold(CpuRenderer& renderer) { renderer.resetPropagation(); }
void startCold(gpu::VulkanRenderer&) {}

/// Full frames (lights marked changed: shadow maps onwards, propagation from scratch),
/// camera-only frames and light-nudge frames (every light 0.5 units up or down, about
/// 0.2 degrees as seen from the object, propagation from the last frame's light where the
/// backend keeps it), each after `warmup` untimed ones; the first frame also gives the
/// setup stages.
template <typename Renderer>
Row measure(Renderer& renderer, const Scene& scene, const Options& o) {
  Row row;
  RenderReport report;
  renderer.render(scene.lpv, &report);
  row.voxelize = report.times.voxelize;
  row.resample = report.times.resample;
  row.activeCells = report.activeCells;
  std::vector<double> shadow, inject, propagate, shade, total, wall, camera;
  for (int i = 0; i < o.warmup + o.repeats; ++i) {
    renderer.setLights(scene.lights);
    startCold(renderer);
    renderer.render(scene.lpv, &report);
    if (i < o.warmup) continue;
    shadow.push_back(report.times.shadowMap);
    inject.push_back(report.times.injection);
    propagate.push_back(report.times.propagation);
    shade.push_back(report.times.shading);
    total.push_back(report.times.frame());
    wall.push_back(report.wallMs);
    row.steps = report.propagation.stepsRun;
    row.coarseSteps = report.coarseStart.steps;
  }
  Camera cam = scene.camera;
  for (int i = 0; i < o.warmup + o.repeats; ++i) {
    cam.position.x = scene.camera.position.x + 0.5 * (i % 2 ? 1 : -1);  // a small orbit step
    renderer.setCamera(cam);
    renderer.render(scene.lpv, &report);
    if (i >= o.warmup) camera.push_back(report.wallMs);
  }
  std::vector<double> nudge;
  std::vector<Light> lights = scene.lights;
  for (int i = 0; i < o.warmup + o.repeats; ++i) {
    for (Light& l : lights) l.position.y += i % 2 ? -0.5 : 0.5;
    renderer.setLights(lights);
    renderer.render(scene.lpv, &report);
    if (i < o.warmup) continue;
    nudge.push_back(report.wallMs);
    row.nudgeSteps = report.propagation.stepsRun;
  }
  row.nudge = median(nudge);
  row.shadow = median(shadow);
  row.inject = median(inject);
  row.propagate = median(propagate);
  row.shade = median(shade);
  row.total = median(total);
  row.wall = median(wall);
  row.cameraOnly = median(camera);
  return row;
}

/// Propagation's achieved rate against the device's roofline (vulkan rows only).
struct Roofline {
  bool valid = false;
  bench::Peaks peaks;
};

void printRow(const Case& c, const char* backend, const Row& r, const Roofline& roof = {}) {
  char steps[32];
  std::snprintf(steps, sizeof steps, r.coarseSteps > 0 ? "%d+%d" : "%d", r.steps, r.coarseSteps);
  const double mcells = r.propagate > 0 ? double(r.activeCells) * r.steps / (r.propagate * 1e3) : 0.0;
  char roofText[96] = "";
  if (roof.valid && r.propagate > 0) {
    // The scene is calibrated (sceneFor): its steps after the first are isotropic.
    const double flops = bench::propagationFlopsPerCellStep(true, r.steps);
    const double gflops = mcells * 1e6 * flops * 1e-9;
    const double gbs = mcells * 1e6 * bench::kBytesPerCellStep * 1e-9;
    const double intensity = flops / bench::kBytesPerCellStep;
    const double attainable = std::min(roof.peaks.fmaGflops, intensity * roof.peaks.bandwidth());
    std::snprintf(roofText, sizeof roofText, " | %7.2f %6.2f %5.1f", gflops, gbs, 100.0 * gflops / attainable);
  }
  std::printf("%-9s %-7s %5d %5s %6d %9zu %2d | %8.2f %8.2f %8.2f %8.2f %8.2f %8.2f %8.2f %8.2f %5d | %9.2f %9.2f | "
              "%8.2f %7s %9zu%s\n",
              c.sweep.c_str(), backend, c.grid, c.steps ? std::to_string(c.steps).c_str() : "auto", c.shadowMap,
              c.triangles, c.lights, r.shadow, r.inject, r.propagate, r.shade, r.total, r.wall, r.cameraOnly, r.nudge,
              r.nudgeSteps, r.voxelize, r.resample, mcells, steps, r.activeCells, roofText);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
      return argv[++i];
    };
    if (a == "--repeats") o.repeats = std::max(1, std::stoi(next()));
    else if (a == "--warmup") o.warmup = std::max(0, std::stoi(next()));
    else if (a == "--backend") {
      const std::string b = next();
      o.cpu = b == "cpu" || b == "both";
      o.vulkan = b == "vulkan" || b == "both";
    } else if (a == "--quick") o.quick = true;
    else if (a == "--no-big") o.big = false;
    else if (a == "--only") o.only = next();
    else if (a == "--no-coarse-start") o.coarseStart = false;
    else {
      std::fprintf(stderr, "frame_bench: unknown argument %s\n", a.c_str());
      return 2;
    }
  }

  std::vector<Case> cases;
  const Case base{"baseline"};
  cases.push_back(base);
  for (int g : {16, 64, 128}) cases.push_back(Case{"grid", g});
  for (int s : {4, 16, 32, 0}) {
    Case c = base;
    c.sweep = "steps";
    c.steps = s;
    cases.push_back(c);
  }
  for (int s : {128, 512}) {
    Case c = base;
    c.sweep = "shadow";
    c.shadowMap = s;
    cases.push_back(c);
  }
  for (std::size_t t : bench::kBenchTriangleTargets) {
    if (t == base.triangles || (t > 1'000'000 && !o.big)) continue;
    Case c = base;
    c.sweep = "mesh";
    c.triangles = t;
    cases.push_back(c);
  }
  {
    Case c = base;
    c.sweep = "lights";
    c.lights = 2;
    cases.push_back(c);
  }
  for (int g : {32, 64}) {
    Case c = base;
    c.sweep = "auto";
    c.grid = g;
    c.steps = 0;
    cases.push_back(c);
  }
  if (!o.only.empty())
    cases.erase(std::remove_if(cases.begin(), cases.end(), [&](const Case& c) { return c.sweep != o.only; }),
                cases.end());
  if (o.quick) cases.resize(std::min<std::size_t>(cases.size(), 4));

  std::unique_ptr<gpu::VulkanDevice> device;
  if (o.vulkan) {
    try {
      device = std::make_unique<gpu::VulkanDevice>();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "frame_bench: no Vulkan device (%s); timing the CPU backend only\n", e.what());
      o.vulkan = false;
    }
  }
  std::printf("frame_bench: median of %d frames after %d warm-up; 512x512 image; times in ms\n", o.repeats, o.warmup);
  std::printf("stage columns are device times (GPU timestamps) for vulkan, wall clock per stage for cpu;\n"
              "wall = whole frame as the caller sees it (propagation from scratch); camera = wall clock of a\n"
              "camera-only re-render; nudge, nsteps = wall clock and steps of a frame after a 0.5-unit light move\n"
              "(cpu --steps auto: propagation from the last frame's light);\n"
              "voxelize/resample run once per mesh or material change (shown from the first frame);\n"
              "steps (last column group) = fine+coarse: a cold cpu auto frame first solves the frame on coarser\n"
              "grids (their steps after the +, their time inside propag; --no-coarse-start: off), Mcell/s counts\n"
              "the fine steps only\n");
  Roofline roof;
  if (device) {
    std::printf("vulkan device: %s\n", device->name().c_str());
    bench::PeakProbe probe(*device);
    roof.peaks = probe.measure(o.repeats);
    roof.valid = true;
    std::printf("device peaks measured now: FMA %.1f GFLOP/s, vec4 triad %.2f GB/s; propagation does %.0f flop and\n"
                "%.0f B per active cell-step on its first step, %.0f flop on the isotropic ones after it\n"
                "(bench/gpu_propagation_bench.cpp explains the count); roof%% = achieved GFLOP/s over\n"
                "min(FMA peak, flop/B x triad peak)\n",
                roof.peaks.fmaGflops, roof.peaks.bandwidth(), bench::kFlopsPerCellStep, bench::kBytesPerCellStep,
                bench::kIsotropicFlopsPerCellStep);
  }
  std::printf("%-9s %-7s %5s %5s %6s %9s %2s | %8s %8s %8s %8s %8s %8s %8s %8s %5s | %9s %9s | %8s %7s %9s | %7s %6s "
              "%5s\n",
              "sweep", "backend", "grid", "steps", "shadow", "triangles", "L", "shadow", "inject", "propag", "shade",
              "total", "wall", "camera", "nudge", "nsteps", "voxelize", "resample", "Mcell/s", "steps", "active",
              "GFLOP/s", "GB/s", "roof%");

  std::shared_ptr<const TriangleMesh> mesh;
  std::size_t meshTarget = 0;
  for (const Case& c : cases) {
    if (!mesh || meshTarget != c.triangles) {
      mesh = std::make_shared<const TriangleMesh>(bench::makeBenchMesh(c.triangles, glm::vec3(0.0f), 20.0f));
      meshTarget = c.triangles;
    }
    Case shown = c;
    shown.triangles = mesh->triangles.size();
    const Scene scene = sceneFor(c, mesh);
    try {
      if (o.cpu) {
        CpuRenderer cpu(scene);
        cpu.setCoarseStart(o.coarseStart);
        printRow(shown, "cpu", measure(cpu, scene, o));
      }
      if (o.vulkan) {
        gpu::VulkanRenderer vulkan(scene, *device);
        printRow(shown, "vulkan", measure(vulkan, scene, o), roof);
      }
    } catch (const std::exception& e) {
      std::printf("%-9s grid %d: failed: %s\n", c.sweep.c_str(), c.grid, e.what());
    }
  }
  return 0;
}
