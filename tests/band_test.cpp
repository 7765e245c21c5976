// Grid-layer bands: the band metric (gridBandAmplitude, volume/image_metrics.h) reads near
// zero on a smooth image and reads the amplitude of bands injected at the grid's cell
// layers; and the CPU renders of a homogeneous box turned against the grid do not band more
// than they did when the metric was introduced (docs/accuracy.md "Grid-layer bands").
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>

#include "bench/band_scenes.h"
#include "volume/cpu_renderer.h"
#include "volume/grid_band_samples.h"
#include "volume/image_metrics.h"

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

}  // namespace
