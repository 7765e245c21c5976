// Procedural deformers (volume/scene/deform.h): exact inverses, keyframes, the scene key's
// strict parsing, and the material following the deformed object through the inverse.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>
#include <random>
#include <string>

#include "seeded_draws.h"
#include "volume/cpu/cpu_renderer.h"
#include "volume/scene/deform.h"
#include "volume/core/error.h"
#include "volume/lpv/lpv_grid.h"
#include "volume/material/material_field.h"
#include "volume/scene/scene.h"
#include "volume/material/scene_object.h"
#include "volume/lpv/voxelize_parity.h"
#include "volume/lpv/resample.h"

namespace sslpv {
namespace {

/// A 2 x 0.5 x 0.5 bar along x from the origin, 40 segments along its length so it bends.
std::string barScene(const std::string& deformers, const std::string& extra = "") {
  return R"({
    "mesh": {"primitive": "box", "min": [0, -0.25, -0.25], "max": [2, 0.25, 0.25], "segments": [40, 4, 4]},
    "material": {"base": {"sigma_t": 1, "sigma_s": 0.5}},
    "lights": [{"type": "directional", "direction": [0, -1, -0.3], "irradiance": 1}],
    "camera": {"position": [1, 0.5, 6], "target": [1, 0.5, 0], "fov_y_deg": 40, "width": 40, "height": 40},
    "lpv": {"resolution": 16, "steps": "auto"})" +
         extra + R"(,
    "deformers": )" + deformers + "}";
}

const char* kBend90 =
    R"([{"type": "bend", "axis": "x", "toward": "y", "length": 2,
         "angle": [{"t": 0, "value": 0}, {"t": 1, "value": 90, "ease": "smoothstep"}]}])";

/// σt 20 in the bar's last fifth (x from 1.6 on, rest space), base elsewhere.
std::shared_ptr<MaterialSet> stripeSet() {
  initializeOpenVdb();
  auto set = std::make_shared<MaterialSet>();
  const double voxel = 0.05;
  for (auto* grid : {&set->sigmaT, &set->sigmaS}) {
    *grid = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    (*grid)->setTransform(openvdb::math::Transform::createLinearTransform(voxel));
  }
  auto accessor = set->sigmaT->getAccessor();
  // Voxel centres i * voxel: x from 1.6 to 2.1, y and z beyond the bar's half width.
  for (int x = 32; x <= 42; ++x)
    for (int y = -7; y <= 7; ++y)
      for (int z = -7; z <= 7; ++z) accessor.setValue(openvdb::Coord(x, y, z), openvdb::Vec3s(20.0f));
  return set;
}

PosedDeformer posed(Deformer::Type type, int axis, int toward, double k, const glm::dvec3& center) {
  PosedDeformer d;
  d.type = type;
  d.axis = axis;
  d.toward = toward;
  d.k = k;
  d.center = center;
  return d;
}

TEST(Deformers, InverseUndoesForwardForEveryTypeAndAxis) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int checked = 0;
  for (Deformer::Type type :
       {Deformer::Type::Bend, Deformer::Type::Twist, Deformer::Type::Taper, Deformer::Type::SquashStretch}) {
    for (int axis = 0; axis < 3; ++axis)
      for (int trial = 0; trial < 40; ++trial) {
        const int toward = (axis + 1 + (trial % 2)) % 3;
        const glm::dvec3 center = test::drawVec3<glm::dvec3>(unit, rng);
        double k = 0.0;
        switch (type) {
          case Deformer::Type::Bend: k = 0.6 * unit(rng); break;  // rad per unit: |k v| < 1 within 1.5
          case Deformer::Type::Twist: k = 6.0 * unit(rng); break;
          case Deformer::Type::Taper: k = 0.5 * unit(rng); break;     // scale stays above 0.25
          case Deformer::Type::SquashStretch: k = std::exp(1.5 * unit(rng)); break;
        }
        const PosedDeformer d = posed(type, axis, toward, k, center);
        const glm::dvec3 p = center + 1.5 * test::drawVec3<glm::dvec3>(unit, rng);
        ASSERT_TRUE(d.outsideDomain(p).empty()) << d.outsideDomain(p);
        const glm::dvec3 q = d.forward(p);
        const glm::dvec3 back = d.inverse(q);
        EXPECT_LT(glm::length(back - p), 1e-12 * (1.0 + glm::length(p)))
            << deformerTypeName(type) << " axis " << axis << " k " << k;
        ++checked;
      }
  }
  EXPECT_EQ(checked, 4 * 3 * 40);
}

