// What a deforming object costs per frame against the same object held still, on each
// backend: the scene's deformed frame (setTime: re-voxelize, resample through the
// deformers' inverse, shadow maps, injection, propagation from the last frame's light
// where the backend keeps it, shading) against the same scene held in its first pose: its
// full frame (a light change: shadow maps onwards, propagation from scratch) and its
// light-nudge frame. The same scene means the same grid: a deformed scene's grid spans
// all its poses (SceneObject::gridBounds). Median of repeated frames after warm-up, with the lavapipe
// device's FMA and triad peaks measured in the same run. Prints a table; not a test.
//
//   deform_bench [--scene FILE] [--grid N[,N...]] [--repeats 5] [--warmup 1]
//                [--backend both|cpu|vulkan] [--start T0] [--step-time DT]
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "bench/device_peaks.h"
#include "gpu/vk/device.h"
#include "gpu/vulkan_renderer.h"
#include "bench/int_list.h"
#include "volume/cpu/cpu_renderer.h"
#include "volume/scene/scene.h"

namespace {
using namespace sslpv;

struct Options {
  std::string scene = std::string(SSLPV_SOURCE_DIR) + "/examples/bending_bar.json";
  std::vector<int> grids{32, 64};
  int repeats = 5, warmup = 1;
  bool cpu = true, vulkan = true;
  double start = 0.2, stepTime = 0.01;  ///< 0.01: about 3° of the bar's bend a frame
};

struct Timing {
  double wall = 0.0;
  int steps = 0;
  StageTimes stages;  ///< of the last timed frame
};

void startCold(CpuRenderer& renderer) { renderer.resetPropagation(); }
void startCold(gpu::VulkanRenderer&) {}

/// Calls frame(i) for warmup + repeats frames and returns the median wall clock of the
/// timed ones.
template <typename Renderer, typename Frame>
Timing timeFrames(Renderer& renderer, const LpvSettings& settings, const Options& o, Frame&& frame) {
  std::vector<double> walls;
  Timing t;
  RenderReport report;
  for (int i = 0; i < o.warmup + o.repeats; ++i) {
    frame(i);
    renderer.render(settings, &report);
    if (i < o.warmup) continue;
    walls.push_back(report.wallMs);
    t.steps = report.propagation.stepsRun;
    t.stages = report.times;
  }
  t.wall = bench::medianOf(walls);
  return t;
}

template <typename Renderer>
void measure(const char* backend, int grid, const Scene& animated, const Options& o,
             const std::function<std::unique_ptr<Renderer>(const Scene&)>& make) {
  LpvSettings settings = animated.lpv;
  settings.resolution = grid;
  settings.autoSteps = true;
  auto fixed = make(animated);
  fixed->setTime(o.start);
  fixed->render(settings);
  const Timing full = timeFrames(*fixed, settings, o, [&](int) {
    fixed->setLights(animated.lights);
    startCold(*fixed);
  });
  std::vector<Light> lights = animated.lights;
  const Timing nudge = timeFrames(*fixed, settings, o, [&](int i) {
    for (Light& l : lights) l.position.y += i % 2 ? -0.5 : 0.5;
    fixed->setLights(lights);
  });
  auto moving = make(animated);
  moving->setTime(o.start);
  moving->render(settings);
  const Timing deformed =
      timeFrames(*moving, settings, o, [&](int i) { moving->setTime(o.start + (i + 1) * o.stepTime); });
  std::printf("%-7s %4d | %8.1f %5d | %8.1f %5d | %8.1f %5d | %5.2f %5.2f |", backend, grid, full.wall, full.steps,
              nudge.wall, nudge.steps, deformed.wall, deformed.steps, deformed.wall / full.wall,
              deformed.wall / nudge.wall);
  for (const Timing* t : {&full, &deformed}) {
    const StageTimes& s = t->stages;
    std::printf(" %6.1f %6.1f %6.1f %6.1f %6.1f %6.1f |", s.voxelize, s.resample, s.shadowMap, s.injection,
                s.propagation, s.shading);
  }
  std::printf("\n");
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "deform_bench: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--scene") o.scene = next();
    else if (a == "--grid") {
      o.grids = bench::parseIntList(next());
    } else if (a == "--repeats") o.repeats = std::max(1, std::stoi(next()));
    else if (a == "--warmup") o.warmup = std::max(0, std::stoi(next()));
    else if (a == "--backend") {
      const std::string b = next();
      o.cpu = b == "cpu" || b == "both";
      o.vulkan = b == "vulkan" || b == "both";
    } else if (a == "--start") o.start = std::stod(next());
    else if (a == "--step-time") o.stepTime = std::stod(next());
    else {
      std::fprintf(stderr, "deform_bench: unknown argument %s\n", a.c_str());
      return 2;
    }
  }
  const Scene animated = loadScene(o.scene);
  if (animated.deformers.empty()) {
    std::fprintf(stderr, "deform_bench: %s has no deformers\n", o.scene.c_str());
    return 2;
  }

  std::unique_ptr<gpu::VulkanDevice> device;
  if (o.vulkan) {
    try {
      device = std::make_unique<gpu::VulkanDevice>();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "deform_bench: no Vulkan device (%s); timing the CPU backend only\n", e.what());
      o.vulkan = false;
    }
  }
  std::printf("deform_bench: %s, %dx%d, --steps auto; median of %d frames after %d warm-up, ms (wall clock)\n",
              o.scene.c_str(), animated.camera.width, animated.camera.height, o.repeats, o.warmup);
  std::printf("full = the scene held at t = %g after a light change (shadow maps onwards, cold propagation);\n"
              "nudge = the same after a 0.5-unit light move (warm where the backend keeps light);\n"
              "deformed = the animated scene advanced by %g from t = %g each frame (everything from voxelize);\n"
              "x full, x nudge = deformed over them; then the stages of a full and a deformed frame (vox, resam,\n"
              "shadow, inject, propag, shade; 0 where cached)\n",
              o.start, o.stepTime, o.start);
  if (device) {
    bench::PeakProbe probe(*device);
    const bench::Peaks peaks = probe.measure(o.repeats);
    std::printf("lavapipe peaks measured now: FMA %.1f GFLOP/s, vec4 triad %.2f GB/s\n", peaks.fmaGflops,
                peaks.bandwidth());
  }
  std::printf("%-7s %4s | %8s %5s | %8s %5s | %8s %5s | %5s %5s | %-41s | %-41s |\n", "backend", "grid", "full",
              "steps", "nudge", "steps", "deformed", "steps", "xfull", "xnudg", "full frame stages",
              "deformed frame stages");
  for (int grid : o.grids) {
    try {
      if (o.cpu)
        measure<CpuRenderer>("cpu", grid, animated, o,
                             [](const Scene& s) { return std::make_unique<CpuRenderer>(s); });
      if (o.vulkan)
        measure<gpu::VulkanRenderer>("vulkan", grid, animated, o, [&](const Scene& s) {
          return std::make_unique<gpu::VulkanRenderer>(s, *device);
        });
    } catch (const std::exception& e) {
      std::printf("grid %d: failed: %s\n", grid, e.what());
    }
  }
  return 0;
}
