// Injection: the SH written into the grid holds exactly the transmitted flux.
#include <gtest/gtest.h>

#include "lpv_test_grids.h"
#include <algorithm>
#include <cmath>

#include "volume/calibration/lpv_calibration.h"
#include "volume/lpv/sh.h"
#include "volume/cpu/inject.h"

namespace {
using namespace sslpv;
using namespace sslpv::test;

TEST(Injection, InjectedShTotalEqualsTransmittedFlux) {
  MaterialGrid material = uniformMaterial(10, glm::vec3(1.0f), glm::vec3(0.9f), 0.0f);
  ShGrid grid;
  grid.resize(material.frame);
  std::vector<SurfaceFluxSample> samples;
  glm::dvec3 expected(0.0);
  for (int i = 0; i < 50; ++i) {
    // Points on the top face z = 9 of the medium (cells 1..8 are inside), lit from above.
    const glm::vec3 p(1.3f + 0.13f * i, 2.0f + 0.1f * (i % 7), 9.0f);
    const glm::vec3 flux(0.5f + 0.01f * i, 0.2f, 0.05f * (i % 3));
    samples.push_back({p, glm::vec3(0, 0, 1), glm::normalize(glm::vec3(0.1f, 0.0f, -1.0f)), flux});
    expected += glm::dvec3(flux);
  }
  const InjectionStats stats = injectSamples(samples, material, grid);
  for (int ch = 0; ch < 3; ++ch) {
    EXPECT_NEAR(channelPower(grid, ch), expected[ch], 1e-5 * expected[ch] + 1e-9);
    EXPECT_NEAR(stats.injectedFlux[ch], expected[ch], 1e-9 + 1e-6 * expected[ch]);
    EXPECT_EQ(stats.droppedFlux[ch], 0.0);
  }
}

TEST(Injection, LobePointsAlongTheRefractedDirection) {
  MaterialGrid material = uniformMaterial(8, glm::vec3(1.0f), glm::vec3(0.9f), 0.0f);
  ShGrid grid;
  grid.resize(material.frame);
  const glm::vec3 dir = glm::normalize(glm::vec3(0.3f, -0.2f, -1.0f));
  injectSamples({{glm::vec3(4.0f, 4.0f, 7.0f), glm::vec3(0, 0, 1), dir, glm::vec3(1.0f)}}, material, grid);
  glm::dvec4 total(0.0);
  for (std::size_t i = 0; i < material.frame.cellCount(); ++i)
    total += glm::dvec4(grid.plane(0, 0)[i], grid.plane(0, 1)[i], grid.plane(0, 2)[i], grid.plane(0, 3)[i]);
  const sh::Coeffs expected = sh::cosineLobe(dir, 1.0f / sh::kPi);
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(total[k], expected[k], 1e-6);
}

/// Power-weighted mean z of channel `ch`'s c0 over the grid, in cell units (centres at
/// half-integers), and the largest |linear coefficient| seen.
glm::dvec2 meanDepthAndLargestLinear(const ShGrid& grid, int ch) {
  const GridFrame& f = grid.frame;
  double sum = 0.0, weighted = 0.0, linear = 0.0;
  for (int z = 0; z < f.dims.z; ++z)
    for (int y = 0; y < f.dims.y; ++y)
      for (int x = 0; x < f.dims.x; ++x) {
        const std::size_t i = f.index(x, y, z);
        sum += grid.plane(ch, 0)[i];
        weighted += grid.plane(ch, 0)[i] * (z + 0.5);
        for (int k = 1; k < 4; ++k) linear = std::max(linear, double(std::abs(grid.plane(ch, k)[i])));
      }
  return {weighted / sum, linear};
}

TEST(Injection, CalibratedSchemeInjectsIsotropicSourcesWhereLightScattersTheSecondTime) {
  // σt' per channel 0.25, 0.5, 2 per cell: 1/σt' = 4, 2 and 0.5 cells, and light scatters
  // the second time k = secondScatteringDepth(1.3) ≈ 1.22 times that deep (the last is
  // near the Δx / 2 floor). Light entering along the normal is centred that deep below
  // the top face (z = 15), isotropic, with its power times the entry coupling (the square
  // root of the medium's calibrated gain); entering at 60° to the normal it starts half as
  // deep (the floor stays), its power also times the oblique-entry gain.
  MaterialGrid material =
      uniformMaterial(16, glm::vec3(0.25f, 0.5f, 2.0f), glm::vec3(0.2f, 0.45f, 1.9f), 0.0f);
  const StepFactors factors = computeStepFactors(material, LpvScheme::Calibrated, 1.3);
  for (double cosTheta : {1.0, 0.5}) {
    ShGrid grid;
    grid.resize(material.frame);
    const glm::vec3 dir(float(std::sqrt(1.0 - cosTheta * cosTheta)), 0.0f, -float(cosTheta));
    const InjectionStats stats = injectSamples(
        {{glm::vec3(8.0f, 8.0f, 15.0f), glm::vec3(0, 0, 1), dir, glm::vec3(1.0f, 2.0f, 3.0f)}}, material, grid,
        &factors);
    const double k = secondScatteringDepth(1.3);
    const double expectedDepth[3] = {4.0 * k * cosTheta, 2.0 * k * cosTheta, std::max(0.5, 0.5 * k * cosTheta)};
    // A uniform medium: every cell holds the same gain nodes.
    const std::size_t anyCell = material.frame.index(8, 8, 8);
    ASSERT_TRUE(factors.active[anyCell]);
    for (int ch = 0; ch < 3; ++ch) {
      const glm::dvec2 depthAndLinear = meanDepthAndLargestLinear(grid, ch);
      EXPECT_NEAR(15.0 - depthAndLinear.x, expectedDepth[ch], 1e-5) << "channel " << ch << " cos " << cosTheta;
      EXPECT_EQ(depthAndLinear.y, 0.0);
      const double gain = obliqueEntryGain(&factors.obliqueGain[ch][anyCell * kObliqueIntervals],
                                           incidentCosineSquared(cosTheta, 1.3));
      if (cosTheta < 1.0) {
        EXPECT_GT(std::abs(gain - 1.0), 0.005) << "channel " << ch;  // so the power check is not vacuous
      }
      const double coupling = factors.entryCoupling[ch][anyCell];
      EXPECT_NEAR(coupling * coupling,
                  calibratedTransport(material.sigmaT[anyCell][ch], material.sigmaS[anyCell][ch], 0.0, 1.0, 1.3).exitGain,
                  1e-6);
      EXPECT_NEAR(channelPower(grid, ch), (ch + 1.0) * gain * coupling, 1e-5 * (ch + 1.0));
    }
    EXPECT_EQ(stats.injectedFlux, glm::dvec3(1.0, 2.0, 3.0));
  }
}

TEST(Injection, CalibratedSourceDeeperThanTheObjectStaysWhereItEntered) {
  // A 2-cell-thick medium (z in [1, 3]) with 1/σt' = 20 cells: no active cell that deep,
  // nor a cell deeper, so the light stays in the cells the sample entered through.
  MaterialGrid material = uniformMaterial(8, glm::vec3(0.05f), glm::vec3(0.04f), 0.0f);
  for (int z = 3; z < 8; ++z)
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x) material.coverage[material.frame.index(x, y, z)] = 0.0f;
  const StepFactors factors = computeStepFactors(material, LpvScheme::Calibrated, 1.0);
  ShGrid grid;
  grid.resize(material.frame);
  injectSamples({{glm::vec3(4.0f, 4.0f, 3.0f), glm::vec3(0, 0, 1), glm::vec3(0, 0, -1), glm::vec3(1.0f)}}, material,
                grid, &factors);
  EXPECT_NEAR(meanDepthAndLargestLinear(grid, 0).x, 2.5, 1e-6) << "the top layer (centre z = 2.5)";
  EXPECT_NEAR(channelPower(grid, 0), factors.entryCoupling[0][material.frame.index(4, 4, 2)], 1e-6);
}

