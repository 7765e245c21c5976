// `sslpv paint SCENE.json --strokes STROKES.json -o OUT.vdb` end to end: the written set
// equals the brush engine's own result bit for bit and hand-computed values at chosen
// voxels; bad stroke files exit 2 with one line naming the key path and leave an existing
// output untouched.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <set>

#include "editor/brush_engine.h"
#include "editor/stroke_io.h"
#include "test_support.h"
#include "volume/calibration/adding_doubling.h"
#include "volume/material/material_set.h"
#include "volume/scene/scene.h"

namespace sslpv::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using openvdb::Coord;

const std::string kPreexisting = "not a vdb: bytes a failed run must leave untouched\n";

/// Box [-5,5]^3 scaled by 2, rotated 30 degrees about y, moved to (1,2,3): voxel size
/// 10 / 128 = 0.078125 in rest space (exact in binary).
json sceneJson() {
  return json::parse(R"({
    "units": "mm",
    "mesh": {"primitive": "box", "min": [-5, -5, -5], "max": [5, 5, 5]},
    "transform": {"translate": [1, 2, 3], "rotate_deg": [0, 30, 0], "scale": 2},
    "material": {"base": {"sigma_t": [1.0, 1.2, 1.4], "sigma_s": [0.9, 1.0, 1.1], "g": 0.1}},
    "lights": [{"type": "point", "position": [20, 30, 40], "intensity": [1000, 1000, 1000]}],
    "camera": {"position": [0, 10, 40], "target": [0, 0, 0], "fov_y_deg": 35, "width": 64, "height": 64}
  })");
}

json worldPoint(const glm::dmat4& restToWorld, const glm::dvec3& rest) {
  const glm::dvec3 w(restToWorld * glm::dvec4(rest, 1.0));
  return json::array({w.x, w.y, w.z});
}

struct Files {
  TempDir dir;
  fs::path scene = dir / "scene.json", strokes = dir / "strokes.json", output = dir / "out.vdb";
};

bool sameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

template <class GridT>
::testing::AssertionResult sameGrid(const GridT& a, const GridT& b, const char* name) {
  openvdb::CoordBBox box, other;
  a.tree().evalLeafBoundingBox(box);
  if (b.tree().evalLeafBoundingBox(other)) box.expand(other);
  if (a.activeVoxelCount() != b.activeVoxelCount())
    return ::testing::AssertionFailure() << name << ": active voxel counts " << a.activeVoxelCount() << " vs "
                                         << b.activeVoxelCount();
  auto accA = a.getConstAccessor();
  auto accB = b.getConstAccessor();
  for (auto it = box.begin(); it && !box.empty(); ++it) {
    typename GridT::ValueType va, vb;
    const bool onA = accA.probeValue(*it, va), onB = accB.probeValue(*it, vb);
    if (onA != onB || std::memcmp(&va, &vb, sizeof va) != 0)
      return ::testing::AssertionFailure() << name << " voxel " << *it << " differs";
  }
  return ::testing::AssertionSuccess();
}

