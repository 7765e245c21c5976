// Grid-layer bands: the band metric (gridBandAmplitude, volume/eval/image_metrics.h) reads near
// zero on a smooth image and reads the amplitude of bands injected at the grid's cell
// layers; and the CPU renders of a homogeneous box turned against the grid and of a tilted
// layered slab do not band more than they did when the metric was introduced
// (docs/accuracy.md "Grid-layer bands").
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <optional>
#include <utility>
#include <openvdb/openvdb.h>

#include "bench/band_scenes.h"
#include "volume/cpu/cpu_renderer.h"
#include "volume/eval/grid_band_samples.h"
#include "volume/eval/image_metrics.h"
#include "volume/material/material_set.h"

namespace {
using namespace sslpv;

const MeasuredMaterial& skin() { return *findMeasuredMaterial("skin1"); }

/// An image that is `value` at every sample and black elsewhere.
Image paint(const Scene& scene, const std::vector<GridBandSample>& samples,
            const std::function<double(const GridBandSample&)>& value) {
  Image image(scene.camera.width, scene.camera.height);
  for (const GridBandSample& s : samples) image.pixels[s.pixel] = glm::vec3(float(value(s)));
  return image;
}

/// Smooth lighting over the box: falling off with distance from the light and with the
/// angle to it, as a lit face does, with no trace of the grid.
double smoothLight(const GridBandSample& s) {
  const glm::dvec3 light(-25.0, 35.0, 30.0);
  const glm::dvec3 toLight = light - s.position;
  const double distance = glm::length(toLight);
  return (0.2 + std::max(0.0, glm::dot(s.normal, toLight / distance))) * 1e3 / (distance * distance);
}

/// Depth, in cells, below the cell face the outward normal points through along axis a.
double inwardPhase(const GridBandSample& s, int a) {
  const double within = s.grid[a] - std::floor(s.grid[a]);
  return s.normal[a] > 0.0 ? 1.0 - within : within;
}

TEST(GridBandAmplitude, ReadsSmoothLightAsFlatAndInjectedBandsAtTheirAmplitude) {
  const Scene scene = bench::bandBox(skin(), 12.0, 8.0, 128);
  const std::vector<GridBandSample> samples = gridBandSamples(scene, 32);
  ASSERT_GT(samples.size(), 5000u);

  const GridBandAmplitude smooth = gridBandAmplitude(paint(scene, samples, smoothLight), samples);
  std::printf("smooth: %.3f %% (x %.3f, y %.3f, z %.3f) over %zu pixels\n", 100 * smooth.amplitude,
              100 * smooth.axis.x, 100 * smooth.axis.y, 100 * smooth.axis.z, smooth.pixels);
  EXPECT_GT(smooth.pixels, 4000u);
  // The renders band by 0.4-2.5 % (docs/accuracy.md); a smooth image must read well under that.
  EXPECT_LT(smooth.amplitude, 0.002);

  // A cosine of amplitude 5 % locked to the z layers' phase has an RMS of 5 %/√2; binning
  // it into eighths of its period averages each bin over its width, sin(π/8)/(π/8).
  const double a = 0.05;
  const GridBandAmplitude locked = gridBandAmplitude(paint(scene, samples,
                                                           [&](const GridBandSample& s) {
                                                             return smoothLight(s) *
                                                                    (1.0 + a * std::cos(2.0 * M_PI * inwardPhase(s, 2)));
                                                           }),
                                                     samples);
  const double expected = a / std::sqrt(2.0) * std::sin(M_PI / 8.0) / (M_PI / 8.0);
  std::printf("phase-locked z: %.3f %% (expected %.3f %%); x %.3f, y %.3f\n", 100 * locked.axis.z, 100 * expected,
              100 * locked.axis.x, 100 * locked.axis.y);
  EXPECT_NEAR(locked.axis.z, expected, 0.1 * expected);
  EXPECT_NEAR(locked.amplitude, locked.axis.z, 1e-12);

  // Every other z layer 3 % brighter, the others 3 % darker: an RMS of 3 % along z.
  const double b = 0.03;
  const GridBandAmplitude alternating =
      gridBandAmplitude(paint(scene, samples,
                              [&](const GridBandSample& s) {
                                const bool odd = int(std::floor(s.grid.z)) % 2 != 0;
                                return smoothLight(s) * (1.0 + (odd ? b : -b));
                              }),
                        samples);
  std::printf("alternating z layers: %.3f %% (expected %.3f %%)\n", 100 * alternating.axis.z, 100 * b);
  EXPECT_NEAR(alternating.axis.z, b, 0.1 * b);
}

TEST(GridBandAmplitude, RejectsSamplesOutsideTheImage) {
  std::vector<GridBandSample> samples(1);
  samples[0].pixel = 16;
  EXPECT_THROW(gridBandAmplitude(Image(4, 4), samples), std::invalid_argument);
  Image se(3, 3);
  EXPECT_THROW(gridBandAmplitude(Image(4, 4), {}, &se), std::invalid_argument);
}

/// The band amplitude of a calibrated CPU render (--steps auto) of the 10 mm skin box.
double renderedBands(double yawDeg, double tiltDeg, int grid) {
  const Scene scene = bench::bandBox(skin(), yawDeg, tiltDeg, 128);
  CpuRenderer renderer(scene);
  const GridBandAmplitude bands = gridBandAmplitude(renderer.render(bench::calibratedAuto(grid)),
                                                    gridBandSamples(scene, grid));
  std::printf("skin box yaw %g tilt %g, %d^3: bands %.2f %% (x %.2f, y %.2f, z %.2f)\n", yawDeg, tiltDeg, grid,
              100 * bands.amplitude, 100 * bands.axis.x, 100 * bands.axis.y, 100 * bands.axis.z);
  return bands.amplitude;
}

TEST(GridBands, ATurnedBoxBandsNoMoreThanWhenMeasured) {
  // Measured 2026-12-04 (bench/band_metric, the same scenes, 128²): yaw 12° 1.74 % at 32³
  // and 1.29 % at 64³, yaw 7° 1.39 % at 64³. The 128-spp path-traced references of the
  // same scenes, binned by the same grids' phases, read 0.65-0.72 % (their noise alone
  // predicts 0.43-0.48 %, the rest is what the smooth fit leaves of real shading): the
  // metric's floor, so these bands are real, 2-2.7x the floor. (Yaw 7° at 32³, 2.53 %, is
  // left out: there the stripes cross a face only ~3 times and the reference already
  // reads 1.56 %.) The margin, ×1.15, lets a change elsewhere in the scheme move the
  // bands a little and fails on one that brings back clearly stronger bands.
  EXPECT_LT(renderedBands(12.0, 0.0, 32), 1.15 * 0.0174);
  EXPECT_LT(renderedBands(12.0, 0.0, 64), 1.15 * 0.0129);
  EXPECT_LT(renderedBands(7.0, 0.0, 64), 1.15 * 0.0139);
}

/// A medium as σs' and σa per mm (g = 0): σs = σs', σt = σs' + σa.
struct Medium {
  glm::vec3 sigmaSPrime, sigmaA;
};

/// The heterogeneous suite's layers3_tilted (bench/hetero_scenes.cpp), made in memory: a
/// 14 x 14 x 4 mm slab of a clear core under a 0.6 mm absorbing skin-like layer and over
/// a 1.2 mm absorbing base, turned (-23°, 11°, 7°) against the grid, 128².
std::pair<Scene, std::shared_ptr<MaterialSet>> tiltedLayers() {
  const Medium skinLike{{1.1f, 0.95f, 0.8f}, {0.09f, 0.40f, 1.10f}};
  const Medium clearCore{{1.55f, 1.60f, 1.70f}, {0.008f, 0.012f, 0.020f}};
  const Medium darkBase{{2.5f, 2.2f, 2.0f}, {0.6f, 1.4f, 2.2f}};
  Scene scene = bench::materialBox(skin(), 1.4, glm::dvec3(-7.0, -7.0, -2.0), glm::dvec3(7.0, 7.0, 2.0));
  scene.material.base.sigmaT = clearCore.sigmaSPrime + clearCore.sigmaA;
  scene.material.base.sigmaS = clearCore.sigmaSPrime;
  scene.transform.rotateDeg = glm::dvec3(-23.0, 11.0, 7.0);
  Light light;
  light.type = Light::Type::Point;
  light.position = glm::dvec3(-25.0, 30.0, 25.0);
  light.intensity = glm::vec3(14000.0f, 13500.0f, 13000.0f);
  scene.lights = {light};
  scene.camera.position = glm::dvec3(6.0, 16.0, 30.0);
  scene.camera.target = glm::dvec3(0.0);
  scene.camera.fovYDeg = 35.0;
  scene.camera.width = scene.camera.height = 128;

  initializeOpenVdb();
  auto set = std::make_shared<MaterialSet>();
  constexpr float kVoxel = 0.1f;
  auto transform = openvdb::math::Transform::createLinearTransform(kVoxel);
  set->sigmaT = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  set->sigmaS = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  set->sigmaT->setTransform(transform);
  set->sigmaS->setTransform(transform->copy());
  auto t = set->sigmaT->getAccessor();
  auto s = set->sigmaS->getAccessor();
  for (int k = -21; k <= 21; ++k) {
    const float z = float(k) * kVoxel;
    if (z <= 1.4f && z >= -0.8f) continue;  // the core: the base material
    const Medium& m = z > 1.4f ? skinLike : darkBase;
    const glm::vec3 st = m.sigmaSPrime + m.sigmaA;
    for (int j = -71; j <= 71; ++j)
      for (int i = -71; i <= 71; ++i) {
        t.setValue(openvdb::Coord(i, j, k), openvdb::Vec3s(st.x, st.y, st.z));
        s.setValue(openvdb::Coord(i, j, k), openvdb::Vec3s(m.sigmaSPrime.x, m.sigmaSPrime.y, m.sigmaSPrime.z));
      }
  }
  return {scene, set};
}

TEST(GridBands, ATiltedLayeredSlabBandsNoMoreThanWhenMeasured) {
  // The worst bands measured (2026-12-04): the 0.6 mm top layer is about one cell thick at
  // 32³, and box-filtered into cells that the tilted face crosses at every phase it gives
  // each boundary cell another mixture: 7.34 % (visible diagonal stripes), against 0.55 %
  // for the suite's 64-spp reference of the same scene (bench/band_metric --builtin 0
  // --scenes build/hetero/layers3_tilted.json with the suite's cached reference). 64³:
  // 1.00 % against 0.47 %. Same margin as above.
  auto [scene, set] = tiltedLayers();
  for (int grid : {32, 64}) {
    CpuRenderer renderer(scene);
    renderer.setMaterialSet(set, std::nullopt);
    const GridBandAmplitude bands =
        gridBandAmplitude(renderer.render(bench::calibratedAuto(grid)), gridBandSamples(scene, grid));
    std::printf("tilted layers, %d^3: bands %.2f %% (x %.2f, y %.2f, z %.2f)\n", grid, 100 * bands.amplitude,
                100 * bands.axis.x, 100 * bands.axis.y, 100 * bands.axis.z);
    EXPECT_GT(bands.pixels, 4000u);
    EXPECT_LT(bands.amplitude, 1.15 * (grid == 32 ? 0.0734 : 0.0100));
  }
}

}  // namespace
