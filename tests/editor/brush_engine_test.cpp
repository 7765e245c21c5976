// The brush engine (editor/brush_engine.h) and stroke files (editor/stroke_io.h): each
// test states the property it checks; exact ones compare stored bits.
#include "editor/brush_engine.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <glm/gtc/matrix_transform.hpp>
#include <random>

#include "editor/stroke_io.h"
#include "seeded_draws.h"
#include "test_meshes.h"
#include "volume/core/error.h"

namespace sslpv {
namespace {

using openvdb::Coord;
using openvdb::Vec3s;
using test::drawVec3;

const MaterialSample kBase{{1.0f, 1.2f, 1.4f}, {0.9f, 1.0f, 1.1f}, 0.1f};

std::unique_ptr<BrushEngine> makeEngine(std::shared_ptr<MaterialSet> set,
                                        const glm::dmat4& restToWorld = glm::dmat4(1.0),
                                        std::shared_ptr<const TriangleMesh> mesh = nullptr) {
  PaintTarget target;
  target.set = std::move(set);
  target.base = kBase;
  target.restToWorld = restToWorld;
  target.restBounds.extend(glm::dvec3(-8.0));
  target.restBounds.extend(glm::dvec3(8.0));
  target.worldMesh = std::move(mesh);
  return std::make_unique<BrushEngine>(std::move(target));
}

struct Voxel {
  Vec3s t, s;
  float g = 0.0f;
  bool onT = false, onS = false, onG = false;
  bool operator==(const Voxel& o) const {
    return std::memcmp(t.asPointer(), o.t.asPointer(), 12) == 0 &&
           std::memcmp(s.asPointer(), o.s.asPointer(), 12) == 0 && std::memcmp(&g, &o.g, 4) == 0 && onT == o.onT &&
           onS == o.onS && onG == o.onG;
  }
  bool inactive() const { return !onT && !onS && !onG; }
};

Voxel voxel(const MaterialSet& set, const Coord& c) {
  Voxel v;
  v.onT = set.sigmaT->tree().probeValue(c, v.t);
  v.onS = set.sigmaS->tree().probeValue(c, v.s);
  if (set.g) v.onG = set.g->tree().probeValue(c, v.g);
  return v;
}

openvdb::CoordBBox dataBox(const MaterialSet& a, const MaterialSet& b) {
  openvdb::CoordBBox box;
  auto addLeaves = [&box](const auto& tree) {
    openvdb::CoordBBox leaves;
    if (tree.evalLeafBoundingBox(leaves)) box.expand(leaves);
  };
  for (const MaterialSet* s : {&a, &b}) {
    // Leaves, not only active voxels: inactive voxels' stored values are compared too.
    addLeaves(s->sigmaT->tree());
    addLeaves(s->sigmaS->tree());
    if (s->g) addLeaves(s->g->tree());
  }
  box.expand(2);
  return box;
}

/// Every voxel (values, inactive ones included, and active states) is bit-identical.
::testing::AssertionResult sameVoxels(const MaterialSet& a, const MaterialSet& b) {
  const openvdb::CoordBBox box = dataBox(a, b);
  for (auto it = box.begin(); it && !box.empty(); ++it)
    if (!(voxel(a, *it) == voxel(b, *it))) return ::testing::AssertionFailure() << "voxel " << *it << " differs";
  if (a.sigmaT->activeVoxelCount() != b.sigmaT->activeVoxelCount())
    return ::testing::AssertionFailure() << "active voxel counts differ";
  return ::testing::AssertionSuccess();
}

/// Random valid material on ~30 % of [-12,12]^3 (background 0 like the shipped files), some
/// voxels active in σt only (their σs is the base's) and inactive voxels holding junk.
std::shared_ptr<MaterialSet> randomSet(std::uint32_t seed) {
  auto set = makeEmptyMaterialSet(MaterialSample{}, 0.5, "mm");
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  auto t = set->sigmaT->getAccessor();
  auto s = set->sigmaS->getAccessor();
  auto g = set->g->getAccessor();
  for (auto it = openvdb::CoordBBox(Coord(-12), Coord(12)).begin(); it; ++it) {
    const float r = unit(rng);
    const Vec3s st = drawVec3<Vec3s>([&] { return 5 * unit(rng); });
    const Vec3s ss = st * drawVec3<Vec3s>(unit, rng);
    if (r < 0.3f) {
      t.setValueOn(*it, st);
      s.setValueOn(*it, ss);
      g.setValueOn(*it, 1.8f * unit(rng) - 0.9f);
    } else if (r < 0.35f) {
      t.setValueOn(*it, st);
    } else if (r < 0.4f) {
      t.setValueOff(*it, st);
    }
  }
  return set;
}

Brush makeBrush(BrushChannel channel, BrushMode mode, double radius, BrushFalloff falloff, double strength) {
  Brush b;
  b.channel = channel;
  b.mode = mode;
  b.radius = radius;
  b.falloff = falloff;
  b.strength = strength;
  return b;
}

double referenceWeight(BrushFalloff f, double u) {
  // Written out from the header comment, independently of falloffWeight().
  switch (f) {
    case BrushFalloff::Constant:
      return 1.0;
    case BrushFalloff::Linear:
      return 1.0 - u;
    case BrushFalloff::Smooth:
      return 1.0 - (3.0 * u * u - 2.0 * u * u * u);
    case BrushFalloff::Gaussian:
      return (std::exp(-4.5 * u * u) - std::exp(-4.5)) / (1.0 - std::exp(-4.5));
  }
  return 0.0;
}

TEST(BrushEngine, ValuesInsideTheRadiusFollowTheFalloffAndOutsideStayUntouched) {
  // One set dab (σt -> (4,5,6), strength 0.7) per falloff, in the identity frame and under a
  // similarity (scale 2, rotation, translation): inside, σt = base + w(u)·0.7·(target - base)
  // with u measured in rest space (radius 5.2 world = 2.6 rest); σs and g keep the base;
  // outside, voxels stay inactive with the background's bits.
  const glm::dmat4 similarity = glm::scale(
      glm::rotate(glm::translate(glm::dmat4(1.0), glm::dvec3(3, -2, 1)), 0.7, glm::normalize(glm::dvec3(1, 2, 3))),
      glm::dvec3(2.0));
  const glm::dvec3 target(4, 5, 6), centre(0.3, -0.15, 0.2);
  const auto empty = makeEmptyMaterialSet(kBase, 0.5, "mm");
  for (const glm::dmat4& frame : {glm::dmat4(1.0), similarity})
    for (BrushFalloff f :
         {BrushFalloff::Constant, BrushFalloff::Linear, BrushFalloff::Smooth, BrushFalloff::Gaussian}) {
      const double scale = glm::length(glm::dvec3(frame[0]));
      auto set = makeEmptyMaterialSet(kBase, 0.5, "mm");
      auto engine = makeEngine(set, frame);
      Brush b = makeBrush(BrushChannel::SigmaT, BrushMode::Set, 2.6 * scale, f, 0.7);
      b.rgb = target;
      const StrokeResult result = engine->applyStroke({b, {glm::dvec3(frame * glm::dvec4(centre, 1.0))}, {}});
      EXPECT_EQ(result.dabs, 1u);
      std::size_t inside = 0;
      for (auto it = openvdb::CoordBBox(Coord(-8), Coord(8)).begin(); it; ++it) {
        const Voxel v = voxel(*set, *it);
        const glm::dvec3 p = 0.5 * glm::dvec3((*it).x(), (*it).y(), (*it).z());
        const double u = glm::length(p - centre) / 2.6;
        if (std::abs(u - 1.0) < 1e-9) continue;  // round-off decides: not a falloff question
        if (u > 1.0) {
          ASSERT_TRUE(v.inactive()) << *it;
          ASSERT_TRUE(v == voxel(*empty, *it)) << *it;
          continue;
        }
        ++inside;
        const double t = referenceWeight(f, u) * 0.7;
        for (int c = 0; c < 3; ++c) {
          const float expected = float(double(kBase.sigmaT[c]) + t * (target[c] - double(kBase.sigmaT[c])));
          const float effective = v.onT ? v.t[c] : kBase.sigmaT[c];
          ASSERT_NEAR(effective, expected, 2e-6 * expected) << *it << " u " << u;
          ASSERT_EQ(v.onS ? v.s[c] : kBase.sigmaS[c], kBase.sigmaS[c]);
        }
        ASSERT_EQ(v.onG ? v.g : kBase.g, kBase.g);
      }
      EXPECT_GT(inside, 250u);  // (4/3)π 5.2³ ≈ 589 voxel centres
    }
  EXPECT_EQ(falloffWeight(BrushFalloff::Smooth, 0.5), 0.5);
  EXPECT_EQ(falloffWeight(BrushFalloff::Gaussian, 1.0), 0.0);
  EXPECT_EQ(falloffWeight(BrushFalloff::Constant, 1.0 + 1e-12), 0.0);
}

double distanceToSegment(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b) {
  const double s = std::clamp(glm::dot(p - a, b - a) / glm::dot(b - a, b - a), 0.0, 1.0);
  return glm::length(p - (a + s * (b - a)));
}

TEST(BrushEngine, EveryModeLeavesVoxelsOutsideTheStrokeBitIdenticalAndCountsWhatChanged) {
  // On a randomly painted set, strokes of every mode/channel change nothing farther than
  // the radius from the stroke's segment; voxelsChanged equals the voxels that differ and
  // worldBounds holds each of them.
  std::vector<Brush> brushes;
  auto add = [&](BrushChannel c, BrushMode m) { brushes.push_back(makeBrush(c, m, 1.7, BrushFalloff::Smooth, 0.8)); };
  add(BrushChannel::SigmaT, BrushMode::Set), brushes.back().rgb = glm::dvec3(3, 0.5, 7);
  add(BrushChannel::SigmaS, BrushMode::Add), brushes.back().rgb = glm::dvec3(-1, 0.5, 2);
  add(BrushChannel::G, BrushMode::Multiply), brushes.back().scalar = -2.0;
  add(BrushChannel::All, BrushMode::Smooth);
  add(BrushChannel::All, BrushMode::Erase);
  add(BrushChannel::AlbedoMfp, BrushMode::Set), brushes.back().albedo = glm::dvec3(0.9, 0.5, 0.2);
  add(BrushChannel::Preset, BrushMode::Set), brushes.back().preset = "ketchup";
  const glm::dvec3 a(-2.1, 0.3, 1.0), b(2.4, -1.0, 0.6);
  for (const Brush& brush : brushes) {
    auto set = randomSet(7);
    const auto before = deepCopy(*set);
    auto engine = makeEngine(set);
    const StrokeResult result = engine->applyStroke({brush, {a, b}, {}});
    std::size_t differing = 0;
    for (auto it = dataBox(*set, *before).begin(); it; ++it) {
      if (voxel(*set, *it) == voxel(*before, *it)) continue;
      ++differing;
      const glm::dvec3 p = 0.5 * glm::dvec3((*it).x(), (*it).y(), (*it).z());
      ASSERT_LE(distanceToSegment(p, a, b), brush.radius * (1 + 1e-12)) << *it;
      for (int axis = 0; axis < 3; ++axis) {
        ASSERT_GE(p[axis] - 0.5, result.worldBounds.min[axis]);
        ASSERT_LE(p[axis] + 0.5, result.worldBounds.max[axis]);
      }
    }
    EXPECT_GT(differing, 50u);
    EXPECT_EQ(result.voxelsChanged, differing);
  }
}

TEST(BrushEngine, EraseRestoresTheBaseAsInactiveVoxels) {
  // Full-strength constant erase over a painted region leaves every grid with no active
  // voxel (inactive = base, value = background); half strength moves halfway to the base.
  auto set = makeEmptyMaterialSet(kBase, 0.5, "mm");
  auto engine = makeEngine(set);
  Brush paint = makeBrush(BrushChannel::AlbedoMfp, BrushMode::Set, 2.0, BrushFalloff::Constant, 1.0);
  paint.albedo = glm::dvec3(0.5);
  paint.meanFreePath = glm::dvec3(0.25);
  engine->applyStroke({paint, {glm::dvec3(0.0), glm::dvec3(2, 0, 0)}, {}});
  ASSERT_GT(set->sigmaT->activeVoxelCount(), 100u);
  Brush half = makeBrush(BrushChannel::All, BrushMode::Erase, 0.6, BrushFalloff::Constant, 0.5);
  engine->applyStroke({half, {glm::dvec3(0.0)}, {}});
  const Voxel v = voxel(*set, Coord(0));
  ASSERT_TRUE(v.onT && v.onS && v.onG);
  EXPECT_FLOAT_EQ(v.t[0], float(0.5 * 4.0 + 0.5 * kBase.sigmaT[0]));
  EXPECT_FLOAT_EQ(v.s[1], float(0.5 * 2.0 + 0.5 * kBase.sigmaS[1]));
  Brush erase = makeBrush(BrushChannel::All, BrushMode::Erase, 3.0, BrushFalloff::Constant, 1.0);
  const StrokeResult result = engine->applyStroke({erase, {glm::dvec3(0.0), glm::dvec3(2, 0, 0)}, {}});
  EXPECT_GT(result.voxelsChanged, 100u);
  EXPECT_EQ(set->sigmaT->activeVoxelCount(), 0u);
  EXPECT_EQ(set->sigmaS->activeVoxelCount(), 0u);
  EXPECT_EQ(set->g->activeVoxelCount(), 0u);
  EXPECT_TRUE(sameVoxels(*set, *makeEmptyMaterialSet(kBase, 0.5, "mm")));
}

TEST(BrushEngine, UndoAndRedoRestoreBitIdenticallyInterleaved) {
  // States S0..S3 after strokes A (set), B (smooth), C (erase) on a random set; undo/redo
  // in any interleaving returns exactly to the matching state, a new stroke after an undo
  // drops the redo branch, and history memory grows with the strokes.
  auto set = randomSet(11);
  auto engine = makeEngine(set);
  std::vector<std::shared_ptr<MaterialSet>> states{deepCopy(*set)};
  Brush a = makeBrush(BrushChannel::SigmaT, BrushMode::Set, 2.0, BrushFalloff::Gaussian, 0.9);
  a.rgb = glm::dvec3(9, 0.1, 3);
  Brush b = makeBrush(BrushChannel::All, BrushMode::Smooth, 2.5, BrushFalloff::Smooth, 1.0);
  Brush c = makeBrush(BrushChannel::All, BrushMode::Erase, 1.5, BrushFalloff::Linear, 1.0);
  std::vector<StrokeResult> results;
  for (const Brush& brush : {a, b, c}) {
    results.push_back(engine->applyStroke({brush, {glm::dvec3(-1, 0, 0), glm::dvec3(1.5, 1, 0)}, {}}));
    states.push_back(deepCopy(*set));
    EXPECT_FALSE(sameVoxels(*states.back(), *states[states.size() - 2]));
  }
  const std::size_t bytesAfterThree = engine->historyBytes();
  EXPECT_GT(bytesAfterThree, 0u);
  EXPECT_EQ(engine->undo()->voxelsChanged, results[2].voxelsChanged);
  EXPECT_TRUE(sameVoxels(*set, *states[2]));
  engine->undo();
  EXPECT_TRUE(sameVoxels(*set, *states[1]));
  engine->redo();
  EXPECT_TRUE(sameVoxels(*set, *states[2]));
  engine->redo();
  EXPECT_TRUE(sameVoxels(*set, *states[3]));
  EXPECT_FALSE(engine->canRedo());
  engine->undo();
  engine->undo();
  EXPECT_TRUE(sameVoxels(*set, *states[1]));
  Brush d = makeBrush(BrushChannel::G, BrushMode::Add, 3.0, BrushFalloff::Constant, 0.5);
  d.scalar = 0.7;
  engine->applyStroke({d, {glm::dvec3(0.5)}, {}});
  const auto afterD = deepCopy(*set);
  EXPECT_FALSE(engine->canRedo());
  EXPECT_EQ(engine->historyStrokes(), 2u);
  engine->undo();
  EXPECT_TRUE(sameVoxels(*set, *states[1]));
  engine->redo();
  EXPECT_TRUE(sameVoxels(*set, *afterD));
  while (engine->canUndo()) engine->undo();
  EXPECT_TRUE(sameVoxels(*set, *states[0]));
  EXPECT_FALSE(engine->undo().has_value());
}

TEST(BrushEngine, MirrorStrokesAreExactlySymmetric) {
  // Strokes with a mirror across x = 0 (through voxel centres) and y = 0.3 (snapped from
  // 0.31 to the face between voxel centres 0 and 0.6 of a 0.6 grid, a size binary floating
  // point cannot reflect exactly) on an empty set give v == mirror(v) bit for bit, for
  // every mode including the order-dependent add and smooth, and for a stroke crossing the
  // plane.
  for (int axis : {0, 1}) {
    auto set = makeEmptyMaterialSet(kBase, 0.6, "mm");
    auto engine = makeEngine(set);
    BrushMirror mirror{axis, axis == 0 ? std::optional<double>() : std::optional<double>(0.31)};
    const double plane = engine->mirrorPlane(mirror);
    EXPECT_EQ(plane, axis == 0 ? 0.0 : 0.3);
    const int twice = axis == 0 ? 0 : 1;
    Brush add = makeBrush(BrushChannel::SigmaS, BrushMode::Add, 1.3, BrushFalloff::Gaussian, 0.6);
    add.rgb = glm::dvec3(0.7, 0.3, 0.1);
    Brush set2 = makeBrush(BrushChannel::SigmaT, BrushMode::Set, 1.1, BrushFalloff::Linear, 0.9);
    set2.rgb = glm::dvec3(6, 2, 0.5);
    Brush smooth = makeBrush(BrushChannel::All, BrushMode::Smooth, 1.6, BrushFalloff::Smooth, 1.0);
    for (Brush* b : {&set2, &add, &smooth, &add}) {
      b->mirror = mirror;
      engine->applyStroke(
          {*b, {glm::dvec3(-0.2, 0.1, 0.3), glm::dvec3(1.9, 0.7, -0.4), glm::dvec3(0.4, 2.2, 0.0)}, {}});
    }
    ASSERT_GT(set->sigmaT->activeVoxelCount(), 100u);
    for (auto it = openvdb::CoordBBox(Coord(-10), Coord(10)).begin(); it; ++it) {
      Coord m = *it;
      m[axis] = twice - m[axis];
      ASSERT_TRUE(voxel(*set, *it) == voxel(*set, m)) << *it << " vs " << m;
    }
  }
}

TEST(BrushEngine, RandomStrokesKeepEveryVoxelValid) {
  // Property (seed 2024): 400 random strokes of random channels, modes, extreme values,
  // radii, falloffs, strengths and mirrors keep σt >= 0, 0 <= σs <= σt, |g| <= 0.99 and
  // everything finite in every active voxel, and the set passes validateMaterialSet.
  auto set = randomSet(5);
  auto engine = makeEngine(set);
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto pick = [&](int n) { return int(unit(rng) * n) % n; };
  const double extremes[] = {0.0, 1e-30, 0.5, 3.0, 1e6, 1e30, 3e38};
  auto value = [&](bool signedValue) {
    double v = unit(rng) < 0.3 ? extremes[pick(7)] : 10.0 * unit(rng);
    return signedValue && unit(rng) < 0.5 ? -v : v;
  };
  for (int i = 0; i < 400; ++i) {
    Brush b;
    b.mode = BrushMode(pick(5));
    const bool valued = b.mode == BrushMode::Set || b.mode == BrushMode::Add || b.mode == BrushMode::Multiply;
    b.channel =
        valued ? BrushChannel(pick(b.mode == BrushMode::Set ? 5 : 3)) : BrushChannel(pick(4) == 3 ? 5 : pick(3));
    if (b.mode == BrushMode::Set && pick(6) == 0) b.channel = BrushChannel::Colour;
    b.artist.colour = drawVec3<glm::dvec3>(unit, rng);
    const double scatterY = 1e-3 + unit(rng);  // drawn before x, as GCC did (seeded_draws.h)
    b.artist.scatterDistance = glm::dvec3(value(false) + 1e-6, scatterY, 0.5);
    b.artist.g = 1.98 * unit(rng) - 0.99;
    b.rgb = drawVec3<glm::dvec3>([&] { return value(b.mode == BrushMode::Add); });
    b.scalar = b.mode == BrushMode::Set ? 1.98 * unit(rng) - 0.99 : value(true);
    b.albedo = drawVec3<glm::dvec3>(unit, rng);
    const double meanFreePathZ = 1e-6 + 4 * unit(rng);  // drawn before x, as GCC did (seeded_draws.h)
    b.meanFreePath = glm::dvec3(1e-3 + unit(rng), 0.5, meanFreePathZ);
    b.preset = measuredMaterials()[std::size_t(pick(11))].name;
    b.radius = 0.3 + 2.5 * unit(rng);
    b.falloff = BrushFalloff(pick(4));
    b.strength = unit(rng) < 0.2 ? 1.0 : unit(rng);
    if (unit(rng) < 0.3) b.mirror = BrushMirror{pick(3), unit(rng) < 0.5 ? std::optional<double>() : 2 * unit(rng)};
    ASSERT_EQ(brushProblem(b), "") << i;
    std::vector<glm::dvec3> points;
    for (int p = 0, n = 1 + pick(3); p < n; ++p)
      points.push_back(drawVec3<glm::dvec3>(unit, rng) * 12.0 - 6.0);
    engine->applyStroke({b, points, {}});
  }
  std::size_t active = 0;
  for (auto it = set->sigmaT->cbeginValueOn(); it; ++it, ++active) {
    const Voxel v = voxel(*set, it.getCoord());
    ASSERT_TRUE(v.onS && v.onG) << it.getCoord() << " touched voxels are active in all grids";
    for (int c = 0; c < 3; ++c) {
      ASSERT_TRUE(std::isfinite(v.t[c]) && std::isfinite(v.s[c])) << it.getCoord();
      ASSERT_GE(v.s[c], 0.0f);
      ASSERT_LE(v.s[c], v.t[c]);
    }
    ASSERT_TRUE(std::isfinite(v.g));
    ASSERT_LE(std::abs(v.g), kBrushMaxG);
  }
  EXPECT_GT(active, 1000u);
  EXPECT_TRUE(validateMaterialSet(*set, "random").empty()) << validateMaterialSet(*set, "random")[0].message;
}

TEST(BrushEngine, ArtistChannelsAndUnitsGiveTheDocumentedValues) {
  // Constant full-strength set: albedo_mfp gives σt = 1/mfp, σs = albedo·σt; a preset gives
  // Jensen's σt, σs (g = 0) and g = 0; in a set stored in cm (scene in mm) σ is stored x10.
  for (const char* units : {"mm", "cm"}) {
    const double k = std::string(units) == "cm" ? 10.0 : 1.0;
    auto set = makeEmptyMaterialSet(kBase, 0.5, units);
    auto engine = makeEngine(set);
    EXPECT_EQ(engine->sigmaToSetUnits(), k);
    Brush mfp = makeBrush(BrushChannel::AlbedoMfp, BrushMode::Set, 0.6, BrushFalloff::Constant, 1.0);
    mfp.albedo = glm::dvec3(0.2, 0.5, 0.9);
    mfp.meanFreePath = glm::dvec3(0.5, 2.0, 4.0);
    engine->applyStroke({mfp, {glm::dvec3(0.0)}, {}});
    Voxel v = voxel(*set, Coord(0));
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(v.t[c], float(k / mfp.meanFreePath[c]));
      EXPECT_EQ(v.s[c], float(mfp.albedo[c] * (k / mfp.meanFreePath[c])));
    }
    EXPECT_EQ(v.g, kBase.g);
    Brush preset = makeBrush(BrushChannel::Preset, BrushMode::Set, 0.6, BrushFalloff::Constant, 1.0);
    preset.preset = "skin1";
    engine->applyStroke({preset, {glm::dvec3(2.0, 0, 0)}, {}});
    v = voxel(*set, Coord(4, 0, 0));
    const MaterialSample skin = *presetMaterial("skin1", 0.0f, 1.0);
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(v.t[c], float(double(skin.sigmaT[c]) * k));
      EXPECT_EQ(v.s[c], float(double(skin.sigmaS[c]) * k));
    }
    EXPECT_EQ(v.g, 0.0f);
  }
}