TEST(PaintCli, WritesExactlyWhatTheEngineComputesAndTheHandExpectedValues) {
  Files f;
  writeText(f.scene, sceneJson().dump());
  const glm::dmat4 restToWorld = loadScene(f.scene).transform.matrix();
  const json strokes = {
      {"strokes",
       {{{"channel", "sigma_t"},
         {"mode", "set"},
         {"value", {4, 5, 6}},
         {"radius", 0.5},
         {"falloff", "constant"},
         {"points", {worldPoint(restToWorld, glm::dvec3(0.0))}}},
        {{"channel", "g"},
         {"mode", "set"},
         {"value", 0.5},
         {"radius", 0.5},
         {"strength", 0.5},
         {"points", {worldPoint(restToWorld, glm::dvec3(1, 0, 0))}}},
        {{"channel", "albedo_mfp"},
         {"mode", "set"},
         {"value", {{"albedo", {0.9, 0.5, 0.2}}, {"mean_free_path", 0.4}}},
         {"radius", 0.6},
         {"falloff", "gaussian"},
         {"mirror", {{"axis", "x"}}},
         {"points", {worldPoint(restToWorld, {2, 1, -1}), worldPoint(restToWorld, {3, 2, 0})}}},
        {{"channel", "sigma_s"},
         {"mode", "add"},
         {"value", 0.3},
         {"radius", 0.4},
         {"depth", 0.5},
         {"rays",
          {{{"origin", {1.2, 20, 3.1}}, {"direction", {0, -1, 0}}},
           {{"origin", {2.0, 20, 3.5}}, {"direction", {0.01, -1, 0}}}}}},
        {{"mode", "smooth"}, {"radius", 0.8}, {"points", {worldPoint(restToWorld, {2.5, 1.5, -0.5})}}},
        {{"mode", "erase"},
         {"radius", 0.3},
         {"falloff", "linear"},
         {"points", {worldPoint(restToWorld, {3, 2, 0})}}}}}};
  writeText(f.strokes, strokes.dump());
  writeText(f.output, kPreexisting);  // a successful run replaces it
  const RunResult run = runSslpv({"paint", f.scene.string(), "--strokes", f.strokes.string(), "-o", f.output.string()});
  ASSERT_EQ(run.exitCode, 0) << run.stderrText;
  EXPECT_NE(run.stdoutText.find("stroke 5:"), std::string::npos) << run.stdoutText;

  // The same strokes through the engine in this process.
  BrushEngine engine(makePaintTarget(loadScene(f.scene)));
  for (const Stroke& stroke : loadStrokes(f.strokes)) EXPECT_GT(engine.applyStroke(stroke).voxelsChanged, 0u);
  const MaterialSet& direct = *engine.materialSet();
  const std::shared_ptr<const MaterialSet> written = loadMaterialSet(f.output);
  EXPECT_EQ(written->units, "mm");
  EXPECT_EQ(written->creator, "sslpv paint");
  EXPECT_TRUE(sameGrid(*written->sigmaT, *direct.sigmaT, "sigma_t"));
  EXPECT_TRUE(sameGrid(*written->sigmaS, *direct.sigmaS, "sigma_s"));
  ASSERT_TRUE(written->g);
  EXPECT_TRUE(sameGrid(*written->g, *direct.g, "g"));
  EXPECT_DOUBLE_EQ(written->sigmaT->voxelSize()[0], 10.0 / 128.0);

  // By hand. Stroke 0, constant falloff, strength 1: the voxel at the dab centre holds the
  // target exactly, with the base's σs; the voxel 4 voxels (0.3125 > 0.5/2 rest) away
  // stays base (inactive).
  auto t = written->sigmaT->getConstAccessor();
  auto s = written->sigmaS->getConstAccessor();
  auto g = written->g->getConstAccessor();
  openvdb::Vec3s value;
  ASSERT_TRUE(t.probeValue(Coord(0, 0, 0), value));
  EXPECT_TRUE(sameBits(value[0], 4.0f) && sameBits(value[1], 5.0f) && sameBits(value[2], 6.0f));
  ASSERT_TRUE(s.probeValue(Coord(0, 0, 0), value));
  EXPECT_TRUE(sameBits(value[0], 0.9f) && sameBits(value[1], 1.0f) && sameBits(value[2], 1.1f));
  EXPECT_FALSE(t.isValueOn(Coord(4, 0, 0)));
  // Stroke 1, smooth falloff, strength 0.5 at rest (1,0,0) = index (12.8,0,0): voxel
  // (13,0,0) is 0.015625 away, u = 0.0625, w = 1 - u²(3 - 2u) = 0.98876953125, so
  // g = 0.1 + 0.5 w (0.5 - 0.1) = 0.29775390625.
  float gValue = 0.0f;
  ASSERT_TRUE(g.probeValue(Coord(13, 0, 0), gValue));
  EXPECT_NEAR(gValue, 0.29775390625, 1e-7);
  // Stroke 2's mirror (x = 0, the box's rest centre) painted the reflection of its path.
  // Rest (2,1,-1) = index (25.6,12.8,-12.8); the plane is index 0.
  openvdb::Vec3s right, left;
  ASSERT_TRUE(t.probeValue(Coord(26, 13, -13), right));
  ASSERT_TRUE(t.probeValue(Coord(-26, 13, -13), left));
  EXPECT_EQ(right, left);
  EXPECT_GT(right[0], 1.0f);
}

