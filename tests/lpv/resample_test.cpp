// Box averages of the material field (exact for axis-aligned grids, stratified for
// rotated ones) and resampleMaterial into the LPV material grid.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <iostream>
#include <random>

#include "seeded_draws.h"
#include "volume/lpv/lpv_grid.h"
#include "volume/material/material_field.h"
#include "volume/lpv/resample.h"

namespace sslpv {
namespace {
using openvdb::Coord;
using openvdb::Vec3s;
using test::drawVec3;

const MaterialSample kBase{glm::vec3(2.0f, 3.0f, 4.0f), glm::vec3(1.0f, 1.5f, 2.0f), 0.2f};

openvdb::Vec3SGrid::Ptr emptyVec3Grid(double voxelSize = 1.0) {
  auto grid = openvdb::Vec3SGrid::create(Vec3s(0.0f));
  grid->setTransform(openvdb::math::Transform::createLinearTransform(voxelSize));
  return grid;
}

std::shared_ptr<MaterialSet> setOf(openvdb::Vec3SGrid::Ptr sigmaT, openvdb::Vec3SGrid::Ptr sigmaS = nullptr,
                                   openvdb::FloatGrid::Ptr g = nullptr) {
  initializeOpenVdb();
  auto set = std::make_shared<MaterialSet>();
  set->sigmaT = std::move(sigmaT);
  set->sigmaS = sigmaS ? std::move(sigmaS) : emptyVec3Grid();
  set->g = std::move(g);
  return set;
}

/// Brute force: midpoint rule with n^3 point samples of sample(). The field is piecewise
/// trilinear with kinks at voxel centres; the midpoint rule's error per axis is at most
/// S·h²/8 (S: largest slope jump, h: sample spacing in index units).
MaterialSample bruteForceAverage(const MaterialField::Sampler& sampler, const glm::dvec3& lo, const glm::dvec3& hi,
                                 int n) {
  glm::dvec3 sigmaT(0.0), sigmaS(0.0);
  double g = 0.0;
  const glm::dvec3 step = (hi - lo) / double(n);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        MaterialSample m = sampler.sample(lo + step * (glm::dvec3(i, j, k) + 0.5));
        sigmaT += glm::dvec3(m.sigmaT);
        sigmaS += glm::dvec3(m.sigmaS);
        g += m.g;
      }
  const double count = double(n) * n * n;
  return MaterialSample{glm::vec3(sigmaT / count), glm::vec3(sigmaS / count), float(g / count)};
}

// The trilinear interpolant of linear data is that linear function, and the average of a
// linear function over a box is its value at the box centre.
TEST(BoxAverage, LinearRampAveragesToTheValueAtTheBoxCentre) {
  auto sigmaT = emptyVec3Grid(0.5);
  auto accessor = sigmaT->getAccessor();
  auto ramp = [](double x, double y, double z) { return 1.0 + 0.5 * x + 0.25 * y - 0.125 * z; };
  for (int i = -2; i < 30; ++i)
    for (int j = -2; j < 30; ++j)
      for (int k = -2; k < 30; ++k) accessor.setValue(Coord(i, j, k), Vec3s(float(ramp(i, j, k))));
  MaterialField field(kBase, setOf(sigmaT), glm::dmat4(1.0), 1.0);
  auto sampler = field.sampler();
  // World box [1.1, 4.3] x [0.7, 2.2] x [3.05, 3.4]; index = world / 0.5.
  const glm::dvec3 lo(1.1, 0.7, 3.05), hi(4.3, 2.2, 3.4);
  const glm::dvec3 centre = (lo + hi) * 0.5 / 0.5;
  EXPECT_NEAR(sampler.boxAverage(lo, hi).sigmaT.x, ramp(centre.x, centre.y, centre.z), 1e-5);
  EXPECT_EQ(sampler.boxAverage(lo, hi).sigmaS, kBase.sigmaS);
}

// One active voxel v at the origin inside the base b: the field is b + (v-b)·hat(x)hat(y)hat(z),
// so its box average is b + (v-b)·Πw with w = (1/L)∫ hat over each axis interval:
// [-0.5, 0.5]: w = 3/4;  [0, 2]: w = (1/2)(1/2) = 1/4;  [-1, 1]: w = 1/2;  [0.5, 3]: w = (1/8)/2.5.
TEST(BoxAverage, SingleVoxelInsideTheBaseIsTheClosedFormHatIntegral) {
  auto sigmaT = emptyVec3Grid();
  sigmaT->tree().setValue(Coord(0, 0, 0), Vec3s(10, 20, 30));
  MaterialField field(kBase, setOf(sigmaT), glm::dmat4(1.0), 1.0);
  auto sampler = field.sampler();
  struct Case {
    glm::dvec3 lo, hi;
    double weight;
  };
  for (const Case& c : {Case{glm::dvec3(-0.5), glm::dvec3(0.5), 0.75 * 0.75 * 0.75},
                        Case{glm::dvec3(0.0), glm::dvec3(2.0), 0.25 * 0.25 * 0.25},
                        Case{glm::dvec3(-1.0, -0.5, 0.0), glm::dvec3(1.0, 0.5, 2.0), 0.5 * 0.75 * 0.25},
                        Case{glm::dvec3(0.5, -1.0, -1.0), glm::dvec3(3.0, 1.0, 1.0), (0.125 / 2.5) * 0.5 * 0.5},
                        Case{glm::dvec3(2.0), glm::dvec3(3.0), 0.0}}) {
    const glm::vec3 average = sampler.boxAverage(c.lo, c.hi).sigmaT;
    EXPECT_NEAR(average.x, kBase.sigmaT.x + (10 - kBase.sigmaT.x) * c.weight, 1e-5);
    EXPECT_NEAR(average.z, kBase.sigmaT.z + (30 - kBase.sigmaT.z) * c.weight, 1e-5);
  }
}

// A zero-size box is the point sample, and swapped corners describe the same box.
TEST(BoxAverage, DegenerateAndSwappedBoxes) {
  auto sigmaT = emptyVec3Grid();
  sigmaT->tree().setValue(Coord(0, 0, 0), Vec3s(10, 20, 30));
  sigmaT->tree().setValue(Coord(1, 0, 0), Vec3s(5, 5, 5));
  MaterialField field(kBase, setOf(sigmaT), glm::dmat4(1.0), 1.0);
  auto sampler = field.sampler();
  const glm::dvec3 p(0.3, 0.2, -0.1);
  EXPECT_NEAR(sampler.boxAverage(p, p).sigmaT.x, sampler.sample(p).sigmaT.x, 1e-6);
  const glm::dvec3 a(-0.3, 0.4, 0.7), b(1.6, -0.9, -0.2);
  EXPECT_EQ(sampler.boxAverage(a, b).sigmaT, sampler.boxAverage(glm::min(a, b), glm::max(a, b)).sigmaT);
}

/// A random sparse set: σt, σs (within albedo ≤ 1) and g with holes, an active tile,
/// and per-axis voxel sizes, so boxes straddle active/inactive boundaries and tiles.
std::shared_ptr<MaterialSet> randomSet(std::mt19937& rng, const openvdb::math::Transform::Ptr& transform) {
  auto sigmaT = emptyVec3Grid(), sigmaS = emptyVec3Grid();
  auto g = openvdb::FloatGrid::create(0.0f);
  std::uniform_real_distribution<float> value(0.5f, 4.0f), unit(0.0f, 1.0f);
  for (int i = -1; i < 7; ++i)
    for (int j = -1; j < 7; ++j)
      for (int k = -1; k < 7; ++k) {
        if (unit(rng) < 0.3f) continue;  // leave holes that take the base
        Vec3s t = drawVec3<Vec3s>(value, rng);
        sigmaT->tree().setValue(Coord(i, j, k), t);
        sigmaS->tree().setValue(Coord(i, j, k), t * unit(rng));
        g->tree().setValue(Coord(i, j, k), unit(rng) * 1.6f - 0.8f);
      }
  sigmaT->tree().addTile(1, Coord(8, 0, 0), Vec3s(3, 1, 2), true);
  g->tree().addTile(1, Coord(8, 0, 0), -0.5f, true);
  for (openvdb::GridBase* grid : std::initializer_list<openvdb::GridBase*>{sigmaT.get(), sigmaS.get(), g.get()})
    grid->setTransform(transform->copy());
  return setOf(sigmaT, sigmaS, g);
}

void expectNear(const MaterialSample& a, const MaterialSample& b, double tolerance) {
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(a.sigmaT[c], b.sigmaT[c], tolerance) << "sigma_t channel " << c;
    EXPECT_NEAR(a.sigmaS[c], b.sigmaS[c], tolerance) << "sigma_s channel " << c;
  }
  EXPECT_NEAR(a.g, b.g, tolerance) << "g";
}

