// How far light spreads along a lit face, SSLPV against the path tracer (docs/design.md §6.7.9). The
// calibration makes a thick slab's total diffuse reflectance exact (slab_calibration), but
// not where on the face that light comes out: a thick slab lit on a disk only, seen from
// straight above, compared ring by ring. Inside the disk the light that scattered near
// where it entered dominates; beyond its rim only light that diffused there is left, so
// the rings outside measure the lattice's far field against transport's.
//
//   lateral_spread [--grid 100] [--spp 64] [--size 128] [--materials ketchup,skin1,marble]
#include <cmath>
#include <cstdio>
#include <vector>

#include "bench/band_profile.h"
#include "volume/scene/material.h"
#include "volume/scene/scene.h"

namespace {

using namespace sslpv;

constexpr double kHalfWidth = 30.0;   // mm: the slab is 60 x 30 x 60 mm, top face at y = 0
constexpr double kDiskRadius = 8.0;   // mm: the lit disk's radius on the top face
constexpr double kLightHeight = 85.0;
constexpr double kCameraHeight = 200.0;

/// Ring edges in mm from the disk's centre: two inside it, the rim, then the far field.
const std::vector<double> kRings = {0.0, 3.0, 6.0, 10.0, 14.0, 18.0, 22.0, 26.0};
/// A ring whose light is below this share of the centre ring's (per channel) is not
/// compared: almost single scattering, ketchup's green and blue beyond the rim say nothing
/// about diffusion.
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

/// Pixel (x, y) sees the face point under its centre; its ring, -1 beyond the last.
int ringAt(int x, int y, int size) {
  const double u = (2.0 * (x + 0.5) / size - 1.0) * kHalfWidth;
  const double v = (2.0 * (y + 0.5) / size - 1.0) * kHalfWidth;
  return bench::bandOf(kRings, std::sqrt(u * u + v * v));
}

}  // namespace

int main(int argc, char** argv) {
  bench::BandRun run;
  if (!bench::parseBandRun(argc, argv, "lateral_spread", run)) return 2;
  std::printf("# slab 60x60x30 mm lit on a disk of radius %.0f mm, Jensen's eta, seen from above;\n", kDiskRadius);
  std::printf("# SSLPV calibrated, grid %d (cell %.2f mm), steps auto; path tracer %d spp, %dx%d pixels.\n", run.grid,
              2.0 * kHalfWidth / run.grid, run.spp, run.size, run.size);
  std::printf("# Per ring: SSLPV / path tracer of the ring's mean radiance (R G B), the path tracer's\n");
  std::printf("# ring mean relative to the disk's centre ring (R), and its largest relative standard error.\n");
  std::printf("%-9s %-9s %7s %7s %7s %10s %8s\n", "material", "ring mm", "R", "G", "B", "ref R/ctr", "ref SE");
  for (const MeasuredMaterial& material : run.materials)
    bench::compareBands(diskScene(material, run.size), material.name, run, kRings, kNegligible,
                        [&run](int x, int y) { return ringAt(x, y, run.size); });
  return 0;
}
