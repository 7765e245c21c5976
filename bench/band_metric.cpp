// Grid-layer bands, measured: the band amplitude of volume/eval/image_metrics.h
// (gridBandAmplitude) on SSLPV renders of a homogeneous box turned by small angles
// against the grid, a sphere, and any scene files given, at each grid, with the render's
// time; and on a path-traced reference of each scene (no grid), which gives the metric's
// floor: its noise (also predicted from the tracer's standard error) and what the smooth
// fit leaves of real shading. Prints a table; not a test.
//
//   band_metric [--grid 32,64] [--material skin1] [--size 128] [--spp 32] [--scenes a.json,b.json]
//               [--cache DIR] [--builtin 0]
//
// --spp 0 skips the references; --cache keeps them (NAME-SIZE-sppN.exr and its
// .stderr.exr, seed 0) and reuses them (an image without its .stderr.exr too: then the
// noise column is unknown, "-"). --builtin 0 measures only the --scenes files. Renders: CPU backend, calibrated, --steps auto, a cold
// first frame (a new renderer per row).
#include <chrono>
#include <filesystem>
#include <cstdio>
#include <string>
#include <vector>

#include "bench/band_scenes.h"
#include "volume/cpu/cpu_renderer.h"
#include "volume/eval/grid_band_samples.h"
#include "volume/core/image_io.h"
#include "volume/eval/image_metrics.h"
#include "volume/reference/reference_tracer.h"

namespace {
using namespace sslpv;

struct Named {
  std::string name;
  Scene scene;
};

void printRow(const std::string& name, const char* kind, int grid, double ms, const GridBandAmplitude& a,
              bool withNoise) {
  std::printf("%-22s %-9s %5d %9.0f %7.2f %7.2f %7.2f %8.2f", name.c_str(), kind, grid, ms, 100 * a.axis.x,
              100 * a.axis.y, 100 * a.axis.z, 100 * a.amplitude);
  if (withNoise)
    std::printf(" %8.2f", 100 * std::max({a.noise.x, a.noise.y, a.noise.z}));
  else
    std::printf(" %8s", "-");
  std::printf(" %7zu\n", a.pixels);
  std::fflush(stdout);
}

/// The scene's path-traced image, from `cache` when it holds one of this size and spp
/// (the scene's name says what it is: a changed scene needs a fresh cache).
ReferenceResult reference(const Named& named, int spp, int size, const std::string& cache) {
  const std::filesystem::path file =
      cache.empty() ? std::filesystem::path() : std::filesystem::path(cache) / (named.name + "-" + std::to_string(size) + "-spp" + std::to_string(spp) + ".exr");
  std::filesystem::path errors = file;
  errors.replace_extension(".stderr.exr");
  ReferenceResult truth;
  if (!cache.empty() && std::filesystem::exists(file)) {
    truth.radiance = readImage(file);
    if (std::filesystem::exists(errors)) truth.standardError = readImage(errors);
    return truth;
  }
  ReferenceOptions options;
  options.spp = spp;
  truth = ReferenceTracer(named.scene).render(options);
  if (!cache.empty()) {
    std::filesystem::create_directories(cache);
    writeImage(truth.radiance, file);
    writeImage(truth.standardError, errors);
  }
  return truth;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace sslpv::bench;
  const char* usage =
      "band_metric [--grid 32,64] [--material skin1] [--size 128] [--spp 32] [--scenes a.json,b.json] [--cache DIR] "
      "[--builtin 0]";
  const Flags flags(argc, argv, {"grid", "material", "size", "spp", "scenes", "cache", "builtin"}, usage);
  if (!flags.ok()) return 2;
  const MeasuredMaterial* material = findMeasuredMaterial(flags.text("material", "skin1"));
  if (material == nullptr) {
    std::fprintf(stderr, "band_metric: unknown material '%s'\n", flags.text("material", "skin1").c_str());
    return 2;
  }
  std::vector<int> grids;
  for (const std::string& g : flags.names("grid", {"32", "64"})) grids.push_back(std::atoi(g.c_str()));
  const int size = flags.integer("size", 128), spp = flags.integer("spp", 32);
  if (size < 32 || spp < 0 || grids.empty()) {
    std::fprintf(stderr, "band_metric: need --size >= 32, --spp >= 0 and a grid\n");
    return 2;
  }
  std::vector<Named> scenes;
  const std::string m(material->name);
  if (flags.integer("builtin", 1) != 0) {
  for (double yaw : {0.0, 7.0, 12.0, 20.0}) scenes.push_back({m + "_box_yaw" + std::to_string(int(yaw)), bandBox(*material, yaw, 0.0, size)});
  scenes.push_back({m + "_box_yaw12_tilt8", bandBox(*material, 12.0, 8.0, size)});
  scenes.push_back({m + "_sphere", bandSphere(*material, size)});
  }
  try {
    for (const std::string& file : flags.names("scenes", {})) {
      Scene scene = loadScene(file);
      scene.camera.width = scene.camera.height = size;
      const std::size_t slash = file.find_last_of('/');
      scenes.push_back({file.substr(slash == std::string::npos ? 0 : slash + 1), scene});
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "band_metric: %s\n", e.what());
    return 2;
  }
  std::printf("band_metric: %dx%d, CPU, calibrated, --steps auto; band amplitude = RMS of the phase-locked\n"
              "relative luminance pattern along each grid axis (%%), max over axes; reference rows: %d spp path\n"
              "tracer binned by the same grid's phases, 'noise' = what its standard error alone predicts\n",
              size, size, spp);
  std::printf("%-22s %-9s %5s %9s %7s %7s %7s %8s %8s %7s\n", "scene", "image", "grid", "ms", "x %", "y %", "z %",
              "band %", "noise %", "pixels");
  for (const Named& named : scenes) {
    ReferenceResult truth;
    if (spp > 0) truth = reference(named, spp, size, flags.text("cache", ""));
    for (int grid : grids) {
      const std::vector<GridBandSample> samples = gridBandSamples(named.scene, grid);
      CpuRenderer renderer(named.scene);
      const auto start = std::chrono::steady_clock::now();
      const Image lpv = renderer.render(calibratedAuto(grid));
      const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
      printRow(named.name, "sslpv", grid, ms, gridBandAmplitude(lpv, samples), false);
      if (spp > 0) {
        const bool withNoise = truth.standardError.width == truth.radiance.width;
        printRow(named.name, "reference", grid, 1000.0 * truth.seconds,
                 gridBandAmplitude(truth.radiance, samples, withNoise ? &truth.standardError : nullptr), withNoise);
      }
    }
  }
  return 0;
}