TEST(BrushEngine, DraggedStrokesHaveNoGaps) {
  // A 10-unit segment with radius 2 gets ceil(10 / 0.5) + 1 = 21 dabs, and with a
  // constant full-strength brush every voxel within 0.99 radius of the segment is painted.
  auto set = makeEmptyMaterialSet(kBase, 0.25, "mm");
  auto engine = makeEngine(set);
  Brush b = makeBrush(BrushChannel::SigmaT, BrushMode::Set, 2.0, BrushFalloff::Constant, 1.0);
  b.rgb = glm::dvec3(5.0);
  const glm::dvec3 a(-5, 0.1, 0), c(5, 0.1, 0);
  const StrokeResult result = engine->applyStroke({b, {a, c}, {}});
  EXPECT_EQ(result.dabs, 21u);
  std::size_t checked = 0;
  for (auto it = openvdb::CoordBBox(Coord(-30, -10, -10), Coord(30, 10, 10)).begin(); it; ++it) {
    const glm::dvec3 p = 0.25 * glm::dvec3((*it).x(), (*it).y(), (*it).z());
    if (distanceToSegment(p, a, c) > 0.99 * 2.0) continue;
    ++checked;
    ASSERT_EQ(voxel(*set, *it).t[0], 5.0f) << *it;
  }
  EXPECT_GT(checked, 5000u);
}

