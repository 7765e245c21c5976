// End-to-end tests of the `sslpv` binary as a user runs it (docs/design.md §3, §5):
// every bad input exits 2 (never a signal) with exactly one "sslpv: error: ..." line on
// stderr naming the file and the key path / grid / voxel, leaves an existing output file
// byte-identical and leaves no temporary files behind. Plus the happy paths and a render
// of every shipped example.
#include <gtest/gtest.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "cli_rejects.h"
#include "test_support.h"

namespace sslpv::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using openvdb::Coord;
using openvdb::Vec3s;

// --- scene JSON ------------------------------------------------------------------------

TEST_F(CliRejects, MalformedJsonNamesTheSceneFile) {
  writeText(scenePath(), R"({"units": "mm", "mesh": {"primitive": "box",)");
  expectRejected(render(), {"scene.json"});
}

TEST_F(CliRejects, UnknownTopLevelKeyIsNamed) {
  json scene = smallScene();
  scene["colour_space"] = "srgb";
  writeScene(scene);
  expectRejected(render(), {"scene.json", "colour_space"});
}

TEST_F(CliRejects, UnknownNestedKeyIsNamedWithItsPath) {
  json scene = smallScene();
  scene["lights"][0]["colour"] = {1, 1, 1};
  writeScene(scene);
  expectRejected(render(), {"scene.json", "lights[0].colour"});
}

TEST_F(CliRejects, MissingRequiredCameraIsNamed) {
  json scene = smallScene();
  scene.erase("camera");
  writeScene(scene);
  expectRejected(render(), {"scene.json", "camera"});
}

TEST_F(CliRejects, WrongTypeForCameraWidthIsNamed) {
  json scene = smallScene();
  scene["camera"]["width"] = "big";
  writeScene(scene);
  expectRejected(render(), {"scene.json", "camera.width"});
}

TEST_F(CliRejects, NegativeLightIntensityIsNamed) {
  json scene = smallScene();
  scene["lights"][0]["intensity"] = {1000, -1, 1000};
  writeScene(scene);
  expectRejected(render(), {"scene.json", "lights[0].intensity"});
}

TEST_F(CliRejects, BaseSigmaSAboveSigmaTIsNamed) {
  json scene = smallScene();
  scene["material"]["base"]["sigma_s"] = {0.9, 1.5, 1.1};  // green 1.5 > sigma_t 1.2
  writeScene(scene);
  expectRejected(render(), {"scene.json", "material.base", "sigma_s"});
}

TEST_F(CliRejects, BaseAsymmetryOfOneIsNamed) {
  json scene = smallScene();
  scene["material"]["base"]["g"] = 1.0;
  writeScene(scene);
  expectRejected(render(), {"scene.json", "material.base.g"});
}

TEST_F(CliRejects, OverflowingSigmaLiteralIsRejected) {
  json scene = smallScene();
  scene["material"]["base"]["sigma_t"] = {12345.5, 1.2, 1.4};
  std::string text = scene.dump(2);
  text.replace(text.find("12345.5"), 7, "1e999");  // not representable: +inf or a parse error
  writeText(scenePath(), text);
  const RunResult r = render();
  expectRejected(r, {"scene.json"});
  EXPECT_TRUE(r.stderrText.find("sigma_t") != std::string::npos ||
              r.stderrText.find("1e999") != std::string::npos)
      << "should name the key or the literal: " << r.stderrText;
}

TEST_F(CliRejects, CameraUpParallelToViewIsNamed) {
  json scene = smallScene();
  scene["camera"]["position"] = {0, 40, 0};  // looking straight down the up vector
  writeScene(scene);
  expectRejected(render(), {"scene.json", "camera.up"});
}

// --- meshes ----------------------------------------------------------------------------

TEST_F(CliRejects, MissingMeshFileIsNamed) {
  json scene = smallScene();
  scene["mesh"] = {{"path", "nothere.obj"}};
  writeScene(scene);
  expectRejected(render(), {"nothere.obj"});
}

TEST_F(CliRejects, GarbageMeshFileIsNamed) {
  std::string garbage = "this is not an OBJ file\n";
  for (int i = 0; i < 256; ++i) garbage.push_back(static_cast<char>((i * 37) & 0xff));
  writeText(dir_ / "garbage.obj", garbage);
  json scene = smallScene();
  scene["mesh"] = {{"path", "garbage.obj"}};
  writeScene(scene);
  expectRejected(render(), {"garbage.obj"});
}

TEST_F(CliRejects, DegenerateBoxIsNamed) {
  json scene = smallScene();
  scene["mesh"]["max"] = scene["mesh"]["min"];
  writeScene(scene);
  expectRejected(render(), {"scene.json", "mesh"});
}