// Exact box averages equal a fine numeric average of sample() for random boxes, through
// a grid transform with different voxel sizes per axis and a mirrored, scaled and
// translated worldToRest (still axis-aligned, so the exact path is used).
TEST(BoxAverage, ExactPathMatchesBruteForceForRandomBoxes) {
  std::mt19937 rng(2024);
  openvdb::Mat4d indexToRest = openvdb::Mat4d::identity();
  indexToRest.setToScale(openvdb::Vec3d(0.5, 1.0, 2.0));
  indexToRest.setTranslation(openvdb::Vec3d(0.1, -0.3, 0.2));
  auto transform = openvdb::math::Transform::createLinearTransform(indexToRest);
  auto set = randomSet(rng, transform);
  glm::dmat4 worldToRest(1.0);
  worldToRest[0][0] = -1.0;  // mirror x
  worldToRest[2][2] = 1.5;
  worldToRest[3] = glm::dvec4(2.0, 0.5, -1.0, 1.0);
  MaterialField field(kBase, set, worldToRest, 2.0);
  auto sampler = field.sampler();
  // The data in world space: x in [-5.6, 2.4] (tile included), y in [-1.8, 5.2],
  // z in [-0.6, 9.5]. World-to-index scales are 2, 1 and 0.75 per axis, so a box up to
  // 1.2 wide spans at most 2.4 index units and 160 samples give h <= 0.015. The midpoint
  // rule's worst case 3·S·h²/8 (S <= 2·8: scaled values up to 8) is 1.4e-3, but the
  // kinks fall at random offsets inside the sample cells and partly cancel: the observed
  // difference is <= 4e-5 and shrinks with n (< 5e-6 at n = 320, all brute-force error),
  // so a tolerance of 1e-4 catches any weight error of practical size.
  std::uniform_real_distribution<double> x(-6.0, 3.0), y(-2.0, 6.0), z(-1.0, 10.0), size(0.2, 1.2);
  double worst = 0.0;
  for (int box = 0; box < 5; ++box) {
    const glm::dvec3 lo = drawVec3<glm::dvec3>(x, y, z, rng);
    const glm::dvec3 hi = lo + drawVec3<glm::dvec3>(size, rng);
    const MaterialSample exact = sampler.boxAverage(lo, hi), numeric = bruteForceAverage(sampler, lo, hi, 160);
    expectNear(exact, numeric, 1e-4);
    worst = std::max({worst, double(std::abs(exact.sigmaT.x - numeric.sigmaT.x)),
                      double(std::abs(exact.sigmaS.y - numeric.sigmaS.y)), double(std::abs(exact.g - numeric.g))});
  }
  std::cout << "exact path: worst difference to brute force " << worst << "\n";
}