TEST(BrushEngine, IncrementalStrokeEqualsTheWholeStroke) {
  // An editor's drag delivered in three calls paints exactly what one applyStroke with the
  // same points paints (the path continues across calls), and each call's bounds hold the
  // voxels it wrote.
  Brush b = makeBrush(BrushChannel::SigmaS, BrushMode::Add, 1.2, BrushFalloff::Gaussian, 0.4);
  b.rgb = glm::dvec3(0.3, -0.2, 0.5);
  const std::vector<glm::dvec3> points = {{-3, 0, 0}, {-1, 1, 0.5}, {0.5, 1.5, 0}, {2, -1, -1}, {3, 0, 0}};
  auto whole = randomSet(3), pieces = randomSet(3);
  makeEngine(whole)->applyStroke({b, points, {}});
  auto engine = makeEngine(pieces);
  engine->beginStroke(b);
  std::size_t dabs = 0;
  for (const auto& part : {std::vector<glm::dvec3>(points.begin(), points.begin() + 2),
                           std::vector<glm::dvec3>(points.begin() + 2, points.begin() + 3),
                           std::vector<glm::dvec3>(points.begin() + 3, points.end())}) {
    const auto before = deepCopy(*pieces);
    const DabResult call = engine->addPoints(part);
    dabs += call.dabs;
    for (auto it = dataBox(*pieces, *before).begin(); it; ++it) {
      if (voxel(*pieces, *it) == voxel(*before, *it)) continue;
      const glm::dvec3 p = 0.5 * glm::dvec3((*it).x(), (*it).y(), (*it).z());
      ASSERT_TRUE(glm::all(glm::greaterThanEqual(p, call.worldBounds.min)) &&
                  glm::all(glm::lessThanEqual(p, call.worldBounds.max)))
          << *it;
    }
  }
  EXPECT_EQ(engine->endStroke().dabs, dabs);
  EXPECT_TRUE(sameVoxels(*whole, *pieces));
}