TEST(PaintCli, PaintsAnExistingSetInItsOwnUnits) {
  // The scene's set stores σ per cm (scene in mm): painting σt = 2 per mm stores 20 per cm;
  // an untouched active voxel and the file's units survive.
  Files f;
  auto set = makeEmptyMaterialSet(MaterialSample{}, 0.25, "cm");
  set->sigmaT->tree().setValueOn(Coord(12, 0, 0), openvdb::Vec3s(7.0f));
  set->sigmaS->tree().setValueOn(Coord(12, 0, 0), openvdb::Vec3s(3.0f));
  saveMaterialSet(*set, f.dir / "in.vdb");
  json scene = sceneJson();
  scene["material"]["vdb"] = "in.vdb";
  writeText(f.scene, scene.dump());
  const glm::dmat4 restToWorld = loadScene(f.scene).transform.matrix();
  writeText(f.strokes, json({{"strokes",
                              {{{"channel", "sigma_t"},
                                {"mode", "set"},
                                {"value", 2},
                                {"radius", 0.2},
                                {"falloff", "constant"},
                                {"points", {worldPoint(restToWorld, {0, 0, 0})}}}}}})
                           .dump());
  const RunResult run = runSslpv({"paint", f.scene.string(), "--strokes", f.strokes.string(), "-o", f.output.string()});
  ASSERT_EQ(run.exitCode, 0) << run.stderrText;
  const std::shared_ptr<const MaterialSet> out = loadMaterialSet(f.output);
  EXPECT_EQ(out->units, "cm");
  EXPECT_EQ(out->sigmaT->tree().getValue(Coord(0)), openvdb::Vec3s(20.0f));
  EXPECT_EQ(out->sigmaT->tree().getValue(Coord(12, 0, 0)), openvdb::Vec3s(7.0f));
  EXPECT_EQ(out->sigmaT->activeVoxelCount(), 2u);
}

TEST(PaintCli, BadStrokeFilesExit2WithOneLineNamingTheKeyAndLeaveTheOutputUntouched) {
  const std::string point = R"("points": [[1, 2, 3]])";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {R"({"strokes": [{"mode": "erase", "radius": 1, )" + point + R"(}, {"mode": "erase", "radiuss": 1, )" + point +
           "}]}",
       "strokes[1].radiuss: unknown key"},
      {R"({"strokes": [{"mode": "erase", "radius": [1], )" + point + "}]}", "strokes[0].radius: expected a number"},
      {R"({"strokes": [{"mode": "erase", "radius": 0, )" + point + "}]}", "strokes[0].radius: must be positive"},
      {R"({"strokes": [{"channel": "preset", "mode": "set", "value": "jade", "radius": 1, )" + point + "}]}",
       "strokes[0].value: unknown preset"},
      {R"({"strokes": [{"mode": "erase", "radius": NaN, )" + point + "}]}", "strokes[0].radius: malformed JSON"},
      {R"({"strokes": [{"mode": "erase", "radius": 1e6, )" + point + "}]}", "strokes[0].radius: a dab covers"},
      {R"({"strokes": [{"mode": "smooth", "strength": 2, "radius": 1, )" + point + "}]}", "strokes[0].strength"},
  };
  for (const auto& [text, expected] : cases) {
    Files f;
    writeText(f.scene, sceneJson().dump());
    writeText(f.strokes, text);
    writeText(f.output, kPreexisting);
    const RunResult run =
        runSslpv({"paint", f.scene.string(), "--strokes", f.strokes.string(), "-o", f.output.string()});
    EXPECT_EQ(run.exitCode, 2) << text;
    EXPECT_EQ(run.stderrText.rfind("sslpv: error: " + f.strokes.string() + ": " + expected, 0), 0u)
        << run.stderrText << "expected: " << expected;
    EXPECT_EQ(std::count(run.stderrText.begin(), run.stderrText.end(), '\n'), 1) << run.stderrText;
    EXPECT_EQ(readText(f.output), kPreexisting);
    std::set<std::string> names;
    for (const auto& entry : fs::directory_iterator(f.dir.path())) names.insert(entry.path().filename().string());
    EXPECT_EQ(names, (std::set<std::string>{"scene.json", "strokes.json", "out.vdb"})) << "temporary files left";
  }
}

/// Runs `sslpv paint` on sceneJson() with `strokes`; the output must not appear.
RunResult paintRefused(const json& strokes) {
  Files f;
  writeText(f.scene, sceneJson().dump());
  writeText(f.strokes, strokes.dump());
  const RunResult run = runSslpv({"paint", f.scene.string(), "--strokes", f.strokes.string(), "-o", f.output.string()});
  EXPECT_FALSE(fs::exists(f.output));
  EXPECT_EQ(std::count(run.stderrText.begin(), run.stderrText.end(), '\n'), 1) << run.stderrText;
  return run;
}

