// Temporal stability of the preview under slow change: renders a sequence of a scene whose
// lights orbit the camera's target about the vertical axis by a small angle per frame (as a
// user dragging a light, or an animated one, would see it), or, with --animate T0, whose
// deformers advance from time T0 by --step-time per frame (a slowly bending bar, re-voxelized
// and resampled every frame), and prints volume/eval/temporal_metrics.h's motion and flicker, for
// the step and for twice it. A smooth change's flicker/motion doubles with the step; flicker
// from texels or cells switching does not. Each frame warm-starts from the last, as a live
// preview does. Prints a table; not a test.
//
//   flicker [--scene FILE] [--grid N[,N...]] [--frames N] [--step-deg D] [--size PX]
//           [--animate T0 [--step-time DT]] [--cold]
// --cold renders every frame from a fresh renderer, to tell the warm start's early stop
// from the discretization's own jumps.
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "bench/int_list.h"
#include "volume/cpu/cpu_renderer.h"
#include "volume/scene/scene.h"
#include "volume/eval/temporal_metrics.h"

namespace {
using namespace sslpv;

std::vector<Light> orbited(const std::vector<Light>& lights, const glm::dvec3& centre, double degrees) {
  const glm::dmat4 turn = glm::rotate(glm::dmat4(1.0), glm::radians(degrees), glm::dvec3(0.0, 1.0, 0.0));
  std::vector<Light> out = lights;
  for (Light& l : out) {
    l.position = centre + glm::dvec3(turn * glm::dvec4(l.position - centre, 1.0));
    l.direction = glm::normalize(glm::dvec3(turn * glm::dvec4(l.direction, 0.0)));
  }
  return out;
}

/// What changes from frame to frame: the lights' orbit angle, or the scene's time.
struct Motion {
  bool animate = false;  ///< advance time (deformers) instead of orbiting the lights
  double start = 0.0;    ///< first frame's time (animate)
  double step = 0.0;     ///< degrees or time per frame
  bool cold = false;     ///< every frame from a fresh renderer: no warm start to stop early
};

TemporalChange measure(const Scene& scene, int grid, int frames, const Motion& motion) {
  auto renderer = std::make_unique<CpuRenderer>(scene);
  LpvSettings settings = scene.lpv;
  settings.resolution = grid;
  settings.autoSteps = true;
  std::vector<Image> images;
  for (int f = 0; f < frames; ++f) {
    if (motion.cold) renderer = std::make_unique<CpuRenderer>(scene);
    if (motion.animate)
      renderer->setTime(motion.start + f * motion.step);
    else
      renderer->setLights(orbited(scene.lights, scene.camera.target, f * motion.step));
    images.push_back(renderer->render(settings));
  }
  return temporalChange(images);
}

}  // namespace

int main(int argc, char** argv) {
  std::string scenePath = std::string(SSLPV_SOURCE_DIR) + "/examples/marble_pebble.json";
  std::vector<int> grids{32, 64};
  int frames = 16, size = 256;
  double stepDeg = 0.25, stepTime = 0.005;
  Motion motion;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto next = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
      return argv[++i];
    };
    if (a == "--scene") scenePath = next();
    else if (a == "--grid") {
      grids = bench::parseIntList(next());
    } else if (a == "--frames") frames = std::max(3, std::stoi(next()));
    else if (a == "--step-deg") stepDeg = std::stod(next());
    else if (a == "--size") size = std::stoi(next());
    else if (a == "--animate") {
      motion.animate = true;
      motion.start = std::stod(next());
    } else if (a == "--step-time") stepTime = std::stod(next());
    else if (a == "--cold") motion.cold = true;
    else {
      std::fprintf(stderr, "usage: flicker [--scene FILE] [--grid N,...] [--frames N] [--step-deg D] [--size PX] "
                           "[--animate T0 [--step-time DT]] [--cold]\n");
      return 2;
    }
  }
  Scene scene = loadScene(scenePath);
  scene.camera.width = scene.camera.height = size;
  if (motion.animate && scene.deformers.empty()) {
    std::fprintf(stderr, "flicker: %s has no deformers to animate\n", scenePath.c_str());
    return 2;
  }
  const double baseStep = motion.animate ? stepTime : stepDeg;
  std::printf("flicker: %s, %d frames, %dx%d, %s; CPU backend,\n"
              "--steps auto, each frame %s; motion and flicker are mean |first| and\n"
              "|second| differences in time of each always-lit pixel's luminance over the mean luminance\n",
              scenePath.c_str(), frames, size, size,
              motion.animate ? ("deformers advancing from t = " + std::to_string(motion.start)).c_str()
                             : "lights orbiting the camera target about +y",
              motion.cold ? "from a fresh renderer (cold)" : "warm-started from the last");
  std::printf("%5s %9s %10s %10s %9s\n", "grid", motion.animate ? "step t" : "step deg", "motion", "flicker",
              "flick/mo");
  for (int grid : grids)
    for (double step : {baseStep, 2.0 * baseStep}) {
      motion.step = step;
      const TemporalChange c = measure(scene, grid, frames, motion);
      std::printf("%5d %9.4f %10.3e %10.3e %9.3f\n", grid, step, c.motion, c.flicker,
                  c.motion > 0 ? c.flicker / c.motion : 0.0);
    }
  return 0;
}