// A rotated grid cannot use separable weights: boxAverage takes a 4x4x4 stratified
// average. Its error is the midpoint rule's with 4 strata of a piecewise-trilinear field
// (observed ~0.01 for values in [0.5, 4] over boxes up to one voxel); a wrong map or a
// misplaced sample gives errors of the order of the value range (~1). 0.05 separates them.
TEST(BoxAverage, RotatedTransformAgreesWithBruteForce) {
  std::mt19937 rng(99);
  auto transform = openvdb::math::Transform::createLinearTransform(1.0);
  transform->postRotate(0.5, openvdb::math::Z_AXIS);
  transform->postRotate(0.3, openvdb::math::X_AXIS);
  auto set = randomSet(rng, transform);
  MaterialField field(kBase, set, glm::dmat4(1.0), 1.0);
  auto sampler = field.sampler();
  std::uniform_real_distribution<double> position(0.0, 4.0), size(0.3, 1.0);
  double worst = 0.0;
  for (int box = 0; box < 5; ++box) {
    const glm::dvec3 lo = drawVec3<glm::dvec3>(position, rng);
    const glm::dvec3 hi = lo + drawVec3<glm::dvec3>(size, rng);
    const MaterialSample exact = bruteForceAverage(sampler, lo, hi, 96);
    const MaterialSample stratified = sampler.boxAverage(lo, hi);
    expectNear(stratified, exact, 0.05);
    worst = std::max(worst, double(std::abs(stratified.sigmaT.x - exact.sigmaT.x)));
  }
  std::cout << "rotated: worst stratified error in sigma_t.r " << worst << "\n";
}