// A stroke ending far outside the object grew the set's voxel tree by ~190 MB/s to
// gigabytes (or died in pthread_create): such a point is refused, by index, before any dab.
TEST(PaintCli, AStrokePointFarOutsideTheObjectIsRefusedByItsIndex) {
  const RunResult run = paintRefused(
      {{"strokes",
        {{{"channel", "sigma_t"},
          {"mode", "set"},
          {"value", 2},
          {"radius", 1},
          {"points", {{1, 2, 3}, {1, 4, 3}, {1, 1e5, 3}}}}}}});
  EXPECT_EQ(run.exitCode, 2) << run.stderrText;
  EXPECT_NE(run.stderrText.find("strokes[0].points[2]: (1, 100000, 3) is farther than the brush radius from the object"),
            std::string::npos)
      << run.stderrText;
}

// Points near the object but a stroke whose dabs would visit more than 2^30 voxels in all
// (here ~200 segments of 8 dabs of ~10^6 voxels each) is refused before it starts.
TEST(PaintCli, AStrokeWhoseTotalWorkIsTooLargeIsRefusedBeforeItStarts) {
  Files f;
  writeText(f.scene, sceneJson().dump());
  const glm::dmat4 restToWorld = loadScene(f.scene).transform.matrix();
  json points = json::array();
  for (int i = 0; i < 200; ++i) points.push_back(worldPoint(restToWorld, glm::dvec3(i % 2 ? 4.0 : -4.0, 0.0, 0.0)));
  const RunResult run =
      paintRefused({{"strokes", {{{"mode", "smooth"}, {"radius", 8}, {"points", points}}}}});
  EXPECT_EQ(run.exitCode, 2) << run.stderrText;
  EXPECT_NE(run.stderrText.find("strokes[0].radius: the stroke's"), std::string::npos) << run.stderrText;
  EXPECT_NE(run.stderrText.find("more than the limit of 2^30"), std::string::npos) << run.stderrText;
}

/// Every active voxel of `set` (σ per scene unit: the scene's units) shows `colour` within
/// 1 % by adding-doubling at `ior` (α' from the stored floats), and `distance` as 1/σt'.
void expectPaintedColour(const MaterialSet& set, const glm::dvec3& colour, const glm::dvec3& distance, double g,
                         double ior, std::size_t minVoxels) {
  ASSERT_TRUE(set.g);
  auto s = set.sigmaS->getConstAccessor();
  auto gs = set.g->getConstAccessor();
  std::size_t voxels = 0;
  for (auto it = set.sigmaT->cbeginValueOn(); it; ++it, ++voxels) {
    const openvdb::Vec3s sigmaT = *it, sigmaS = s.getValue(it.getCoord());
    const double vg = gs.getValue(it.getCoord());
    ASSERT_NEAR(vg, g, 1e-6) << it.getCoord();
    for (int c = 0; c < 3; ++c) {
      const double reducedT = sigmaT[c] - sigmaS[c] * vg;
      const double rd = addingDoublingHalfSpace(sigmaS[c] * (1.0 - vg) / reducedT, ior).rd;
      ASSERT_NEAR(rd, colour[c], 0.01 * colour[c]) << it.getCoord() << " channel " << c;
      ASSERT_NEAR(1.0 / reducedT, distance[c], 1e-5 * distance[c]) << it.getCoord() << " channel " << c;
    }
  }
  EXPECT_GE(voxels, minVoxels);
}

json sceneWithIor(double ior) {
  json scene = sceneJson();
  scene["material"]["ior"] = ior;
  return scene;
}

// The colour form: a picked surface colour and scatter distance, painted at full strength,
// leave voxels whose albedo shows that colour behind the scene's ior.
TEST(PaintCli, AColourStrokePaintsVoxelsThatShowThePickedColour) {
  Files f;
  writeText(f.scene, sceneWithIor(1.4).dump());
  const glm::dmat4 restToWorld = loadScene(f.scene).transform.matrix();
  const glm::dvec3 colour(0.8, 0.35, 0.05), distance(2.0, 1.0, 0.5);
  writeText(f.strokes, json({{"strokes",
                              {{{"color", {colour.x, colour.y, colour.z}},
                                {"scatter_distance", {distance.x, distance.y, distance.z}},
                                {"g", 0.4},
                                {"radius", 0.5},
                                {"falloff", "constant"},
                                {"points", {worldPoint(restToWorld, {1, 1, 1})}}}}}})
                           .dump());
  const RunResult run = runSslpv({"paint", f.scene.string(), "--strokes", f.strokes.string(), "-o", f.output.string()});
  ASSERT_EQ(run.exitCode, 0) << run.stderrText;
  expectPaintedColour(*loadMaterialSet(f.output), colour, distance, 0.4, 1.4, 50);
}