TEST_F(CliRejects, OpenMeshIsNotClosed) {
  // A unit cube with its top face (two triangles) missing.
  writeText(dir_ / "open_box.obj",
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
            "f 1 4 3\nf 1 3 2\n"   // z = 0
            "f 5 6 7\nf 5 7 8\n"   // z = 1
            "f 1 2 6\nf 1 6 5\n"   // y = 0
            "f 1 5 8\nf 1 8 4\n"   // x = 0
            "f 2 3 7\nf 2 7 6\n");  // x = 1; y = 1 missing
  json scene = smallScene();
  scene["mesh"] = {{"path", "open_box.obj"}};
  writeScene(scene);
  expectRejected(render(), {"open_box.obj", "not closed"});
}

// --- material-set files ----------------------------------------------------------------

TEST_F(CliRejects, MissingVdbFileIsNamed) {
  writeSceneWithVdb("missing.vdb");
  expectRejected(render(), {"missing.vdb"});
}

TEST_F(CliRejects, EmptyVdbFileIsNamed) {
  writeText(dir_ / "empty.vdb", "");
  writeSceneWithVdb("empty.vdb");
  expectRejected(render(), {"empty.vdb"});
}

TEST_F(CliRejects, TruncatedVdbFileIsNamed) {
  writeVdb(dir_ / "truncated.vdb", validGrids());
  const std::string whole = readText(dir_ / "truncated.vdb");
  ASSERT_GT(whole.size(), 100u);
  writeText(dir_ / "truncated.vdb", whole.substr(0, whole.size() / 2));
  writeSceneWithVdb("truncated.vdb");
  expectRejected(render(), {"truncated.vdb"});
}

TEST_F(CliRejects, RandomBytesVdbFileIsNamed) {
  std::mt19937 random(20240601u);
  std::string bytes(4096, '\0');
  for (char& c : bytes) c = static_cast<char>(random() & 0xff);
  writeText(dir_ / "random.vdb", bytes);
  writeSceneWithVdb("random.vdb");
  expectRejected(render(), {"random.vdb"});
}

TEST_F(CliRejects, SigmaTAsFloatGridIsAWrongGridType) {
  MaterialGrids grids = validGrids();
  auto scalarSigmaT = openvdb::FloatGrid::create(0.0f);
  scalarSigmaT->setName("sigma_t");
  scalarSigmaT->getAccessor().setValue(Coord(0, 0, 0), 1.5f);
  writeVdb(dir_ / "bad.vdb", openvdb::GridPtrVec{scalarSigmaT, grids.sigmaS});
  writeSceneWithVdb("bad.vdb");
  const RunResult r = render();
  expectRejected(r, {"bad.vdb", "sigma_t"});
}

TEST_F(CliRejects, MissingSigmaSGridIsNamed) {
  MaterialGrids grids = validGrids();
  writeVdb(dir_ / "bad.vdb", openvdb::GridPtrVec{grids.sigmaT, grids.g});
  writeSceneWithVdb("bad.vdb");
  expectRejected(render(), {"bad.vdb", "sigma_s"});
}

TEST_F(CliRejects, NaNSigmaTVoxelIsNamed) {
  MaterialGrids grids = validGrids();
  grids.sigmaT->getAccessor().setValue(kBadVoxel, Vec3s(1.5f, std::numeric_limits<float>::quiet_NaN(), 1.7f));
  writeVdb(dir_ / "bad.vdb", grids);
  writeSceneWithVdb("bad.vdb");
  expectVoxelRejected(render(), "bad.vdb", "sigma_t");
}

TEST_F(CliRejects, InfiniteSigmaTVoxelIsNamed) {
  MaterialGrids grids = validGrids();
  grids.sigmaT->getAccessor().setValue(kBadVoxel, Vec3s(std::numeric_limits<float>::infinity(), 1.6f, 1.7f));
  writeVdb(dir_ / "bad.vdb", grids);
  writeSceneWithVdb("bad.vdb");
  expectVoxelRejected(render(), "bad.vdb", "sigma_t");
}

TEST_F(CliRejects, NegativeSigmaSVoxelIsNamed) {
  MaterialGrids grids = validGrids();
  grids.sigmaS->getAccessor().setValue(kBadVoxel, Vec3s(1.2f, -0.1f, 1.4f));
  writeVdb(dir_ / "bad.vdb", grids);
  writeSceneWithVdb("bad.vdb");
  expectVoxelRejected(render(), "bad.vdb", "sigma_s");
}

TEST_F(CliRejects, SigmaSAboveSigmaTVoxelIsNamed) {
  MaterialGrids grids = validGrids();
  grids.sigmaS->getAccessor().setValue(kBadVoxel, Vec3s(1.2f, 2.0f, 1.4f));  // 2.0 > sigma_t 1.6
  writeVdb(dir_ / "bad.vdb", grids);
  writeSceneWithVdb("bad.vdb");
  expectVoxelRejected(render(), "bad.vdb", "sigma_s");
}