TEST(BrushEngine, RayStrokesFollowTheSurfaceAndPaintToDepth) {
  // Two rays hitting the +z face of the box [-4,4]^3 at x = -2 and x = 2: the interpolated
  // rays paint the surface voxels between them without gaps; depth 1 paints along the
  // inward normal down to z = 3 (± radius) and no deeper; a ray that misses is counted.
  auto mesh = std::make_shared<const TriangleMesh>(test::makeBoxMesh(glm::vec3(-4.0f), glm::vec3(4.0f)));
  auto set = makeEmptyMaterialSet(kBase, 0.25, "mm");
  auto engine = makeEngine(set, glm::dmat4(1.0), mesh);
  Brush b = makeBrush(BrushChannel::SigmaT, BrushMode::Set, 0.5, BrushFalloff::Constant, 1.0);
  b.rgb = glm::dvec3(3.0);
  b.depth = 1.0;
  // y = 0.3: off the face's diagonal, where an interpolated ray could slip between triangles.
  const std::vector<SurfaceRay> rays = {{{-2, 0.3, 10}, {0, 0, -1}},
                                        {{50, 0, 10}, {0, 0, -1}},
                                        {{-2, 0.3, 10}, {0, 0, -1}},
                                        {{2.0, 0.3, 10}, {0, 0, -1}}};
  const StrokeResult result = engine->applyStroke({b, {}, rays});
  EXPECT_EQ(result.raysMissed, 1u);
  for (int i = -8; i <= 8; ++i) {
    EXPECT_EQ(voxel(*set, Coord(i, 1, 16)).t[0], 3.0f) << "surface voxel x=" << i * 0.25;
    EXPECT_EQ(voxel(*set, Coord(i, 1, 12)).t[0], 3.0f) << "depth-1 voxel x=" << i * 0.25;
    EXPECT_TRUE(voxel(*set, Coord(i, 1, 9)).inactive()) << "below depth + radius, x=" << i * 0.25;
  }
  EXPECT_TRUE(voxel(*set, Coord(12, 1, 16)).inactive());
}