// The flags give the material of strokes that name none: one path file, any colour.
TEST(PaintCli, ColourFlagsPaintStrokesThatNameNoMaterial) {
  Files f;
  writeText(f.scene, sceneWithIor(1.3).dump());
  const glm::dmat4 restToWorld = loadScene(f.scene).transform.matrix();
  writeText(f.strokes, json({{"strokes",
                              {{{"radius", 0.5},
                                {"falloff", "constant"},
                                {"points", {worldPoint(restToWorld, {-1, 0, 2})}}}}}})
                           .dump());
  const RunResult run = runSslpv({"paint", f.scene.string(), "--strokes", f.strokes.string(), "-o",
                                  f.output.string(), "--colour", "0.6,0.3,0.9", "--scatter-distance", "1.5"});
  ASSERT_EQ(run.exitCode, 0) << run.stderrText;
  expectPaintedColour(*loadMaterialSet(f.output), {0.6, 0.3, 0.9}, glm::dvec3(1.5), 0.0, 1.3, 50);
  // Without the flags the same file is refused as before.
  const RunResult bare = runSslpv({"paint", f.scene.string(), "--strokes", f.strokes.string(), "-o",
                                   (f.dir / "bare.vdb").string()});
  EXPECT_EQ(bare.exitCode, 2);
  EXPECT_NE(bare.stderrText.find("strokes[0]: missing required key \"mode\""), std::string::npos) << bare.stderrText;
}

TEST(PaintCli, BadColourStrokesAndFlagsExit2NamingTheKeyOrFlag) {
  const json point = {{1, 2, 3}};
  auto stroke = [&](json extra) {
    json s = {{"radius", 1}, {"points", point}};
    s.update(extra);
    return json({{"strokes", {s}}});
  };
  const std::vector<std::pair<json, std::string>> strokeCases = {
      {stroke({{"colour", 0.5}, {"scatter_distance", 1}, {"channel", "sigma_t"}}),
       "strokes[0].channel: a stroke gives either \"colour\""},
      {stroke({{"colour", 0.5}, {"color", 0.5}, {"scatter_distance", 1}}), "strokes[0].color: duplicates \"colour\""},
      {stroke({{"colour", 0.5}}), "strokes[0]: missing required key \"scatter_distance\""},
      {stroke({{"scatter_distance", 1}}), "strokes[0]: missing required key \"colour\""},
      {stroke({{"colour", {0.5, 1.5, 0.5}}, {"scatter_distance", 1}}), "strokes[0].colour[1]: must be a surface colour"},
      {stroke({{"colour", 0.5}, {"scatter_distance", {1, 0, 1}}}), "strokes[0].scatter_distance[1]: must be"},
      {stroke({{"colour", 0.5}, {"scatter_distance", 1}, {"g", 1}}), "strokes[0].g: must be in [-0.99, 0.99], got 1"},
      {stroke({{"colour", 0.5}, {"scatter_distance", 1}, {"mode", "add"}}), "strokes[0].mode: the colour form takes"},
      // Brighter than a non-absorbing medium behind the scene's ior 1.5 boundary shows:
      // refused when painted, naming the channel, the value and the bound.
      {stroke({{"colour", {0.5, 0.5, 0.97}}, {"scatter_distance", 1}}),
       "strokes[0].colour[2]: must be in [0, 0.96], got 0.97"},
  };
  for (const auto& [strokes, expected] : strokeCases) {
    Files f;
    writeText(f.scene, sceneWithIor(1.5).dump());
    writeText(f.strokes, strokes.dump());
    const RunResult run = runSslpv({"paint", f.scene.string(), "--strokes", f.strokes.string(), "-o", f.output.string()});
    EXPECT_EQ(run.exitCode, 2) << strokes.dump();
    EXPECT_EQ(run.stderrText.rfind("sslpv: error: " + f.strokes.string() + ": " + expected, 0), 0u)
        << run.stderrText << "expected: " << expected;
    EXPECT_EQ(std::count(run.stderrText.begin(), run.stderrText.end(), '\n'), 1) << run.stderrText;
    EXPECT_FALSE(fs::exists(f.output));
  }
  const std::vector<std::pair<std::vector<std::string>, std::string>> flagCases = {
      {{"--g", "0.3"}, "--g: needs --colour"},
      {{"--colour", "0.5"}, "--colour: needs --scatter-distance"},
      {{"--colour", "0.5,0.2", "--scatter-distance", "1"}, "--colour: expected one number or R,G,B, got 2 numbers"},
      {{"--colour", "0.5,x,0.2", "--scatter-distance", "1"}, "--colour: expected one number or R,G,B, got \"0.5,x,0.2\""},
      {{"--colour", "0.99", "--scatter-distance", "1"}, "--colour[0]: must be in [0, 0.96], got 0.99"},
      {{"--colour", "0.5", "--scatter-distance", "1,-1,1"}, "--scatter-distance[1]: must be positive"},
      {{"--colour", "0.5", "--scatter-distance", "1", "--g", "-2"}, "--g: must be in [-0.99, 0.99], got -2"},
  };
  for (const auto& [flags, expected] : flagCases) {
    Files f;
    writeText(f.scene, sceneWithIor(1.5).dump());
    writeText(f.strokes, stroke(json::object()).dump());
    std::vector<std::string> args = {"paint", f.scene.string(), "--strokes", f.strokes.string(), "-o",
                                     f.output.string()};
    args.insert(args.end(), flags.begin(), flags.end());
    const RunResult run = runSslpv(args);
    EXPECT_EQ(run.exitCode, 2) << expected;
    EXPECT_EQ(run.stderrText.rfind("sslpv: error: " + expected, 0), 0u) << run.stderrText << "expected: " << expected;
    EXPECT_FALSE(fs::exists(f.output));
  }
}

