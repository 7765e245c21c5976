// The parity voxelizer (volume/lpv/voxelize_parity.h, the CPU twin of the GPU voxelizer)
// against geometry with known answers and against the OpenVDB voxelizer
// (voxelizeCoverage), whose coverage rule it shares.
#include "volume/lpv/voxelize_parity.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "seeded_draws.h"
#include "device_shared/voxelize_shared.h"
#include "volume/core/error.h"
#include "volume/lpv/voxelize.h"
#include "voxelize_parity_meshes.h"

namespace sslpv {
namespace {

using namespace sslpv::test;

TEST(VoxelizeParityShared, FloatPlaneCubeCoverageMatchesDoubleReference) {
  // Same exact plane-cube fraction, float and regrouped against double inclusion-
  // exclusion; the double version lifts components below 1e-3 (a shift < 1e-3 cell),
  // so normals with such components are held to that looser bound.
  std::mt19937 rng(11);
  std::normal_distribution<double> gauss;
  std::uniform_real_distribution<double> offset(-0.95, 0.95);
  double worst = 0.0, worstNearAxis = 0.0;
  for (int trial = 0; trial < 20000; ++trial) {
    glm::dvec3 n = drawVec3<glm::dvec3>(gauss, rng);
    if (trial % 4 == 0) n.x *= 1e-4;  // near-axis and near-face-diagonal normals
    if (trial % 8 == 0) n.y *= 1e-3;
    n = glm::normalize(n);
    const double d = offset(rng);
    const double expected = planeCubeCoverage(d, n);
    const double got = vox::vox_planeCubeCoverage(float(d), vox::vec3(float(n.x), float(n.y), float(n.z)));
    const double minComponent = std::min({std::fabs(n.x), std::fabs(n.y), std::fabs(n.z)});
    (minComponent < 2e-3 ? worstNearAxis : worst) = std::max(minComponent < 2e-3 ? worstNearAxis : worst,
                                                             std::fabs(got - expected));
  }
  std::printf("float vs double plane-cube coverage: max diff %.2e (components >= 2e-3), %.2e (near axis)\n", worst,
              worstNearAxis);
  EXPECT_LT(worst, 2e-6);
  EXPECT_LT(worstNearAxis, 1e-3);
  EXPECT_NEAR(vox::vox_planeCubeCoverage(0.3f, vox::vec3(0.0f, 0.0f, 1.0f)), 0.2f, 1e-7f);
  EXPECT_EQ(vox::vox_planeCubeCoverage(0.87f, vox::vec3(0.57735f)), 0.0f);
  EXPECT_EQ(vox::vox_planeCubeCoverage(-0.87f, vox::vec3(0.57735f)), 1.0f);
}

TEST(VoxelizeParityShared, PackedDistanceAndNormalRoundTrip) {
  // Distance within half a 14-bit step (2.6e-5 cells); |normal| on a 511-step grid of
  // the octant's plane u + v + w = 1: half a step is up to ~0.23 degrees near the axes.
  std::mt19937 rng(5);
  std::normal_distribution<float> gauss;
  std::uniform_real_distribution<float> distance(0.0f, SSLPV_VOX_WHOLE_CELL);
  double worstAngle = 0.0, worstDistance = 0.0;
  for (int trial = 0; trial < 20000; ++trial) {
    const glm::vec3 n = glm::normalize(drawVec3<glm::vec3>(gauss, rng));
    const float d = distance(rng);
    const std::uint32_t packed = vox::vox_pack(d, vox::vec3(n.x, n.y, n.z));
    ASSERT_NE(packed, SSLPV_VOX_EMPTY);
    float dd;
    vox::vec3 nn;
    vox::vox_unpack(packed, dd, nn);
    worstDistance = std::max(worstDistance, double(std::fabs(dd - d)));
    const double cosine = glm::dot(glm::abs(n), glm::vec3(nn.x, nn.y, nn.z));
    worstAngle = std::max(worstAngle, std::acos(std::min(1.0, cosine)) * 180.0 / kVoxelizePi);
  }
  std::printf("pack round trip: distance %.2e cells, normal %.3f degrees\n", worstDistance, worstAngle);
  EXPECT_LE(worstDistance, 0.5 * SSLPV_VOX_WHOLE_CELL / SSLPV_VOX_DISTANCE_STEPS + 1e-6);
  EXPECT_LT(worstAngle, 0.25);
  // The nearest triangle wins the atomic minimum whatever the normals.
  EXPECT_LT(vox::vox_pack(0.1f, vox::vec3(0.0f, 0.0f, 1.0f)), vox::vox_pack(0.10006f, vox::vec3(1.0f, 0.0f, 0.0f)));
}

TEST(VoxelizeParity, AxisAlignedBoxFacesCutCellsAtKnownFractions) {
  // Faces at known positions inside their cells (as in voxelize_test): exact up to the
  // distance quantization (2.6e-5 cells).
  const GridFrame frame = cubeFrame(16);
  const glm::vec3 lo(4.75f, 3.25f, 2.5f), hi(11.5f, 12.75f, 10.25f);
  const std::vector<float> coverage = voxelizeCoverageParity(makeBoxMesh(lo, hi), frame);
  auto at = [&](int x, int y, int z) { return coverage[frame.index(x, y, z)]; };
  const float tol = 1e-4f;
  for (int a = 6; a <= 9; ++a)
    for (int b = 5; b <= 8; ++b) {
      EXPECT_NEAR(at(4, a, b), 0.25f, tol);
      EXPECT_NEAR(at(11, a, b), 0.5f, tol);
      EXPECT_NEAR(at(a, 3, b), 0.75f, tol);
      EXPECT_NEAR(at(a, 12, b), 0.75f, tol);
      EXPECT_NEAR(at(a, b, 2), 0.5f, tol);
      EXPECT_NEAR(at(a, b, 10), 0.25f, tol);
      EXPECT_EQ(at(3, a, b), 0.0f);
      EXPECT_EQ(at(13, a, b), 0.0f);
      EXPECT_EQ(at(a, b + 1, 6), 1.0f);
    }
  const glm::dvec3 size = glm::dvec3(hi - lo);
  const double volume = size.x * size.y * size.z;
  // Edge cells: the plane of the nearest point over-estimates convex edges by at most a
  // quarter cell per cell of edge length (as the OpenVDB path does).
  EXPECT_NEAR(sumCoverage(coverage), volume, 0.25 * 4.0 * (size.x + size.y + size.z));
  const CoverageDifference vsVdb = compareCoverage(coverage, voxelizeCoverage(makeBoxMesh(lo, hi), frame));
  std::printf("aligned box, parity vs OpenVDB: %s; volume %.3f vs exact %.3f\n", vsVdb.describe().c_str(),
              sumCoverage(coverage), volume);
}

TEST(VoxelizeParity, BoxWithFacesAndEdgesOnCellCentreColumns) {
  // Every vertex and every x, y face lies exactly on cell-centre column lines, where the
  // edge tie rule decides: a column counted twice or never would flip a whole column of
  // cells. Cells whose centre lies on a face read 0.5; the rest are exact.
  const GridFrame frame = cubeFrame(12);
  const std::vector<float> coverage =
      voxelizeCoverageParity(makeBoxMesh(glm::vec3(2.5f, 3.5f, 2.25f), glm::vec3(8.5f, 9.5f, 9.75f)), frame);
  for (int z = 0; z < 12; ++z)
    for (int y = 0; y < 12; ++y)
      for (int x = 0; x < 12; ++x) {
        const double fx = (x == 2 || x == 8) ? 0.5 : (x > 2 && x < 8 ? 1.0 : 0.0);
        const double fy = (y == 3 || y == 9) ? 0.5 : (y > 3 && y < 9 ? 1.0 : 0.0);
        const double fz = (z == 2 || z == 9) ? 0.75 : (z > 2 && z < 9 ? 1.0 : 0.0);
        // Edge and corner cells are approximated by one plane: only face cells are exact.
        const int partial = (fx == 0.5) + (fy == 0.5) + (fz == 0.75);
        if (fx * fy * fz == 0.0 || partial <= 1) {
          ASSERT_NEAR(coverage[frame.index(x, y, z)], fx * fy * fz, 1e-4) << x << "," << y << "," << z;
        }
      }
}

TEST(VoxelizeParity, OctahedronWithVerticesOnColumnsHasNoParityStreaks) {
  // Apex vertices and four edges project onto cell-centre columns. Beyond 0.8661 cells
  // from the surface every cell must be exactly 0 or 1 (the distance to a face plane
  // bounds the distance to the solid).
  const GridFrame frame = cubeFrame(20);
  const glm::dvec3 centre(10.5, 9.5, 10.2);
  const double r = 7.0;
  const std::vector<float> coverage = voxelizeCoverageParity(makeOctahedron(centre, r), frame);
  int checked = 0;
  for (int z = 0; z < 20; ++z)
    for (int y = 0; y < 20; ++y)
      for (int x = 0; x < 20; ++x) {
        const glm::dvec3 p = frame.cellCenter(x, y, z) - centre;
        const double planeDistance = (std::fabs(p.x) + std::fabs(p.y) + std::fabs(p.z) - r) / std::sqrt(3.0);
        if (std::fabs(planeDistance) < 0.87) continue;
        ++checked;
        ASSERT_EQ(coverage[frame.index(x, y, z)], planeDistance < 0.0 ? 1.0f : 0.0f) << x << "," << y << "," << z;
      }
  EXPECT_GT(checked, 7000);
  // Twelve sharp edges of length r sqrt(2): the plane rule over-estimates them by at most
  // a quarter cell per cell of edge (measured ~0.1), exactly as the OpenVDB path does.
  const double vdbVolume = sumCoverage(voxelizeCoverage(makeOctahedron(centre, r), frame));
  EXPECT_NEAR(sumCoverage(coverage), 4.0 / 3.0 * r * r * r, 0.25 * 12.0 * r * std::sqrt(2.0));
  EXPECT_NEAR(sumCoverage(coverage), vdbVolume, 0.002 * vdbVolume);
  std::printf("octahedron: volume %.2f vs exact %.2f, OpenVDB %.2f\n", sumCoverage(coverage), 4.0 / 3.0 * r * r * r,
              vdbVolume);
}

TEST(VoxelizeParity, HeightBlockWithEveryVertexOnAColumnCountsEachCrossingOnce) {
  // Every vertex of the rolling top (six triangles meet at most) and every grid edge lies
  // on a column line. A column's centres are inside exactly between the bottom and the
  // height at its vertex; a crossing counted twice or never would flip the column above it.
  const GridFrame frame = cubeFrame(14);
  const TriangleMesh block = makeHeightBlock(2, 11, 1.25, rollingHeight);
  const ParityVoxelization v = voxelizeParityDetailed(block.positions, block.triangles, frame);
  int checked = 0;
  for (int y = 3; y <= 10; ++y)
    for (int x = 3; x <= 10; ++x)
      for (int z = 0; z < 14; ++z) {
        const double centre = z + 0.5;
        ASSERT_EQ(parityInside(v, x, y, z), centre > 1.25 && centre < rollingHeight(x, y)) << x << "," << y << "," << z;
        ++checked;
      }
  EXPECT_EQ(checked, 8 * 8 * 14);
}

TEST(VoxelizeParity, SphereVolumeAndAgreementWithOpenVdb) {
  // 64 cells across, off-grid centre (as voxelize_test's sphere): total coverage within
  // 0.3% of the polyhedron's volume; per cell close to the OpenVDB path, which differs
  // only in how it estimates the gradient (central differences of its level set).
  const double radius = 1.0;
  GridFrame frame = cubeFrame(72, 2.0 * radius / 64.0);
  frame.origin = glm::dvec3(-36.0 * frame.cellSize) + 0.3 * frame.cellSize;
  const TriangleMesh sphere = makeIcosphere(glm::vec3(0.0f), float(radius), 5);
  const std::vector<float> coverage = voxelizeCoverageParity(sphere, frame);
  const double volume = sumCoverage(coverage) * std::pow(frame.cellSize, 3);
  const double exact = enclosedVolume(sphere);
  const CoverageDifference vsVdb = compareCoverage(coverage, voxelizeCoverage(sphere, frame));
  std::printf("sphere 64 across: volume %.5f, polyhedron %.5f (%.3f%%), analytic %.5f; vs OpenVDB: %s\n", volume, exact,
              100.0 * (volume / exact - 1.0), 4.0 / 3.0 * kVoxelizePi, vsVdb.describe().c_str());
  EXPECT_NEAR(volume, exact, 0.003 * exact);
  EXPECT_LT(vsVdb.meanBand, 0.01);
  EXPECT_LT(vsVdb.maxAbs, 0.08);
  // Flags differ only where one side has a sliver of a corner (plane nearly at sqrt(3)/2).
  EXPECT_LT(vsVdb.maxMismatchCoverage, 0.005);
}

TEST(VoxelizeParity, SphereCellsMatchSupersampledCoverage) {
  // Same bounds as voxelize_test's check of the OpenVDB path (worst 0.03, mean 0.008):
  // every cell against 12^3 point samples of the analytic sphere at 24 cells across.
  const double radius = 1.0;
  GridFrame frame = cubeFrame(28, 2.0 * radius / 24.0);
  frame.origin = glm::dvec3(-14.0 * frame.cellSize) + 0.17 * frame.cellSize;
  const std::vector<float> coverage = voxelizeCoverageParity(makeIcosphere(glm::vec3(0.0f), float(radius), 6), frame);
  const test::SupersampledSphereError e = test::compareWithSupersampledSphere(coverage, frame, radius);
  std::printf("sphere 24 across vs supersampled: worst %.4f, mean %.5f over %d cells\n", e.worst,
              e.meanBoundary, e.boundaryCells);
  ASSERT_GT(e.boundaryCells, 1000);
  EXPECT_LT(e.worst, 0.03);
  EXPECT_LT(e.meanBoundary, 0.008);
}

TEST(VoxelizeParity, RotatedBoxVolumeAndAgreementWithOpenVdb) {
  // A 10 x 7 x 5 box rotated off every axis: volume within the edge bound of a quarter
  // cell per cell of edge length, and close to the OpenVDB path.
  const GridFrame frame = cubeFrame(24);
  const TriangleMesh box = rotated(makeBoxMesh(glm::vec3(7.0f, 8.5f, 9.5f), glm::vec3(17.0f, 15.5f, 14.5f)),
                                   glm::dvec3(12.0, 12.0, 12.0), 0.4, 0.7, 0.25);
  const std::vector<float> coverage = voxelizeCoverageParity(box, frame);
  const std::vector<float> vdb = voxelizeCoverage(box, frame);
  const CoverageDifference vsVdb = compareCoverage(coverage, vdb);
  std::printf("rotated box: volume %.3f vs exact 350 (%.2f%%), OpenVDB %.3f; vs OpenVDB: %s\n", sumCoverage(coverage),
              100.0 * (sumCoverage(coverage) / 350.0 - 1.0), sumCoverage(vdb), vsVdb.describe().c_str());
  EXPECT_NEAR(sumCoverage(coverage), 350.0, 0.25 * 4.0 * (10.0 + 7.0 + 5.0));
  EXPECT_NEAR(sumCoverage(coverage), sumCoverage(vdb), 0.002 * 350.0);
  EXPECT_LT(vsVdb.meanBand, 0.01);
  EXPECT_LT(vsVdb.maxMismatchCoverage, 0.005);
}

TEST(VoxelizeParity, TorusKeepsItsHoleEmptyAndTubeFull) {
  // Ring radius 7, tube radius 2.5 cells: the hole (within 4.5 - 0.87 of the axis) is
  // empty and the tube core full. The plane rule over-estimates a surface curved this
  // tightly (measured +1.3% against the polyhedron, as the OpenVDB path): the volume is
  // held within 2% of the polyhedron's and 0.2% of the OpenVDB path's.
  const GridFrame frame = cubeFrame(24);
  const glm::dvec3 centre(12.2, 11.9, 12.1);
  const TriangleMesh torus = makeTorus(centre, 7.0, 2.5, 96, 32);
  const std::vector<float> coverage = voxelizeCoverageParity(torus, frame);
  for (int z = 0; z < 24; ++z)
    for (int y = 0; y < 24; ++y)
      for (int x = 0; x < 24; ++x) {
        const glm::dvec3 p = frame.cellCenter(x, y, z) - centre;
        const double tube = std::hypot(std::hypot(p.x, p.y) - 7.0, p.z) - 2.5;
        if (tube > 0.95) {
          ASSERT_EQ(coverage[frame.index(x, y, z)], 0.0f) << x << "," << y << "," << z;
        }
        if (tube < -0.95) {
          ASSERT_EQ(coverage[frame.index(x, y, z)], 1.0f) << x << "," << y << "," << z;
        }
      }
  const double exact = enclosedVolume(torus);
  const std::vector<float> vdb = voxelizeCoverage(torus, frame);
  const CoverageDifference vsVdb = compareCoverage(coverage, vdb);
  std::printf("torus: volume %.2f vs polyhedron %.2f (%.2f%%), OpenVDB %.2f; vs OpenVDB: %s\n", sumCoverage(coverage),
              exact, 100.0 * (sumCoverage(coverage) / exact - 1.0), sumCoverage(vdb), vsVdb.describe().c_str());
  EXPECT_NEAR(sumCoverage(coverage), exact, 0.02 * exact);
  EXPECT_NEAR(sumCoverage(coverage), sumCoverage(vdb), 0.002 * exact);
  EXPECT_LT(vsVdb.meanBand, 0.01);
  EXPECT_LT(vsVdb.maxMismatchCoverage, 0.005);
}

TEST(VoxelizeParity, ThinPlateKeepsItsFootprint) {
  // 0.3 cells thick inside one layer: no interior sample exists, so as in the OpenVDB
  // path the value is approximate, but it must be in [0,1], non-zero over the footprint
  // and zero two layers away.
  const GridFrame frame = cubeFrame(12);
  const std::vector<float> coverage =
      voxelizeCoverageParity(makeBoxMesh(glm::vec3(2.0f, 2.0f, 5.35f), glm::vec3(10.0f, 10.0f, 5.65f)), frame);
  for (float c : coverage) ASSERT_TRUE(std::isfinite(c) && c >= 0.0f && c <= 1.0f);
  for (int y = 3; y < 9; ++y)
    for (int x = 3; x < 9; ++x) {
      EXPECT_GT(coverage[frame.index(x, y, 5)], 0.0f);
      EXPECT_EQ(coverage[frame.index(x, y, 3)], 0.0f);
      EXPECT_EQ(coverage[frame.index(x, y, 7)], 0.0f);
    }
}

TEST(VoxelizeParity, MeshOutsideOrAroundTheFrame) {
  const GridFrame frame = cubeFrame(8);
  // Beside, above and below the frame: nothing covered (below, both crossings of every
  // column fall under the grid and cancel).
  for (const glm::vec3 shift : {glm::vec3(20.0f, 0.0f, 0.0f), glm::vec3(0.0f, 0.0f, 30.0f), glm::vec3(0.0f, 0.0f, -30.0f)}) {
    const TriangleMesh box = makeBoxMesh(glm::vec3(1.0f) + shift, glm::vec3(7.0f) + shift);
    EXPECT_EQ(sumCoverage(voxelizeCoverageParity(box, frame)), 0.0);
  }
  // The frame deep inside a mesh: every cell covered, though no triangle is near.
  EXPECT_EQ(sumCoverage(voxelizeCoverageParity(makeBoxMesh(glm::vec3(-20.0f), glm::vec3(26.0f)), frame)),
            double(frame.cellCount()));
  EXPECT_EQ(sumCoverage(voxelizeCoverageParity(TriangleMesh{}, frame)), 0.0);
  TriangleMesh broken = makeBoxMesh(glm::vec3(1.0f), glm::vec3(2.0f));
  broken.triangles[3].y = 99;
  EXPECT_THROW(voxelizeCoverageParity(broken, frame), InputError);
}

}  // namespace
}  // namespace sslpv