TEST(BrushEngine, RejectsUnusableBrushesAndGrids) {
  auto engine = makeEngine(makeEmptyMaterialSet(kBase, 0.5, "mm"));
  Brush b = makeBrush(BrushChannel::Preset, BrushMode::Add, 1.0, BrushFalloff::Smooth, 1.0);
  EXPECT_THROW(engine->beginStroke(b), InputError);
  b.mode = BrushMode::Set;
  b.preset = "plutonium";
  EXPECT_THROW(engine->beginStroke(b), InputError);
  Brush huge = makeBrush(BrushChannel::All, BrushMode::Erase, 1e6, BrushFalloff::Smooth, 1.0);
  EXPECT_THROW(engine->applyStroke({huge, {glm::dvec3(0.0)}, {}}), InputError);  // 2^26-voxel dab limit
  auto skewed = makeEmptyMaterialSet(kBase, 0.5, "mm");
  skewed->sigmaS->setTransform(openvdb::math::Transform::createLinearTransform(0.25));
  EXPECT_THROW(makeEngine(skewed), InputError);
}

// --- stroke files --------------------------------------------------------------------

TEST(StrokeIo, FormatThenParseGivesTheSameStrokes) {
  Brush a = makeBrush(BrushChannel::AlbedoMfp, BrushMode::Set, 0.1 + 1e-15, BrushFalloff::Gaussian, 1.0 / 3.0);
  a.albedo = glm::dvec3(0.1, 0.2, 0.3);
  a.meanFreePath = glm::dvec3(1.0 / 7.0, 2, 3);
  a.mirror = BrushMirror{2, 0.125};
  Brush b = makeBrush(BrushChannel::All, BrushMode::Smooth, 2, BrushFalloff::Linear, 0.5);
  b.depth = 0.75;
  Brush c = makeBrush(BrushChannel::Colour, BrushMode::Set, 1, BrushFalloff::Smooth, 1);
  c.artist = {glm::dvec3(0.1, 1.0 / 3.0, 0.9), glm::dvec3(0.25, 2, 1e-3), -0.3};
  const std::vector<Stroke> strokes = {{a, {glm::dvec3(1, 2, 3), glm::dvec3(0.1, -0.2, 1e-9)}, {}},
                                       {b, {}, {{glm::dvec3(0, 0, 5), glm::dvec3(0, 0.1, -1)}}},
                                       {c, {glm::dvec3(0.5)}, {}}};
  const std::vector<Stroke> back = parseStrokes(formatStrokes(strokes), "round.json");
  ASSERT_EQ(back.size(), 3u);
  EXPECT_EQ(back[2].brush.channel, BrushChannel::Colour);
  EXPECT_EQ(back[2].brush.mode, BrushMode::Set);
  EXPECT_EQ(back[2].brush.artist.colour, c.artist.colour);
  EXPECT_EQ(back[2].brush.artist.scatterDistance, c.artist.scatterDistance);
  EXPECT_EQ(back[2].brush.artist.g, -0.3);
  EXPECT_EQ(back[0].brush.radius, a.radius);
  EXPECT_EQ(back[0].brush.strength, a.strength);
  EXPECT_EQ(back[0].brush.meanFreePath, a.meanFreePath);
  EXPECT_EQ(back[0].brush.mirror->axis, 2);
  EXPECT_EQ(*back[0].brush.mirror->at, 0.125);
  EXPECT_EQ(back[0].points, strokes[0].points);
  EXPECT_EQ(back[1].brush.channel, BrushChannel::All);
  EXPECT_EQ(back[1].brush.depth, 0.75);
  EXPECT_EQ(back[1].rays[0].direction, strokes[1].rays[0].direction);
}