TEST_F(CliRejects, AsymmetryOfOneVoxelIsNamed) {
  MaterialGrids grids = validGrids();
  grids.g->getAccessor().setValue(kBadVoxel, 1.0f);
  writeVdb(dir_ / "bad.vdb", grids);
  writeSceneWithVdb("bad.vdb");
  expectVoxelRejected(render(), "bad.vdb", "g");
}

// --- command line ----------------------------------------------------------------------

TEST_F(CliRejects, OutputInMissingDirectoryIsNamed) {
  writeScene(smallScene());
  const fs::path target = dir_ / "nodir" / "image.png";
  const RunResult r = run({"render", scenePath().string(), "-o", target.string()});
  expectRejected(r, {"nodir"});
  EXPECT_FALSE(fs::exists(dir_ / "nodir")) << "the missing folder must not be created";
}

TEST_F(CliRejects, UnsupportedOutputExtensionIsNamed) {
  writeScene(smallScene());
  const RunResult r = run({"render", scenePath().string(), "-o", (dir_ / "image.bmp").string()});
  expectRejected(r, {"image.bmp"});
}

TEST_F(CliRejects, GridOfOneCellIsRejected) {
  writeScene(smallScene());
  expectRejected(render({"--grid", "1"}), {"--grid"});
}

TEST_F(CliRejects, ZeroStepsAreRejected) {
  writeScene(smallScene());
  expectRejected(render({"--steps", "0"}), {"--steps"});
}

TEST_F(CliRejects, UnknownBackendIsRejected) {
  writeScene(smallScene());
  expectRejected(render({"--backend", "bogus"}), {"--backend"});
}

TEST_F(CliRejects, UnknownSubcommandIsNamed) {
  writeScene(smallScene());
  expectRejected(run({"frobnicate", scenePath().string()}), {"frobnicate"});
}

TEST_F(CliRejects, InspectOfMissingFileIsNamed) {
  expectRejected(run({"inspect", (dir_ / "missing.vdb").string()}), {"missing.vdb"});
}

// --- successful runs -------------------------------------------------------------------

/// Width and height from a PNG's IHDR chunk (big-endian at bytes 16 and 20).
std::pair<std::uint32_t, std::uint32_t> pngSize(const std::string& bytes) {
  auto be32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (std::size_t i = 0; i < 4; ++i) v = (v << 8) | static_cast<unsigned char>(bytes[at + i]);
    return v;
  };
  return {be32(16), be32(20)};
}

const std::string kPngSignature("\x89PNG\r\n\x1a\n", 8);

TEST(Cli, RenderOfSmallSceneReplacesTheOutputWithA64x64Png) {
  TempDir dir;
  writeText(dir / "scene.json", smallScene().dump(2));
  writeText(dir / "out.png", kPreexistingOutput);
  const RunResult r = runSslpv({"render", (dir / "scene.json").string(), "-o", (dir / "out.png").string()});
  ASSERT_EQ(r.signal, 0);
  ASSERT_EQ(r.exitCode, 0) << r.stderrText;
  const std::string png = readText(dir / "out.png");
  ASSERT_GE(png.size(), 24u);
  EXPECT_EQ(png.substr(0, 8), kPngSignature);
  EXPECT_EQ(pngSize(png), std::make_pair(64u, 64u));
  // The atomic write leaves nothing but the scene and the image.
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir.path())) names.insert(entry.path().filename().string());
  EXPECT_EQ(names, (std::set<std::string>{"scene.json", "out.png"}));
}

TEST(Cli, TimingsTableNamesEveryStage) {
  TempDir dir;
  writeText(dir / "scene.json", smallScene().dump(2));
  const RunResult r =
      runSslpv({"render", (dir / "scene.json").string(), "-o", (dir / "out.png").string(), "--timings"});
  ASSERT_EQ(r.exitCode, 0) << r.stderrText;
  const std::string table = lower(r.stdoutText);
  for (const char* stage : {"shadow map", "injection", "propagation", "shading", "total"})
    EXPECT_NE(table.find(stage), std::string::npos) << "missing '" << stage << "' in:\n" << r.stdoutText;
}

TEST(Cli, InspectOfValidVdbListsItsGrids) {
  TempDir dir;
  writeVdb(dir / "good.vdb", validGrids());
  const RunResult r = runSslpv({"inspect", (dir / "good.vdb").string()});
  EXPECT_EQ(r.signal, 0);
  EXPECT_EQ(r.exitCode, 0) << r.stderrText;
  for (const char* grid : {"sigma_t", "sigma_s", "g"})
    EXPECT_TRUE(mentionsWord(r.stdoutText, grid)) << "missing grid " << grid << " in:\n" << r.stdoutText;
}