TEST(Deformers, ForwardMovesPointsWhereTheDefinitionsSay) {
  // A quarter turn of bend over 2 units along x towards y: the axis's end lands on the
  // arc of radius 4/π, a quarter circle from the origin.
  const double k = (M_PI / 2.0) / 2.0;
  const PosedDeformer bend = posed(Deformer::Type::Bend, 0, 1, k, glm::dvec3(0.0));
  const glm::dvec3 end = bend.forward({2.0, 0.0, 0.0});
  EXPECT_NEAR(end.x, 1.0 / k, 1e-12);
  EXPECT_NEAR(end.y, 1.0 / k, 1e-12);
  // Lengths along the axis are kept: the point at arc length 1 is at angle k.
  const glm::dvec3 mid = bend.forward({1.0, 0.0, 0.3});
  EXPECT_NEAR(mid.x, std::sin(k) / k, 1e-12);
  EXPECT_NEAR(mid.y, (1.0 - std::cos(k)) / k, 1e-12);
  EXPECT_EQ(mid.z, 0.3);
  // Twist about z by 90 degrees per unit: a point at z = 1 turns a quarter.
  const glm::dvec3 twisted = posed(Deformer::Type::Twist, 2, 0, M_PI / 2.0, glm::dvec3(0.0)).forward({1.0, 0.0, 1.0});
  EXPECT_NEAR(twisted.x, 0.0, 1e-12);
  EXPECT_NEAR(twisted.y, 1.0, 1e-12);
  // Squash-stretch keeps the volume: the Jacobian's determinant is f · (1/√f)² = 1.
  const PosedDeformer squash = posed(Deformer::Type::SquashStretch, 1, 2, 0.25, glm::dvec3(0.0));
  const glm::dvec3 s = squash.forward({1.0, 1.0, 1.0});
  EXPECT_NEAR(s.x * s.y * s.z, 1.0, 1e-12);
  EXPECT_NEAR(s.y, 0.25, 1e-12);
}

TEST(Deformers, TinyBendsLoseNoPrecision) {
  const PosedDeformer bend = posed(Deformer::Type::Bend, 1, 2, 1e-14, glm::dvec3(0.0));
  const glm::dvec3 p(0.3, 0.7, -0.2);
  EXPECT_LT(glm::length(bend.forward(p) - p), 1e-13);
  EXPECT_LT(glm::length(bend.inverse(bend.forward(p)) - p), 1e-15);
}

TEST(Deformers, AStackInvertsInReverseOrder) {
  Scene scene = parseScene(barScene(R"([
      {"type": "twist", "axis": "x", "center": [1, 0, 0], "angle": 60},
      {"type": "taper", "axis": "x", "amount": -0.3, "length": 2},
      {"type": "bend", "axis": "x", "angle": 70, "length": 2},
      {"type": "squash_stretch", "axis": "y", "center": [1, 0, 0], "factor": 0.6}])"),
                           "stack.json");
  const DeformationPose pose(scene.deformers, 0.0);
  ASSERT_EQ(pose.stages().size(), 4u);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> along(0.0, 2.0), across(-0.25, 0.25);
  for (int i = 0; i < 200; ++i) {
    const glm::dvec3 p = test::drawVec3<glm::dvec3>(along, across, across, rng);
    EXPECT_LT(glm::length(pose.inverse(pose.forward(p)) - p), 1e-12);
  }
}

TEST(Deformers, KeyframesInterpolateLinearlyOrSmoothly) {
  AnimatedValue v;
  v.keys = {{0.0, 0.0, Ease::Linear}, {1.0, 10.0, Ease::Linear}, {3.0, 30.0, Ease::Smoothstep}};
  EXPECT_EQ(v.at(-5.0), 0.0);
  EXPECT_DOUBLE_EQ(v.at(0.25), 2.5);
  // Smoothstep at a quarter of its segment: 3/16 - 2/64 = 0.15625 of the way.
  EXPECT_DOUBLE_EQ(v.at(1.5), 10.0 + 20.0 * 0.15625);
  EXPECT_EQ(v.at(3.0), 30.0);
  EXPECT_EQ(v.at(100.0), 30.0);
}

