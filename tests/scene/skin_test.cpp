// Skinned animation from glTF (volume/scene/skin.h): keyframes, the import through the
// reader child, linear blend skinning, the blended inverse that brings the painted
// material along, and the scene key's errors. The rig is written at run time.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <random>
#include <string>

#include "skinned_rig.h"
#include "test_support.h"
#include "volume/core/error.h"
#include "volume/cpu/cpu_renderer.h"
#include "volume/lpv/lpv_grid.h"
#include "volume/lpv/resample.h"
#include "volume/lpv/voxelize_parity.h"
#include "volume/material/material_field.h"
#include "volume/material/scene_object.h"
#include "volume/scene/scene.h"
#include "volume/scene/skin.h"

namespace sslpv {
namespace {

using test::kBarWidth;

class Skinning : public ::testing::Test {
 protected:
  void SetUp() override { test::writeText(barFile(), writeGltf(test::bendingBarRig())); }
  std::filesystem::path barFile() const { return dir_ / "bar.gltf"; }
  Scene scene(const std::string& animation, double t) const {
    return sceneAtTime(parseScene(test::skinnedBarScene(barFile().string(), animation), dir_ / "bar.json"), t);
  }
  test::TempDir dir_;
};

/// The tip joint's pivot and what the Bend clip does to a rest point fully weighted to it.
const glm::dvec3 kPivot(2.0 * test::kJointSpan, 0.0, 0.0);
glm::dvec3 turnedAboutPivot(const glm::dvec3& p, double degrees) {
  return glm::dvec3(glm::rotate(glm::dmat4(1.0), glm::radians(degrees), glm::dvec3(0, 0, 1)) * glm::dvec4(p - kPivot, 1.0)) +
         kPivot;
}

/// σt 20 in x from 1.6 to 2.1 of the rest bar (the tip joint's rigid part), base elsewhere.
std::shared_ptr<MaterialSet> tipStripe() {
  initializeOpenVdb();
  auto set = std::make_shared<MaterialSet>();
  for (auto* grid : {&set->sigmaT, &set->sigmaS}) {
    *grid = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    (*grid)->setTransform(openvdb::math::Transform::createLinearTransform(0.05));
  }
  auto accessor = set->sigmaT->getAccessor();
  for (int x = 32; x <= 42; ++x)
    for (int y = -7; y <= 7; ++y)
      for (int z = -7; z <= 7; ++z) accessor.setValue(openvdb::Coord(x, y, z), openvdb::Vec3s(20.0f));
  return set;
}

TEST(SkinTracks, KeysHoldAtTheKeysAndInterpolateBetween) {
  Vec3Track move;
  move.times = {0.0, 1.0, 3.0};
  move.values = {{0, 0, 0}, {2, 0, 0}, {2, 4, 0}};
  EXPECT_EQ(move.at(-1.0, {}), glm::dvec3(0.0));
  EXPECT_EQ(move.at(1.0, {}), glm::dvec3(2, 0, 0));
  EXPECT_EQ(move.at(0.25, {}), glm::dvec3(0.5, 0, 0));
  EXPECT_EQ(move.at(2.0, {}), glm::dvec3(2, 2, 0));
  EXPECT_EQ(move.at(9.0, {}), glm::dvec3(2, 4, 0));
  EXPECT_EQ(Vec3Track{}.at(0.5, {7, 8, 9}), glm::dvec3(7, 8, 9));

  // Slerp: a quarter of the way from 0 to 120 degrees about z is 30 degrees, at constant
  // angular speed (a normalised lerp would give about 26).
  RotationTrack turn;
  turn.times = {0.0, 1.0};
  turn.values = {glm::angleAxis(0.0, glm::dvec3(0, 0, 1)), glm::angleAxis(glm::radians(120.0), glm::dvec3(0, 0, 1))};
  EXPECT_NEAR(glm::degrees(glm::angle(turn.at(0.25, {}))), 30.0, 1e-9);
  EXPECT_NEAR(glm::degrees(glm::angle(turn.at(1.0, {}))), 120.0, 1e-9);
  // q and -q are one rotation: the interpolation takes the short way, not 350 degrees.
  turn.values[1] = -glm::angleAxis(glm::radians(20.0), glm::dvec3(0, 0, 1));
  EXPECT_NEAR(glm::degrees(glm::angle(turn.at(0.5, {}))), 10.0, 1e-9);
}

TEST_F(Skinning, TheReaderChildReturnsTheRigAndClipsInSeconds) {
  const SkinnedMesh mesh = loadSkinnedMesh(barFile());
  EXPECT_EQ(mesh.rest.positions.size(), mesh.skin.influences.size());
  ASSERT_EQ(mesh.skin.joints.size(), 3u);
  ASSERT_EQ(mesh.skin.clips.size(), 2u);
  EXPECT_EQ(mesh.skin.clips[0].name, "Idle");
  EXPECT_EQ(mesh.skin.clips[1].name, "Bend");
  // Key times come back in seconds whatever the importer's ticks are.
  EXPECT_NEAR(mesh.skin.clips[1].start(), 0.0, 1e-9);
  EXPECT_NEAR(mesh.skin.clips[1].end(), 1.0, 1e-6);
  for (const SkinInfluence& in : mesh.skin.influences)
    EXPECT_NEAR(in.weights[0] + in.weights[1] + in.weights[2] + in.weights[3], 1.0f, 1e-6f);
  // The bind pose: every joint matrix is the identity up to float inverse bind matrices.
  for (const glm::dmat4& m : jointMatrices(mesh.skin, &mesh.skin.clips[1], 0.0))
    for (int c = 0; c < 4; ++c) EXPECT_LT(glm::length(m[c] - glm::dmat4(1.0)[c]), 1e-6);
}

TEST_F(Skinning, AVertexOnOneJointMovesByThatJointsTransform) {
  const SkinnedMesh mesh = loadSkinnedMesh(barFile());
  const auto grid = std::make_shared<const PointGrid>(
      std::vector<glm::dvec3>(mesh.rest.positions.begin(), mesh.rest.positions.end()));
  for (double t : {0.5, 1.0}) {
    const SkinPose pose(mesh, grid, &mesh.skin.clips[1], t);
    const std::vector<glm::dmat4> joints = jointMatrices(mesh.skin, &mesh.skin.clips[1], t);
    int tipVertices = 0;
    for (std::size_t v = 0; v < mesh.rest.positions.size(); ++v) {
      const SkinInfluence& in = mesh.skin.influences[v];
      if (in.weights[0] != 1.0f) continue;
      const glm::dvec3 rest(mesh.rest.positions[v]);
      const glm::dvec3 expected(joints[in.joints[0]] * glm::dvec4(rest, 1.0));
      EXPECT_LT(glm::length(pose.posedVertices()[v] - expected), 1e-9);
      if (in.joints[0] == 2) {
        ++tipVertices;
        // ... and that transform is the clip's turn about the joint, slerped at t = 0.5.
        EXPECT_LT(glm::length(pose.posedVertices()[v] - turnedAboutPivot(rest, 90.0 * t)), 1e-5) << "t " << t;
      }
    }
    EXPECT_GT(tipVertices, 40);
  }
}

TEST(SkinGrid, NearestPointsMatchABruteForceSearch) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<glm::dvec3> points;
  for (int i = 0; i < 500; ++i) points.emplace_back(u(rng), 0.2 * u(rng), 3.0 * u(rng));
  const PointGrid grid(points);
  for (int trial = 0; trial < 200; ++trial) {
    const glm::dvec3 q(1.5 * u(rng), u(rng), 4.0 * u(rng));  // some outside the points' box
    std::uint32_t index[8];
    double d2[8];
    ASSERT_EQ(grid.nearest(q, 8, index, d2), 8);
    std::vector<double> all;
    for (const glm::dvec3& p : points) all.push_back(glm::dot(p - q, p - q));
    std::sort(all.begin(), all.end());
    for (int k = 0; k < 8; ++k) EXPECT_DOUBLE_EQ(d2[k], all[std::size_t(k)]);
  }
}

// The accuracy figure of docs/accuracy.md: interior points of the bar bent a quarter turn
// at its tip joint, forward then inverse, as a fraction of the bar's width.
TEST_F(Skinning, TheBlendedInverseUndoesTheForwardMapInsideTheBar) {
  const SkinnedMesh mesh = loadSkinnedMesh(barFile());
  const auto grid = std::make_shared<const PointGrid>(
      std::vector<glm::dvec3>(mesh.rest.positions.begin(), mesh.rest.positions.end()));
  const SkinPose pose(mesh, grid, &mesh.skin.clips[1], 1.0);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> along(0.0, test::kBarLength), across(-0.4 * kBarWidth, 0.4 * kBarWidth);
  double worst = 0.0, sum = 0.0, worstOneStep = 0.0, sumOneStep = 0.0, worstRigid = 0.0;
  constexpr int kPoints = 4000;
  for (int i = 0; i < kPoints; ++i) {
    const glm::dvec3 p(along(rng), across(rng), across(rng));
    const glm::dvec3 q = pose.forward(p);
    const double error = glm::length(pose.inverse(q) - p) / kBarWidth;
    const double oneStep = glm::length(pose.blendedInverse(q) - p) / kBarWidth;
    worst = std::max(worst, error);
    sum += error;
    worstOneStep = std::max(worstOneStep, oneStep);
    sumOneStep += oneStep;
    // Where every neighbour, rest or posed, moves with one bone, even the one step is exact.
    if (std::abs(p.x - kPivot.x) > test::kBlend + 0.35) worstRigid = std::max(worstRigid, oneStep);
  }
  std::printf("skinned bar, 90 degree bend, round-trip error / width: one-step blend mean %.3g max %.3g; "
              "refined mean %.3g max %.3g; rigid parts (one step) max %.3g\n",
              sumOneStep / kPoints, worstOneStep, sum / kPoints, worst, worstRigid);
  EXPECT_LT(worstRigid, 1e-6);
  // Left over: points whose forward map is not one-to-one, where the inner side of the
  // bend crowds the two bones' vertices together (docs/accuracy.md has the figures).
  EXPECT_LT(sum / kPoints, 2e-3);
  EXPECT_LT(worst, 0.2);
  EXPECT_GT(sumOneStep, 10.0 * sum) << "the refinement should matter: is the test still bending the bar?";
  // A vertex maps exactly both ways.
  const glm::dvec3 corner(test::kBarLength, 0.5 * kBarWidth, 0.5 * kBarWidth);
  EXPECT_LT(glm::length(pose.forward(corner) - turnedAboutPivot(corner, 90.0)), 1e-5);
}

// The point of the inverse: a stripe painted on the bar's tip in rest space is read where
// the tip went, not where it was.
TEST_F(Skinning, APaintedStripeFollowsTheBentTip) {
  const Scene bent = scene("\"Bend\"", 1.0);
  SceneObject object(bent);
  object.setMaterialSet(tipStripe());
  ASSERT_TRUE(object.pose());
  const SpaceDeformation& pose = *object.pose();
  const MaterialField::Sampler sampler = object.field().sampler();
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> across(-0.2, 0.2);
  for (int i = 0; i < 200; ++i) {
    const double x = 1.7 + 0.25 * (i / 200.0);
    const glm::dvec3 rest(x, across(rng), across(rng));
    const glm::dvec3 world = pose.forward(rest);
    EXPECT_GT(world.y, 0.3) << "the tip did not lift";
    EXPECT_NEAR(sampler.sample(world).sigmaT.x, 20.0f, 1e-3f) << "rest x " << x;
    // Where the tip was: now outside the bar, and no stripe is read there either.
    const glm::dvec3 offBar = pose.forward({0.3 + 0.6 * (i / 200.0), rest.y, rest.z});
    EXPECT_NEAR(sampler.sample(offBar).sigmaT.x, 1.0f, 1e-3f);
  }
  // The resampled lattice agrees: cells inside the bent bar whose rest point is in the
  // stripe carry it, the rest the base.
  MaterialGrid material;
  material.frame = makeGridFrame(object.bounds(), 40);
  material.coverage = voxelizeCoverageParity(object.mesh(), material.frame);
  resampleMaterial(object.field(), material);
  int stripe = 0, base = 0;
  const GridFrame& f = material.frame;
  for (int z = 0; z < f.dims.z; ++z)
    for (int y = 0; y < f.dims.y; ++y)
      for (int x = 0; x < f.dims.x; ++x) {
        const std::size_t i = f.index(x, y, z);
        if (material.coverage[i] < 1.0f) continue;
        const glm::dvec3 rest = pose.inverse(f.cellCenter(x, y, z));
        if (rest.x > 1.7 && rest.x < 1.95) {
          ++stripe;
          EXPECT_NEAR(material.sigmaT[i].x, 20.0f, 0.05f) << "rest x " << rest.x;
        } else if (rest.x < 1.0) {
          ++base;
          EXPECT_NEAR(material.sigmaT[i].x, 1.0f, 0.05f) << "rest x " << rest.x;
        }
      }
  EXPECT_GT(stripe, 10);
  EXPECT_GT(base, 100);
}

TEST_F(Skinning, TheGridSpansEveryPoseAndSetTimeReposes) {
  SceneObject object(scene("1", 0.0));
  ASSERT_TRUE(object.deformed());
  const Bounds straight = object.bounds();
  object.setTime(1.0);
  const Bounds bent = object.bounds();
  EXPECT_GT(bent.max.y, straight.max.y + 0.3);
  for (const Bounds& b : {straight, bent}) {
    EXPECT_TRUE(glm::all(glm::lessThanEqual(object.gridBounds().min, b.min + 1e-6)));
    EXPECT_TRUE(glm::all(glm::greaterThanEqual(object.gridBounds().max, b.max - 1e-6)));
  }
  // The clip by index is the clip by name.
  SceneObject byName(scene("\"Bend\"", 1.0));
  EXPECT_EQ(byName.mesh().positions, object.mesh().positions);
}

// The renderer re-poses through setTime like a deformed scene: same grid as a fresh
// renderer at that time, warm-started from the last frame's light, the same image within
// the stop rule.
TEST_F(Skinning, SetTimeRendersWhatAFreshRendererRenders) {
  const Scene start = scene("\"Bend\"", 0.0);
  CpuRenderer moving(start);
  moving.setMaterialSet(tipStripe(), std::nullopt);
  moving.render(start.lpv);
  moving.setTime(0.6);
  RenderReport report;
  const Image animated = moving.render(start.lpv, &report);
  CpuRenderer fresh(scene("\"Bend\"", 0.6));
  fresh.setMaterialSet(tipStripe(), std::nullopt);
  RenderReport freshReport;
  const Image expected = fresh.render(start.lpv, &freshReport);
  EXPECT_EQ(report.frame.dims, freshReport.frame.dims);
  EXPECT_EQ(report.frame.origin, freshReport.frame.origin);
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

void expectOneLine(const std::function<void()>& load, const std::vector<std::string>& needles) {
  try {
    load();
    ADD_FAILURE() << "accepted; expected an error with: " << needles.front();
  } catch (const InputError& e) {
    const std::string message = e.what();
    for (const std::string& needle : needles) EXPECT_NE(message.find(needle), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

TEST_F(Skinning, BadClipsAndKeysAreOneLineErrorsNamingTheFileAndKey) {
  expectOneLine([&] { SceneObject{scene("\"Wave\"", 0.0)}; },
                {"bar.json: mesh.animation: ", "bar.gltf: animation 'Wave' not found (clips: Idle, Bend)"});
  expectOneLine([&] { SceneObject{scene("7", 0.0)}; }, {"mesh.animation", "animation 7 not found (2 clips: Idle, Bend)"});
  // A mesh without a skin has nothing to play.
  GltfRig plain = test::bendingBarRig();
  plain.vertexJoints.clear();
  plain.vertexWeights.clear();
  test::writeText(dir_ / "plain.gltf", writeGltf(plain));
  expectOneLine(
      [&] {
        SceneObject{parseScene(test::skinnedBarScene((dir_ / "plain.gltf").string(), "\"Bend\""), dir_ / "p.json")};
      },
      {"p.json: mesh.animation: ", "plain.gltf: the mesh has no skin"});
  const std::string gltf = barFile().string();
  expectOneLine([&] { parseScene(test::skinnedBarScene(gltf, "\"\""), "s.json"); }, {"s.json: mesh.animation: "});
  expectOneLine([&] { parseScene(test::skinnedBarScene(gltf, "-1"), "s.json"); }, {"s.json: mesh.animation: "});
  expectOneLine([&] { parseScene(test::skinnedBarScene(gltf, "[1]"), "s.json"); }, {"s.json: mesh.animation: expected"});
  expectOneLine(
      [&] {
        parseScene(R"({"mesh": {"primitive": "sphere", "center": [0, 0, 0], "radius": 1, "animation": 0},
            "material": {"base": {"sigma_t": 1, "sigma_s": 0.5}}, "lights": [{"type": "directional",
            "direction": [0, -1, 0], "irradiance": 1}], "camera": {"position": [0, 0, 5], "target": [0, 0, 0]}})",
                   "s.json");
      },
      {"s.json: mesh.animation: unknown key"});
  // A clip that scales the root joint to nothing flattens the whole bar: refused by time.
  GltfRig vanishing = test::bendingBarRig();
  GltfRig::Channel shrink{0, "scale", {0.0, 1.0}, {}};
  // Pushed one by one: GCC 12.2 at -O3 with AVX-512 (SSLPV_NATIVE on this machine) builds
  // a braced list {dvec4(1.0), dvec4(0.0)} as two copies of the first.
  shrink.values.push_back(glm::dvec4(1.0));
  shrink.values.push_back(glm::dvec4(0.0));
  vanishing.clips = {{"Vanish", {shrink}}};
  test::writeText(dir_ / "vanish.gltf", writeGltf(vanishing));
  const Scene vanish = parseScene(test::skinnedBarScene((dir_ / "vanish.gltf").string(), "\"Vanish\""), dir_ / "v.json");
  EXPECT_NO_THROW(SceneObject{sceneAtTime(vanish, 0.5)});
  expectOneLine([&] { SceneObject{sceneAtTime(vanish, 1.0)}; },
                {"v.json: mesh.animation: at t = 1 the pose of ", "vanish.gltf encloses no volume"});
  // A damaged file through the skinned reader is an error too, not a crash.
  test::writeText(dir_ / "broken.gltf", writeGltf(test::bendingBarRig()).substr(0, 900));
  expectOneLine(
      [&] {
        SceneObject{parseScene(test::skinnedBarScene((dir_ / "broken.gltf").string(), "0"), dir_ / "b.json")};
      },
      {"b.json: mesh.path: ", "broken.gltf"});
}

// Without the key a rigged file is read as any mesh: its rest pose, pixel for pixel the
// image of the same mesh written without a skin.
TEST_F(Skinning, WithoutTheKeyARiggedFileRendersItsRestPoseAsToday) {
  GltfRig plain = test::bendingBarRig();
  plain.vertexJoints.clear();
  plain.vertexWeights.clear();
  test::writeText(dir_ / "plain.gltf", writeGltf(plain));
  const Scene rigged = parseScene(test::skinnedBarScene(barFile().string(), ""), dir_ / "a.json");
  const Scene unrigged = parseScene(test::skinnedBarScene((dir_ / "plain.gltf").string(), ""), dir_ / "b.json");
  EXPECT_FALSE(rigged.animated());
  CpuRenderer a(rigged), b(unrigged);
  const Image ia = a.render(rigged.lpv), ib = b.render(unrigged.lpv);
  ASSERT_EQ(ia.pixels.size(), ib.pixels.size());
  EXPECT_TRUE(ia.pixels == ib.pixels);
  // The skinned path's own rest pose (t = 0 of Bend, all joints at bind) is that mesh too.
  SceneObject rest(scene("\"Bend\"", 0.0));
  SceneObject still(rigged);
  ASSERT_EQ(rest.mesh().positions.size(), still.mesh().positions.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < rest.mesh().positions.size(); ++i)
    worst = std::max(worst, double(glm::length(rest.mesh().positions[i] - still.mesh().positions[i])));
  EXPECT_LT(worst, 1e-5);
}

}  // namespace
}  // namespace sslpv
