// How much light comes round an edge, SSLPV against the path tracer (docs/design.md §6.7.9). A box lit
// from straight above only, seen square-on through one of its side faces, which no light
// reaches directly: everything that face shows entered the top and turned the edge. The
// face is compared band by band below the edge. It is the shipped ketchup_box's largest
// error (its front face, lit mostly through the top, held 83-90 % of the image's error)
// without the box's rotation, so the grid's staircase is not in it.
//
//   edge_crossing [--grid 100] [--spp 64] [--size 128] [--materials ketchup,skin1,marble]
#include <cmath>
#include <cstdio>
#include <vector>

#include "bench/band_profile.h"
#include "volume/scene/material.h"
#include "volume/scene/scene.h"

namespace {

using namespace sslpv;

// The box is 60 x 30 x 30 mm, top face at y = 0, the viewed side face at z = 0; the view
// covers x and depth in [-kView, kView] and [0, 2 kView], away from the other edges.
constexpr double kHalfWidth = 30.0, kHeight = 30.0, kView = 12.0;
constexpr double kCameraDistance = 250.0;

/// Band edges, mm below the lit edge.
const std::vector<double> kBands = {0.0, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0, 10.0, 14.0, 18.0, 24.0};
/// A band whose light is below this share of the first band's (per channel) is not
/// compared: a channel that has died out that far below the edge says nothing.
constexpr double kNegligible = 1e-3;

Scene edgeScene(const MeasuredMaterial& material, int size) {
  Scene scene = bench::materialBox(material, material.eta, glm::dvec3(-kHalfWidth, -kHeight, -kHeight),
                                   glm::dvec3(kHalfWidth, 0.0, 0.0));
  Light light;
  light.type = Light::Type::Directional;
  light.direction = glm::dvec3(0.0, -1.0, 0.0);
  light.irradiance = glm::vec3(1.0f);
  scene.lights = {light};
  // Square-on, so a pixel row is a depth below the edge.
  scene.camera.position = glm::dvec3(0.0, -kView, kCameraDistance);
  scene.camera.target = glm::dvec3(0.0, -kView, 0.0);
  scene.camera.up = glm::dvec3(0.0, 1.0, 0.0);
  scene.camera.fovYDeg = 2.0 * std::atan(kView / kCameraDistance) * 180.0 / M_PI;
  scene.camera.width = scene.camera.height = size;
  return scene;
}

}  // namespace

int main(int argc, char** argv) {
  bench::BandRun run;
  if (!bench::parseBandRun(argc, argv, "edge_crossing", run)) return 2;
  std::printf("# box 60x30x30 mm lit from straight above only, Jensen's eta; a side face seen square-on.\n");
  std::printf("# SSLPV calibrated, grid %d (cell %.2f mm), steps auto; path tracer %d spp, %dx%d pixels.\n", run.grid,
              2.0 * kHalfWidth / run.grid, run.spp, run.size, run.size);
  std::printf("# Per band below the lit edge: SSLPV / path tracer of the band's mean radiance (R G B),\n");
  std::printf("# the path tracer's band mean relative to the first band's (R), its largest relative SE.\n");
  std::printf("%-9s %-9s %7s %7s %7s %10s %8s\n", "material", "depth mm", "R", "G", "B", "ref R/1st", "ref SE");
  // Pixel row y sees the face (y + 1/2) / size · 2 kView below the edge.
  for (const MeasuredMaterial& material : run.materials)
    bench::compareBands(edgeScene(material, run.size), material.name, run, kBands, kNegligible,
                        [&run](int, int y) { return bench::bandOf(kBands, (y + 0.5) / run.size * 2.0 * kView); });
  return 0;
}