// resampleMaterial stores, per cell, the box average over that cell's world box.
TEST(ResampleMaterial, EachCellIsTheBoxAverageOverTheCell) {
  auto sigmaT = emptyVec3Grid(), sigmaS = emptyVec3Grid();
  sigmaT->tree().setValue(Coord(0, 0, 0), Vec3s(10, 20, 30));
  sigmaS->tree().setValue(Coord(2, 1, 0), Vec3s(1, 1, 1));
  auto g = openvdb::FloatGrid::create(0.0f);
  g->tree().setValue(Coord(1, 1, 1), 0.9f);
  MaterialField field(kBase, setOf(sigmaT, sigmaS, g), glm::dmat4(1.0), 1.0);
  MaterialGrid material;
  material.frame.origin = glm::dvec3(-0.5, -1.0, -1.5);
  material.frame.cellSize = 1.0;
  material.frame.dims = glm::ivec3(4, 3, 2);
  material.coverage.assign(material.frame.cellCount(), 0.25f);
  resampleMaterial(field, material);
  ASSERT_EQ(material.sigmaT.size(), material.frame.cellCount());
  ASSERT_EQ(material.sigmaS.size(), material.frame.cellCount());
  ASSERT_EQ(material.g.size(), material.frame.cellCount());
  EXPECT_EQ(material.coverage, std::vector<float>(material.frame.cellCount(), 0.25f));
  auto sampler = field.sampler();
  for (int z = 0; z < 2; ++z)
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 4; ++x) {
        const glm::dvec3 lo = material.frame.cellMin(x, y, z);
        const MaterialSample expected = sampler.boxAverage(lo, lo + 1.0);
        const std::size_t i = material.frame.index(x, y, z);
        EXPECT_EQ(material.sigmaT[i], expected.sigmaT);
        EXPECT_EQ(material.sigmaS[i], expected.sigmaS);
        EXPECT_EQ(material.g[i], expected.g);
      }
  // Cell (0,1,1) spans [-0.5,0.5] x [0,1] x [-0.5,0.5]: weights 3/4 · 1/2 · 3/4 for voxel 0.
  const double weight = 0.75 * 0.5 * 0.75;
  EXPECT_NEAR(material.sigmaT[material.frame.index(0, 1, 1)].x, kBase.sigmaT.x + (10 - kBase.sigmaT.x) * weight, 1e-5);
}

TEST(ResampleMaterial, HomogeneousFieldIsTheBaseExactly) {
  MaterialField field(kBase, nullptr, glm::dmat4(1.0), 1.0);
  MaterialGrid material;
  material.frame.dims = glm::ivec3(5, 4, 3);
  material.frame.cellSize = 0.25;
  resampleMaterial(field, material);
  ASSERT_EQ(material.sigmaT.size(), 60u);
  for (std::size_t i = 0; i < 60; ++i) {
    EXPECT_EQ(material.sigmaT[i], kBase.sigmaT);
    EXPECT_EQ(material.sigmaS[i], kBase.sigmaS);
    EXPECT_EQ(material.g[i], kBase.g);
  }
}

// Cells far from any active voxel are the base exactly, also in a heterogeneous field.
TEST(ResampleMaterial, CellsAwayFromTheGridAreTheBaseExactly) {
  auto sigmaT = emptyVec3Grid();
  sigmaT->tree().setValue(Coord(0, 0, 0), Vec3s(10, 20, 30));
  MaterialField field(kBase, setOf(sigmaT), glm::dmat4(1.0), 1.0);
  MaterialGrid material;
  material.frame.origin = glm::dvec3(5.0);
  material.frame.dims = glm::ivec3(3);
  resampleMaterial(field, material);
  for (const glm::vec3& v : material.sigmaT) EXPECT_EQ(v, kBase.sigmaT);
}

}  // namespace
}  // namespace sslpv
