// Injection: the SH written into the grid holds exactly the transmitted flux.
#include <gtest/gtest.h>

#include "lpv_test_grids.h"
#include "volume/sh.h"

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
