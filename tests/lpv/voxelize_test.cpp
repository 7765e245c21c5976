#include "volume/lpv/voxelize.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "seeded_draws.h"
#include "test_meshes.h"

namespace sslpv {
namespace {

using test::drawVec3;
using test::enclosedVolume;
using test::makeBoxMesh;
using test::makeIcosphere;

constexpr double kPi = 3.14159265358979323846;

GridFrame unitCellFrame(int n) {
  GridFrame frame;
  frame.origin = glm::dvec3(0.0);
  frame.cellSize = 1.0;
  frame.dims = glm::ivec3(n);
  return frame;
}

double totalCoverage(const std::vector<float>& coverage) {
  return std::accumulate(coverage.begin(), coverage.end(), 0.0);
}

/// Fraction of the unit cube [-0.5,0.5]^3 with n.u < -d, by a dense midpoint lattice.
double latticeCubeFraction(double d, const glm::dvec3& n, int samples) {
  long inside = 0;
  for (int i = 0; i < samples; ++i)
    for (int j = 0; j < samples; ++j)
      for (int k = 0; k < samples; ++k) {
        const glm::dvec3 u = (glm::dvec3(i, j, k) + 0.5) / double(samples) - 0.5;
        if (glm::dot(n, u) < -d) ++inside;
      }
  return double(inside) / (double(samples) * samples * samples);
}

TEST(PlaneCubeCoverage, AxisAlignedNormalIsTheLinearRamp) {
  for (double d = -1.0; d <= 1.0; d += 0.05)
    for (const glm::dvec3& n : {glm::dvec3(1, 0, 0), glm::dvec3(0, -1, 0), glm::dvec3(0, 0, 1)})
      EXPECT_NEAR(planeCubeCoverage(d, n), std::clamp(0.5 - d, 0.0, 1.0), 2e-3) << "d=" << d;
}

TEST(PlaneCubeCoverage, MatchesLatticeCountForObliquePlanes) {
  std::mt19937 rng(7);
  std::normal_distribution<double> gauss;
  std::uniform_real_distribution<double> offset(-0.9, 0.9);
  for (int trial = 0; trial < 40; ++trial) {
    const glm::dvec3 n = glm::normalize(drawVec3<glm::dvec3>(gauss, rng));
    const double d = offset(rng);
    // 100^3 lattice points: counting error well below 1e-2 for any plane.
    EXPECT_NEAR(planeCubeCoverage(d, n), latticeCubeFraction(d, n, 100), 1e-2)
        << "n=(" << n.x << "," << n.y << "," << n.z << ") d=" << d;
  }
}

TEST(PlaneCubeCoverage, DiagonalPlaneKnownValues) {
  const glm::dvec3 diagonal = glm::normalize(glm::dvec3(1.0));
  EXPECT_NEAR(planeCubeCoverage(0.0, diagonal), 0.5, 1e-9);  // plane through the centre
  // The corner tetrahedron cut off at distance sqrt(3)/2 - 1/sqrt(3) from the centre has
  // legs of length 1: volume 1/6.
  EXPECT_NEAR(planeCubeCoverage(std::sqrt(3.0) / 2.0 - 1.0 / std::sqrt(3.0), diagonal), 1.0 / 6.0, 1e-6);
  EXPECT_EQ(planeCubeCoverage(0.87, diagonal), 0.0);  // beyond half the diagonal
  EXPECT_EQ(planeCubeCoverage(-0.87, diagonal), 1.0);
}

TEST(Voxelize, AxisAlignedBoxFacesCutCellsAtKnownFractions) {
  const GridFrame frame = unitCellFrame(16);
  // Each face sits at a known position inside its cell: x faces leave 0.25 and 0.5 of the
  // cell inside, y faces 0.75 and 0.75, z faces 0.5 and 0.25.
  const glm::vec3 lo(4.75f, 3.25f, 2.5f), hi(11.5f, 12.75f, 10.25f);
  const std::vector<float> coverage = voxelizeCoverage(makeBoxMesh(lo, hi), frame);
  ASSERT_EQ(coverage.size(), frame.cellCount());
  auto at = [&](int x, int y, int z) { return coverage[frame.index(x, y, z)]; };
  const float tol = 1e-3f;
  // Face cells away from edges (y, z well inside for x faces, and so on).
  for (int a = 6; a <= 9; ++a)
    for (int b = 5; b <= 8; ++b) {
      EXPECT_NEAR(at(4, a, b), 0.25f, tol);
      EXPECT_NEAR(at(11, a, b), 0.5f, tol);
      EXPECT_NEAR(at(a, 3, b), 0.75f, tol);
      EXPECT_NEAR(at(a, 12, b), 0.75f, tol);
      EXPECT_NEAR(at(a, b, 2), 0.5f, tol);
      EXPECT_NEAR(at(a, b, 10), 0.25f, tol);
      EXPECT_EQ(at(3, a, b), 0.0f);   // wholly outside
      EXPECT_EQ(at(13, a, b), 0.0f);
      EXPECT_EQ(at(a, b + 1, 6), 1.0f);  // wholly inside
    }
  const glm::dvec3 size = glm::dvec3(hi - lo);
  const double volume = size.x * size.y * size.z;
  // Only cells along the 12 edges are approximated (the distance field is not planar
  // there): at most a quarter cell of error per cell of edge length.
  const double edgeLength = 4.0 * (size.x + size.y + size.z);
  EXPECT_NEAR(totalCoverage(coverage), volume, 0.25 * edgeLength);
  for (float c : coverage) ASSERT_TRUE(c >= 0.0f && c <= 1.0f);
}

TEST(Voxelize, SphereTotalCoverageMatchesVolumeAt64CellsAcross) {
  const double radius = 1.0;
  GridFrame frame;
  frame.cellSize = 2.0 * radius / 64.0;
  frame.dims = glm::ivec3(72);
  frame.origin = glm::dvec3(-36.0 * frame.cellSize) + 0.3 * frame.cellSize;  // off-grid centre
  const TriangleMesh sphere = makeIcosphere(glm::vec3(0.0f), float(radius), 5);
  const std::vector<float> coverage = voxelizeCoverage(sphere, frame);
  const double cellVolume = std::pow(frame.cellSize, 3);
  const double voxelVolume = totalCoverage(coverage) * cellVolume;
  EXPECT_NEAR(voxelVolume, 4.0 / 3.0 * kPi * std::pow(radius, 3), 0.02 * 4.0 / 3.0 * kPi);
  // Against the polyhedron's own volume (no tessellation error) it is much closer.
  EXPECT_NEAR(voxelVolume, enclosedVolume(sphere), 0.003 * enclosedVolume(sphere));
}

TEST(Voxelize, SphereCellsMatchSupersampledCoverage) {
  // Per-cell check at 24 cells across: every boundary cell against 12^3 point samples of
  // the analytic sphere (the tessellation error, ~2e-4 of the radius, is far below a cell).
  const double radius = 1.0;
  GridFrame frame;
  frame.cellSize = 2.0 * radius / 24.0;
  frame.dims = glm::ivec3(28);
  frame.origin = glm::dvec3(-14.0 * frame.cellSize) + 0.17 * frame.cellSize;
  const std::vector<float> coverage =
      voxelizeCoverage(makeIcosphere(glm::vec3(0.0f), float(radius), 6), frame);
  const test::SupersampledSphereError e = test::compareWithSupersampledSphere(coverage, frame, radius);
  ASSERT_GT(e.boundaryCells, 1000);
  // The linear ramp clamp(0.5 - d) would be off by up to ~0.05 on oblique cells; the
  // exact plane-cube fraction leaves only the curvature error, O((h/r)^2) of a cell.
  EXPECT_LT(e.worst, 0.03);
  EXPECT_LT(e.meanBoundary, 0.008);
}

TEST(Voxelize, MeshOutsideFrameGivesAllZeros) {
  const GridFrame frame = unitCellFrame(8);
  const auto coverage = voxelizeCoverage(makeBoxMesh(glm::vec3(20.0f), glm::vec3(24.0f)), frame);
  ASSERT_EQ(coverage.size(), frame.cellCount());
  EXPECT_EQ(totalCoverage(coverage), 0.0);
}

TEST(Voxelize, EmptyMeshGivesAllZeros) {
  const GridFrame frame = unitCellFrame(4);
  const auto coverage = voxelizeCoverage(TriangleMesh{}, frame);
  ASSERT_EQ(coverage.size(), frame.cellCount());
  EXPECT_EQ(totalCoverage(coverage), 0.0);
}

TEST(Voxelize, FrameDeepInsideMeshIsFullyCovered) {
  // The frame lies in the mesh's interior, beyond the narrow band: every cell is inside.
  const GridFrame frame = unitCellFrame(6);
  const auto coverage = voxelizeCoverage(makeBoxMesh(glm::vec3(-20.0f), glm::vec3(26.0f)), frame);
  EXPECT_EQ(totalCoverage(coverage), double(frame.cellCount()));
}

TEST(Voxelize, ThinPlateStaysInRangeAndKeepsItsFootprint) {
  // A plate 0.3 cells thick lies inside one layer of cells; its coverage cannot be exact
  // (the distance field has no interior sample) but must stay in [0,1], be non-zero over
  // the footprint and zero away from it.
  const GridFrame frame = unitCellFrame(12);
  const auto coverage = voxelizeCoverage(
      makeBoxMesh(glm::vec3(2.0f, 2.0f, 5.35f), glm::vec3(10.0f, 10.0f, 5.65f)), frame);
  for (float c : coverage) ASSERT_TRUE(std::isfinite(c) && c >= 0.0f && c <= 1.0f);
  for (int y = 3; y < 9; ++y)
    for (int x = 3; x < 9; ++x) {
      EXPECT_GT(coverage[frame.index(x, y, 5)], 0.0f);
      EXPECT_EQ(coverage[frame.index(x, y, 2)], 0.0f);
      EXPECT_EQ(coverage[frame.index(x, y, 8)], 0.0f);
    }
}

TEST(Voxelize, MillionTriangleIcosphereAt128Cells) {
  // 20 * 4^8 = 1.31M triangles; the point is that this completes quickly (not timed here).
  const TriangleMesh sphere = makeIcosphere(glm::vec3(0.5f, -0.25f, 0.1f), 1.0f, 8);
  ASSERT_EQ(sphere.triangles.size(), 1310720u);
  GridFrame frame;
  frame.cellSize = 2.2 / 126.0;
  frame.dims = glm::ivec3(128);
  frame.origin = glm::dvec3(0.5, -0.25, 0.1) - 64.0 * frame.cellSize;
  const auto coverage = voxelizeCoverage(sphere, frame);
  EXPECT_EQ(coverage[frame.index(64, 64, 64)], 1.0f);
  EXPECT_EQ(coverage[frame.index(0, 0, 0)], 0.0f);
  const double volume = totalCoverage(coverage) * std::pow(frame.cellSize, 3);
  EXPECT_NEAR(volume, enclosedVolume(sphere), 0.003 * enclosedVolume(sphere));
}

TEST(TestMeshes, BoxAndIcosphereAreWoundOutward) {
  EXPECT_NEAR(enclosedVolume(makeBoxMesh(glm::vec3(0.0f), glm::vec3(1.0f, 2.0f, 3.0f))), 6.0, 1e-6);
  EXPECT_NEAR(enclosedVolume(makeIcosphere(glm::vec3(0.0f), 1.0f, 4)), 4.0 / 3.0 * kPi, 0.01 * 4.0);
}

}  // namespace
}  // namespace sslpv