TEST(StrokeIo, ErrorsNameTheFileAndKeyPath) {
  const std::string good = R"({"channel": "g", "mode": "set", "value": 0.5, "radius": 1, "points": [[0,0,0]]})";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {R"({"strokes": [)" + good + R"(, {"mode": "erase", "radius": 1, "radiuss": 2, "points": [[0,0,0]]}]})",
       "s.json: strokes[1].radiuss: unknown key"},
      {R"({"strokes": [{"mode": "erase", "radius": "big", "points": [[0,0,0]]}]})",
       "s.json: strokes[0].radius: expected a number"},
      {R"({"strokes": [{"mode": "erase", "radius": 0, "points": [[0,0,0]]}]})",
       "s.json: strokes[0].radius: must be positive"},
      {R"({"strokes": [{"channel": "preset", "mode": "set", "value": "jade", "radius": 1, "points": [[0,0,0]]}]})",
       "s.json: strokes[0].value: unknown preset \"jade\""},
      {R"({"strokes": [{"mode": "erase", "radius": 1, "points": [[0, NaN, 0]]}]})",
       "s.json: strokes[0].points[0][1]: malformed JSON"},
      {R"({"strokes": [{"mode": "erase", "radius": 1, "radius": 2, "points": [[0,0,0]]}]})",
       "s.json: strokes[0].radius: duplicate key"},
      {R"({"strokes": [{"mode": "erase", "value": 1, "radius": 1, "points": [[0,0,0]]}]})",
       "s.json: strokes[0].value: not used by mode"},
      {R"({"strokes": [{"channel": "g", "mode": "set", "value": 1.5, "radius": 1, "points": [[0,0,0]]}]})",
       "s.json: strokes[0].value: g must be"},
      {R"({"strokes": [{"mode": "erase", "radius": 1, "points": [[0,0,0]], "rays": []}]})",
       "s.json: strokes[0]: expected exactly one"},
      {R"({"strokes": [{"mode": "erase", "radius": 1, "rays": [{"origin": [0,0,0], "direction": [0,0,0]}]}]})",
       "s.json: strokes[0].rays[0].direction: must be a non-zero vector"},
      {R"({"strokes": [{"channel": "sigma_t", "mode": "add", "radius": 1, "points": [[0,0,0]]}]})",
       "missing required key \"value\""},
      {R"({"strokes": [{"channel": "albedo_mfp", "mode": "set", "value": {"albedo": 2, "mean_free_path": 1}, "radius": 1, "points": [[0,0,0]]}]})",
       "s.json: strokes[0].value.albedo: must be in [0, 1]"},
  };
  for (const auto& [text, expected] : cases) {
    try {
      parseStrokes(text, "s.json");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what() << "\nexpected: " << expected;
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    }
  }
}

}  // namespace
}  // namespace sslpv