TEST(PaintCli, BadOutputOrMissingStrokeFileExit2) {
  Files f;
  writeText(f.scene, sceneJson().dump());
  RunResult run =
      runSslpv({"paint", f.scene.string(), "--strokes", (f.dir / "none.json").string(), "-o", f.output.string()});
  EXPECT_EQ(run.exitCode, 2);
  EXPECT_NE(run.stderrText.find("none.json: cannot read stroke file"), std::string::npos) << run.stderrText;
  writeText(f.strokes, R"({"strokes": []})");
  run = runSslpv({"paint", f.scene.string(), "--strokes", f.strokes.string(), "-o", (f.dir / "out.png").string()});
  EXPECT_EQ(run.exitCode, 2);
  EXPECT_NE(run.stderrText.find("must be a .vdb file"), std::string::npos) << run.stderrText;
  EXPECT_FALSE(fs::exists(f.dir / "out.png"));
}

/// Runs `sslpv paint` on `f` (scene and strokes already written).
RunResult paint(const Files& f, const std::vector<std::string>& extra = {}) {
  std::vector<std::string> args{"paint", f.scene.string(), "--strokes", f.strokes.string(), "-o", f.output.string()};
  args.insert(args.end(), extra.begin(), extra.end());
  return runSslpv(args);
}

std::size_t countLines(const std::string& text, const std::string& needle) {
  std::size_t n = 0;
  for (std::size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1)) ++n;
  return n;
}

// A dab in the corner region of the object's box reach (within the radius of the bounds on
// every axis, 1.4 radii from the box itself) painted voxels the object never shows, silently.
TEST(PaintCli, DabsClearOfTheObjectWarnNamingThePointsButThePaintIsWritten) {
  Files f;
  writeText(f.scene, sceneJson().dump());
  const glm::dmat4 restToWorld = loadScene(f.scene).transform.matrix();
  const json strokes = {{"strokes",
                         {{{"channel", "sigma_t"},
                           {"mode", "set"},
                           {"value", 3},
                           {"radius", 1},
                           {"points", {worldPoint(restToWorld, {4, 4, 4}), worldPoint(restToWorld, {5.4, 5.4, 5.4})}}}}}};
  writeText(f.strokes, strokes.dump());
  const RunResult run = paint(f);
  ASSERT_EQ(run.exitCode, 0) << run.stderrText;
  EXPECT_NE(run.stderrText.find("sslpv: warning: " + f.strokes.string() +
                                ": strokes[0].points: 1 of 2 points are farther than the brush radius (1) from the "
                                "object and paint voxels it does not show (the first: points[1] ("),
            std::string::npos)
      << run.stderrText;
  EXPECT_EQ(countLines(run.stderrText, "\n"), 1u) << run.stderrText;
  EXPECT_TRUE(fs::exists(f.output));
}