void expectRejected(const std::string& deformers, const std::string& expected) {
  try {
    parseScene(barScene(deformers), "bad.json");
    ADD_FAILURE() << "accepted: " << deformers;
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(expected), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

TEST(Deformers, ParserErrorsNameTheKeyPath) {
  expectRejected(R"({"type": "bend"})", "bad.json: deformers: expected an array");
  expectRejected(R"([{"type": "bend", "angle": 1, "angel": 2}])", "deformers[0].angel: unknown key");
  expectRejected(R"([{"type": "wobble", "angle": 1}])", "deformers[0].type: unknown deformer type \"wobble\"");
  expectRejected(R"([{"type": "bend"}])", "deformers[0]");
  expectRejected(R"([{"type": "twist", "angle": 1}, {"type": "bend", "angle": [{"t": 0, "value": 0}, {"t": "1", "value": 9}]}])",
                 "deformers[1].angle[1].t");
  expectRejected(R"([{"type": "bend", "angle": [{"t": 1, "value": 0}, {"t": 1, "value": 9}]}])",
                 "deformers[0].angle[1].t: must exceed the previous keyframe's t");
  expectRejected(R"([{"type": "bend", "angle": [{"t": 0, "value": 0, "ease": "cubic"}]}])",
                 "deformers[0].angle[0].ease: unknown ease \"cubic\"");
  expectRejected(R"([{"type": "bend", "angle": []}])", "deformers[0].angle: expected a number or a non-empty array");
  expectRejected(R"([{"type": "squash_stretch", "factor": 0}])", "deformers[0].factor: must be in [0.001, 1000]");
  expectRejected(R"([{"type": "bend", "axis": "x", "toward": "x", "angle": 5}])",
                 "deformers[0].toward: must differ from the deformer's axis");
  expectRejected(R"([{"type": "taper", "axis": "w", "amount": 1}])", "deformers[0].axis: unknown axis \"w\"");
  expectRejected(R"([{"type": "twist", "angle": 5, "length": 0}])", "deformers[0].length: must be in");
  expectRejected(R"([{"type": "twist", "angle": 5, "center": [0, 1e9, 0]}])", "deformers[0].center[1]");
  expectRejected(R"([{"type": "squash_stretch", "factor": 2, "length": 1}])", "deformers[0].length: unknown key");
}

TEST(Deformers, AFoldingPoseIsAnInputErrorNamingTheDeformer) {
  Scene scene = parseScene(barScene(R"([{"type": "taper", "axis": "x", "amount": 0.1},
                                       {"type": "bend", "axis": "x", "length": 2, "angle": [{"t": 0, "value": 0}, {"t": 1, "value": 400}]}])"),
                           "fold.json");
  EXPECT_NO_THROW(SceneObject{sceneAtTime(scene, 0.2)});
  try {
    SceneObject object(sceneAtTime(scene, 1.0));
    ADD_FAILURE() << "a 400 degree bend over the bar was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("fold.json: deformers[1]: at t = 1 the bend bends"), std::string::npos)
        << e.what();
  }
  // setTime leaves the object as it was when the pose is refused.
  SceneObject object(sceneAtTime(scene, 0.2));
  const Bounds before = object.bounds();
  EXPECT_THROW(object.setTime(1.0), InputError);
  EXPECT_EQ(object.bounds().max, before.max);
  EXPECT_THROW(sceneAtTime(scene, std::nan("")), InputError);
}

// The point of the inverse: a stripe painted on one end of the bar stays on that end when
// the bar bends up a quarter turn, instead of staying where the end used to be.
TEST(Deformers, APaintedStripeFollowsTheBentEnd) {
  const Scene scene = sceneAtTime(parseScene(barScene(kBend90), "bar.json"), 1.0);
  SceneObject object(scene);
  object.setMaterialSet(stripeSet());
  MaterialGrid material;
  material.frame = makeGridFrame(object.bounds(), 48);
  material.coverage = voxelizeCoverageParity(object.mesh(), material.frame);
  resampleMaterial(object.field(), material);

  const DeformationPose pose(scene.deformers, 1.0);
  int stripeCells = 0, baseCells = 0;
  const GridFrame& f = material.frame;
  for (int z = 0; z < f.dims.z; ++z)
    for (int y = 0; y < f.dims.y; ++y)
      for (int x = 0; x < f.dims.x; ++x) {
        const std::size_t i = f.index(x, y, z);
        if (material.coverage[i] < 1.0f) continue;  // wholly inside the bent bar
        const glm::dvec3 world = f.cellCenter(x, y, z);
        const glm::dvec3 rest = pose.inverse(world);
        if (rest.x > 1.7 && rest.x < 1.95) {
          ++stripeCells;
          EXPECT_NEAR(material.sigmaT[i].x, 20.0f, 0.01f) << "rest x " << rest.x;
          // Where the end went: a quarter turn up, far from where the straight bar's end was.
          EXPECT_GT(world.y, 0.6);
        } else if (rest.x < 1.45) {
          ++baseCells;
          EXPECT_NEAR(material.sigmaT[i].x, 1.0f, 0.01f) << "rest x " << rest.x;
        }
      }
  EXPECT_GT(stripeCells, 20);
  EXPECT_GT(baseCells, 200);
  // The straight bar's stripe position is outside the bent bar: nothing is read there.
  const MaterialField::Sampler sampler = object.field().sampler();
  EXPECT_NEAR(sampler.sample(pose.forward({1.8, 0.1, 0.05})).sigmaT.x, 20.0f, 1e-4f);
  EXPECT_NEAR(sampler.sample(pose.forward({0.8, 0.1, 0.05})).sigmaT.x, 1.0f, 1e-4f);
}

TEST(Deformers, AnEmptyListIsTheStaticScene) {
  const std::string json = barScene("[]");
  Scene withKey = parseScene(json, "a.json");
  EXPECT_TRUE(withKey.deformers.empty());
  CpuRenderer a(withKey);
  Scene plain = withKey;
  plain.time = 0.7;  // ignored without deformers
  CpuRenderer b(plain);
  b.setTime(0.3);
  const Image ia = a.render(withKey.lpv), ib = b.render(plain.lpv);
  ASSERT_EQ(ia.pixels.size(), ib.pixels.size());
  EXPECT_TRUE(ia.pixels == ib.pixels);
}

// setTime re-voxelizes and resamples: after it, a frame equals a fresh renderer's at that time.
TEST(Deformers, SetTimeRendersWhatAFreshRendererRenders) {
  const Scene scene = parseScene(barScene(kBend90), "bar.json");
  CpuRenderer moving(sceneAtTime(scene, 0.0));
  moving.setMaterialSet(stripeSet(), std::nullopt);
  moving.render(scene.lpv);
  moving.setTime(0.5);
  RenderReport report;
  const Image animated = moving.render(scene.lpv, &report);
  EXPECT_FALSE(report.times.cached(Stage::Voxelize));
  EXPECT_FALSE(report.times.cached(Stage::Resample));

  CpuRenderer fresh(sceneAtTime(scene, 0.5));
  fresh.setMaterialSet(stripeSet(), std::nullopt);
  RenderReport freshReport;
  const Image expected = fresh.render(scene.lpv, &freshReport);
  // The grid is fitted to the animation's span, not to each pose, so both renderers use
  // the same frame, and the moving one starts from the straight bar's light (warm start):
  // it converges to the same light within the stop rule's 1e-2 per shaded cell.
  EXPECT_EQ(report.frame.dims, freshReport.frame.dims);
  EXPECT_EQ(report.frame.origin, freshReport.frame.origin);
  EXPECT_EQ(report.frame.cellSize, freshReport.frame.cellSize);
  EXPECT_TRUE(report.propagation.warmStarted);
  ASSERT_EQ(animated.pixels.size(), expected.pixels.size());
  double worst = 0.0, peak = 0.0;
  for (std::size_t i = 0; i < expected.pixels.size(); ++i) {
    worst = std::max(worst, double(glm::length(animated.pixels[i] - expected.pixels[i])));
    peak = std::max(peak, double(glm::length(expected.pixels[i])));
  }
  EXPECT_GT(peak, 0.0);
  EXPECT_LE(worst, 1e-2 * peak);
}

}  // namespace
}  // namespace sslpv