TEST(Injection, OnlyCellsInsideTheMediumReceiveLight) {
  MaterialGrid material = uniformMaterial(8, glm::vec3(1.0f), glm::vec3(0.9f), 0.0f);
  ShGrid grid;
  grid.resize(material.frame);
  // Half a cell inside the top face: trilinear weights straddle the outside ring.
  injectSamples({{glm::vec3(1.1f, 6.9f, 7.0f), glm::vec3(0, 0, 1), glm::vec3(0, 0, -1), glm::vec3(1.0f)}},
                material, grid);
  const GridFrame& f = material.frame;
  for (int z = 0; z < 8; ++z)
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x) {
        const bool ring = x == 0 || y == 0 || z == 0 || x == 7 || y == 7 || z == 7;
        if (ring) {
          EXPECT_EQ(grid.plane(0, 0)[f.index(x, y, z)], 0.0f);
        }
      }
  EXPECT_NEAR(channelPower(grid, 0), 1.0, 1e-6);
}

TEST(Injection, SamplesFarFromTheMediumAreReportedAsDropped) {
  MaterialGrid material = uniformMaterial(8, glm::vec3(1.0f), glm::vec3(0.9f), 0.0f);
  ShGrid grid;
  grid.resize(material.frame);
  const InjectionStats stats = injectSamples(
      {{glm::vec3(40.0f, 0.0f, 0.0f), glm::vec3(1, 0, 0), glm::vec3(-1, 0, 0), glm::vec3(2.0f)}}, material, grid);
  EXPECT_EQ(stats.droppedFlux.x, 2.0);
  EXPECT_EQ(channelPower(grid, 0), 0.0);
}

}  // namespace
