// How far light spreads along a lit face, SSLPV against the path tracer (issue 4). The
// calibration makes a thick slab's total diffuse reflectance exact (slab_calibration), but
// not where on the face that light comes out: a thick slab lit on a disk only, seen from
// straight above, compared ring by ring. Inside the disk the light that scattered near
// where it entered dominates; beyond its rim only light that diffused there is left, so
// the rings outside measure the lattice's far field against transport's.
//
//   lateral_spread [--grid 100] [--spp 64] [--size 128] [--materials ketchup,skin1,marble]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench/slab_scene.h"
#include "volume/cpu_renderer.h"
#include "volume/material.h"
#include "volume/reference_tracer.h"
#include "volume/scene.h"

namespace {

using namespace sslpv;

constexpr double kHalfWidth = 30.0;   // mm: the slab is 60 x 30 x 60 mm, top face at y = 0
constexpr double kDiskRadius = 8.0;   // mm: the lit disk's radius on the top face
constexpr double kLightHeight = 85.0;
constexpr double kCameraHeight = 200.0;

/// Ring edges in mm from the disk's centre: two inside it, the rim, then the far field.
const double kRings[] = {0.0, 3.0, 6.0, 10.0, 14.0, 18.0, 22.0, 26.0};
constexpr int kRingCount = int(sizeof(kRings) / sizeof(kRings[0])) - 1;
/// A ring whose light is below this share of the centre ring's (per channel) is not compared.
constexpr double kNegligible = 1e-3;

Scene diskScene(const MeasuredMaterial& material, int size) {
  Scene scene = bench::materialBox(material, material.eta, glm::dvec3(-kHalfWidth, -30.0, -kHalfWidth),
                                   glm::dvec3(kHalfWidth, 0.0, kHalfWidth));
  // A spot straight down whose hard-edged cone lights a disk of unit irradiance.
  Light light;
  light.type = Light::Type::Spot;
  light.position = glm::dvec3(0.0, kLightHeight, 0.0);
  light.direction = glm::dvec3(0.0, -1.0, 0.0);
  light.fovDeg = 2.0 * std::atan(kDiskRadius / kLightHeight) * 180.0 / M_PI;
  light.intensity = glm::vec3(float(kLightHeight * kLightHeight));
  scene.lights = {light};
  // Straight down, so a pixel's distance from the disk's centre is its distance on the face.
  scene.camera.position = glm::dvec3(0.0, kCameraHeight, 0.0);
  scene.camera.target = glm::dvec3(0.0);
  scene.camera.up = glm::dvec3(0.0, 0.0, -1.0);
  scene.camera.fovYDeg = 2.0 * std::atan(kHalfWidth / kCameraHeight) * 180.0 / M_PI;
  scene.camera.width = scene.camera.height = size;
  return scene;
}

struct RingSums {
  glm::dvec3 lpv{0.0}, reference{0.0}, variance{0.0};
  int pixels = 0;
};

/// Sums each image over the rings; pixel (x, y) sees the face point under its centre.
std::vector<RingSums> ringSums(const Image& lpv, const ReferenceResult& truth) {
  std::vector<RingSums> rings(kRingCount);
  const int size = lpv.width;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const double u = (2.0 * (x + 0.5) / size - 1.0) * kHalfWidth;
      const double v = (2.0 * (y + 0.5) / size - 1.0) * kHalfWidth;
      const double r = std::sqrt(u * u + v * v);
      const int ring = int(std::upper_bound(std::begin(kRings), std::end(kRings), r) - std::begin(kRings)) - 1;
      if (ring < 0 || ring >= kRingCount) continue;
      RingSums& s = rings[std::size_t(ring)];
      const glm::dvec3 se(truth.standardError.at(x, y));
      s.lpv += glm::dvec3(lpv.at(x, y));
      s.reference += glm::dvec3(truth.radiance.at(x, y));
      s.variance += se * se;
      ++s.pixels;
    }
  return rings;
}

}  // namespace

int main(int argc, char** argv) {
  const bench::Flags flags(argc, argv, {"grid", "spp", "size", "materials"},
                           "lateral_spread [--grid N] [--spp N] [--size N] [--materials a,b]");
  if (!flags.ok()) return 2;
  const int grid = flags.integer("grid", 100), spp = flags.integer("spp", 64), size = flags.integer("size", 128);
  const std::vector<std::string> only = flags.names("materials", {"ketchup", "skin1", "marble"});
  if (grid < 8 || spp < 1 || size < 16) {
    std::fprintf(stderr, "lateral_spread: need --grid >= 8, --spp >= 1, --size >= 16\n");
    return 2;
  }
  std::printf("# slab 60x60x30 mm lit on a disk of radius %.0f mm, Jensen's eta, seen from above;\n", kDiskRadius);
  std::printf("# SSLPV calibrated, grid %d (cell %.2f mm), steps auto; path tracer %d spp, %dx%d pixels.\n", grid,
              2.0 * kHalfWidth / grid, spp, size, size);
  std::printf("# Per ring: SSLPV / path tracer of the ring's mean radiance (R G B), the path tracer's\n");
  std::printf("# ring mean relative to the disk's centre ring (R), and its largest relative standard error.\n");
  std::printf("%-9s %-9s %7s %7s %7s %10s %8s\n", "material", "ring mm", "R", "G", "B", "ref R/ctr", "ref SE");
  for (const MeasuredMaterial& material : measuredMaterials()) {
    if (std::find(only.begin(), only.end(), std::string(material.name)) == only.end()) continue;
    const Scene scene = diskScene(material, size);
    ReferenceOptions options;
    options.spp = spp;
    const ReferenceResult truth = ReferenceTracer(scene).render(options);
    const Image lpv = CpuRenderer(scene).render(bench::calibratedAuto(grid));
    const std::vector<RingSums> rings = ringSums(lpv, truth);
    const glm::dvec3 centre = rings[0].reference / double(std::max(1, rings[0].pixels));
    for (int k = 0; k < kRingCount; ++k) {
      const RingSums& s = rings[std::size_t(k)];
      if (s.pixels == 0) continue;
      const glm::dvec3 mean = s.reference / double(s.pixels);
      char ring[32], cells[3][16];
      std::snprintf(ring, sizeof ring, "%g-%g", kRings[k], kRings[k + 1]);
      double worstSe = 0.0;
      for (int ch = 0; ch < 3; ++ch) {
        // A channel that has died out in this ring (almost single scattering: ketchup's
        // green and blue beyond the rim) says nothing about diffusion; leave it out.
        if (!(mean[ch] > kNegligible * centre[ch])) {
          std::snprintf(cells[ch], sizeof cells[ch], "%7s", "-");
          continue;
        }
        std::snprintf(cells[ch], sizeof cells[ch], "%7.3f", s.lpv[ch] / s.reference[ch]);
        worstSe = std::max(worstSe, std::sqrt(s.variance[ch]) / s.reference[ch]);
      }
      char se[16];
      if (worstSe > 0.0)
        std::snprintf(se, sizeof se, "%7.1f%%", 100.0 * worstSe);
      else
        std::snprintf(se, sizeof se, "%8s", "-");
      std::printf("%-9s %-9s %s %s %s %10.2e %s\n", std::string(material.name).c_str(), ring, cells[0], cells[1],
                  cells[2], mean.x / centre.x, se);
    }
    std::fflush(stdout);
  }
  return 0;
}