TEST(Cli, InspectOfInvalidVdbExits2AndListsTheProblem) {
  TempDir dir;
  MaterialGrids grids = validGrids();
  grids.sigmaT->getAccessor().setValue(kBadVoxel, Vec3s(std::numeric_limits<float>::quiet_NaN()));
  writeVdb(dir / "bad.vdb", grids);
  const RunResult r = runSslpv({"inspect", (dir / "bad.vdb").string()});
  EXPECT_EQ(r.signal, 0);
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_EQ(std::count(r.stderrText.begin(), r.stderrText.end(), '\n'), 1) << r.stderrText;
  EXPECT_EQ(r.stderrText.rfind("sslpv: error: ", 0), 0u) << r.stderrText;
  const std::string report = r.stdoutText + r.stderrText;
  EXPECT_NE(report.find("voxel"), std::string::npos) << report;
  EXPECT_TRUE(mentionsWord(report, "sigma_t")) << report;
}

// --- shipped examples ------------------------------------------------------------------

std::vector<fs::path> exampleScenes() {
  std::vector<fs::path> scenes;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(examplesDir(), ec))
    if (entry.path().extension() == ".json") scenes.push_back(entry.path());
  std::sort(scenes.begin(), scenes.end());
  return scenes;
}

TEST(Examples, EveryDocumentedSceneIsShipped) {
  std::set<std::string> names;
  for (const auto& scene : exampleScenes()) names.insert(scene.filename().string());
  for (const char* expected : {"marble_pebble.json", "jade_slab_backlit.json", "skin_sphere.json", "ketchup_box.json"})
    EXPECT_EQ(names.count(expected), 1u) << expected;
}

TEST(Examples, ShippedMaterialSetPassesInspection) {
  const RunResult r = runSslpv({"inspect", (examplesDir() / "marble_veins.vdb").string()});
  EXPECT_EQ(r.exitCode, 0) << r.stderrText << r.stdoutText;
  for (const char* grid : {"sigma_t", "sigma_s", "g"}) EXPECT_TRUE(mentionsWord(r.stdoutText, grid)) << grid;
}

/// Linear RGB pixels of a PFM file ("PF", width height, negative scale = little endian).
struct Pfm {
  int width = 0, height = 0;
  std::vector<float> rgb;
};

Pfm readPfm(const fs::path& file) {
  const std::string bytes = readText(file);
  Pfm pfm;
  std::size_t pos = 0;
  auto token = [&] {
    while (pos < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[pos]))) ++pos;
    const std::size_t start = pos;
    while (pos < bytes.size() && !std::isspace(static_cast<unsigned char>(bytes[pos]))) ++pos;
    return bytes.substr(start, pos - start);
  };
  if (token() != "PF") return pfm;
  pfm.width = std::stoi(token());
  pfm.height = std::stoi(token());
  const double scale = std::stod(token());
  ++pos;  // the single whitespace byte that ends the header
  const std::size_t count = static_cast<std::size_t>(pfm.width) * pfm.height * 3;
  if (scale >= 0.0 || bytes.size() - pos != count * sizeof(float)) return Pfm{};  // this host is little endian
  pfm.rgb.resize(count);
  std::memcpy(pfm.rgb.data(), bytes.data() + pos, count * sizeof(float));
  return pfm;
}

class ExampleScene : public ::testing::TestWithParam<fs::path> {};

TEST_P(ExampleScene, RendersToAFiniteLitPfm) {
  TempDir dir;
  const fs::path image = dir / "image.pfm";
  const RunResult r = runSslpv({"render", GetParam().string(), "-o", image.string(), "--grid", "16", "--steps",
                                "4", "--shadow-map", "64"});
  ASSERT_EQ(r.signal, 0);
  ASSERT_EQ(r.exitCode, 0) << r.stderrText;
  const json scene = json::parse(readText(GetParam()));
  const Pfm pfm = readPfm(image);
  ASSERT_EQ(pfm.width, scene["camera"]["width"].get<int>());
  ASSERT_EQ(pfm.height, scene["camera"]["height"].get<int>());
  float brightest = 0.0f;
  for (float v : pfm.rgb) {
    ASSERT_TRUE(std::isfinite(v) && v >= 0.0f) << "radiance must be finite and non-negative, got " << v;
    brightest = std::max(brightest, v);
  }
  // Every example lights its object in view: some pixel must receive light.
  EXPECT_GT(brightest, 0.0f);
}

/// The scene's stem with anything but letters and digits replaced: a valid test name.
std::string exampleTestName(const ::testing::TestParamInfo<fs::path>& scene) {
  std::string name = scene.param.stem().string();
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return name;
}

INSTANTIATE_TEST_SUITE_P(Shipped, ExampleScene, ::testing::ValuesIn(exampleScenes()), exampleTestName);

}  // namespace
}  // namespace sslpv::test