// A ray stroke whose rays all miss changed nothing: warned by key, exit 2, no file written.
TEST(PaintCli, AStrokeThatChangesNothingWarnsAndExits2WithoutWriting) {
  Files f;
  writeText(f.scene, sceneJson().dump());
  const json strokes = {{"strokes",
                         {{{"channel", "sigma_s"},
                           {"mode", "add"},
                           {"value", 0.3},
                           {"radius", 0.4},
                           {"rays", {{{"origin", {100, 20, 3}}, {"direction", {0, 1, 0}}}}}}}}};
  writeText(f.strokes, strokes.dump());
  writeText(f.output, kPreexisting);
  const RunResult run = paint(f);
  EXPECT_EQ(run.exitCode, 2) << run.stderrText;
  EXPECT_NE(run.stderrText.find("sslpv: warning: " + f.strokes.string() +
                                ": strokes[0].rays: 1 of 1 rays missed the object and painted nothing\n"),
            std::string::npos)
      << run.stderrText;
  EXPECT_NE(run.stderrText.find("sslpv: warning: " + f.strokes.string() + ": strokes[0]: changed no voxel\n"),
            std::string::npos)
      << run.stderrText;
  EXPECT_NE(run.stderrText.find("sslpv: error: " + f.strokes.string() +
                                ": no stroke changed any voxel (see the warnings above): nothing written to " +
                                f.output.string() + "\n"),
            std::string::npos)
      << run.stderrText;
  EXPECT_EQ(readText(f.output), kPreexisting);
}

// --update-scene changes the scene's material.vdb and not one other byte of the file.
TEST(PaintCli, UpdateSceneNamesTheOutputAndKeepsTheRestOfTheFileByteForByte) {
  Files f;
  const std::string before =
      "{\n"
      "  \"units\": \"mm\",\n"
      "  \"mesh\": {\"primitive\": \"box\", \"min\": [-5, -5, -5], \"max\": [5, 5, 5]},\n"
      "  \"transform\": {\"translate\": [1, 2, 3], \"rotate_deg\": [0, 30, 0], \"scale\": 2},\n"
      "  \"material\": {\n"
      "    \"base\": {\"sigma_t\": [1.0, 1.2, 1.4], \"sigma_s\": [0.9, 1.0, 1.1], \"g\": 0.1}\n"
      "  },\n"
      "  \"lights\": [{\"type\": \"point\", \"position\": [20, 30, 40], \"intensity\": 1000}],\n"
      "  \"camera\": {\"position\": [0, 10, 40], \"target\": [0, 0, 0], \"fov_y_deg\": 35,\n"
      "             \"width\": 64, \"height\": 64}\n"
      "}\n";
  writeText(f.scene, before);
  const glm::dmat4 restToWorld = loadScene(f.scene).transform.matrix();
  const json strokes = {{"strokes",
                         {{{"channel", "sigma_t"},
                           {"mode", "set"},
                           {"value", 3},
                           {"radius", 1},
                           {"points", {worldPoint(restToWorld, {0, 0, 0})}}}}}};
  writeText(f.strokes, strokes.dump());
  const RunResult run = paint(f, {"--update-scene"});
  ASSERT_EQ(run.exitCode, 0) << run.stderrText;
  std::string expected = before;
  const std::string base = "\"g\": 0.1}\n";
  expected.replace(expected.find(base), base.size(), "\"g\": 0.1},\n    \"vdb\": \"out.vdb\"\n");
  EXPECT_EQ(readText(f.scene), expected);
  EXPECT_EQ(loadScene(f.scene).material.vdb, f.output.lexically_normal());
  EXPECT_NE(run.stdoutText.find("wrote " + f.output.string() + " ("), std::string::npos) << run.stdoutText;
  EXPECT_NE(run.stdoutText.find("wrote " + f.scene.string() + " (material.vdb now names out.vdb, "),
            std::string::npos)
      << run.stdoutText;
}

}  // namespace
}  // namespace sslpv::test
