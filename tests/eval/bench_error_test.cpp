// Unit tests of bench-error's pure parts (volume/eval/bench_table.h): the Pareto front on
// hand-made points whose front is known by inspection, the cross product of the option
// lists, the CSV/JSON tables and the reference cache key.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "test_support.h"
#include "volume/eval/bench_table.h"
#include "volume/core/error.h"
#include "volume/material/material_set.h"
#include "volume/scene/scene.h"

namespace sslpv::test {
namespace {

namespace fs = std::filesystem;
const double kNaN = std::numeric_limits<double>::quiet_NaN();

std::vector<std::string> splitCsvLine(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted && c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
      field += '"';
      ++i;
    } else if (c == '"') {
      quoted = !quoted;
    } else if (c == ',' && !quoted) {
      fields.push_back(field);
      field.clear();
    } else {
      field += c;
    }
  }
  fields.push_back(field);
  return fields;
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

TEST(BenchErrorPareto, KeepsExactlyTheUndominatedPoints) {
  // (ms, error): a is fastest; b trades time for error; c is slower and worse than a;
  // d equals b's error but is slower; e is the most accurate; f is b's exact twin (equal
  // points do not dominate each other); g has no error value.
  const std::vector<double> ms = {10, 20, 15, 30, 40, 20, 5};
  const std::vector<double> err = {0.5, 0.3, 0.6, 0.3, 0.1, 0.3, kNaN};
  const std::vector<bool> expected = {true, true, false, false, true, true, false};
  EXPECT_EQ(paretoFront(ms, err), expected);
}

TEST(BenchErrorPareto, ErrorsEqualWithinTheToleranceAreTies) {
  // The Vulkan twin of a CPU render: 50x slower, error smaller by 1e-5 relative. Not an
  // accuracy gain, so off the front; an error 1 % smaller is one, so it stays.
  EXPECT_EQ(paretoFront({20, 1000}, {0.285356, 0.285353}), (std::vector<bool>{true, false}));
  EXPECT_EQ(paretoFront({20, 1000}, {0.285356, 0.2825}), (std::vector<bool>{true, true}));
  // Equal time and errors within the tolerance: both stay (neither is better).
  EXPECT_EQ(paretoFront({20, 20}, {0.285356, 0.285353}), (std::vector<bool>{true, true}));
}

TEST(BenchErrorPareto, SinglePointAndEqualTimeTies) {
  EXPECT_EQ(paretoFront({7.0}, {0.2}), std::vector<bool>{true});
  // Same time, different errors: only the smaller error survives.
  EXPECT_EQ(paretoFront({7.0, 7.0}, {0.2, 0.1}), (std::vector<bool>{false, true}));
  EXPECT_TRUE(paretoFront({}, {}).empty());
}

TEST(BenchErrorPareto, FrontsArePerScene) {
  // Scene "fast" has a point that would dominate every point of scene "slow"; each scene
  // still keeps its own front.
  std::vector<BenchRow> rows(5);
  const std::vector<std::tuple<const char*, double, double>> data = {
      {"slow.json", 100, 0.4}, {"slow.json", 200, 0.2}, {"slow.json", 300, 0.3}, {"fast.json", 1, 0.01},
      {"fast.json", 2, 0.02}};
  for (std::size_t i = 0; i < rows.size(); ++i) {
    rows[i].scene = std::get<0>(data[i]);
    rows[i].ms.total = std::get<1>(data[i]);
    rows[i].metrics.meanRelativeError = std::get<2>(data[i]);
  }
  markParetoFronts(rows);
  EXPECT_TRUE(rows[0].pareto);
  EXPECT_TRUE(rows[1].pareto);
  EXPECT_FALSE(rows[2].pareto);  // slower and worse than row 1
  EXPECT_TRUE(rows[3].pareto);
  EXPECT_FALSE(rows[4].pareto);
}

TEST(BenchErrorConfigs, CrossProductIsCompleteUniqueAndBackendMajor) {
  BenchAxes axes;
  axes.backends = parseNameList("--backend", "cpu,vulkan", {"cpu", "vulkan"});
  axes.schemes = parseSchemeList("--scheme", "seed,calibrated");
  axes.grids = parseIntList("--grid", "32,64", 2, kMaxLpvResolution);
  axes.steps = parseStepsList("--steps", "8,auto");
  axes.shadowMaps = parseIntList("--shadow-map", "128,256,512", 1, kMaxShadowMap);
  const std::vector<BenchConfig> configs = expandConfigs(axes);
  ASSERT_EQ(configs.size(), 2u * 2u * 2u * 2u * 3u);
  std::set<std::tuple<std::string, int, int, std::string, int>> unique;
  for (const BenchConfig& c : configs)
    unique.insert({c.backend, int(c.scheme), c.grid, c.stepsText(), c.shadowMap});
  EXPECT_EQ(unique.size(), configs.size());
  EXPECT_EQ(configs.front().backend, "cpu");
  EXPECT_EQ(configs.front().scheme, LpvScheme::Seed);
  EXPECT_EQ(configs.front().grid, 32);
  EXPECT_EQ(configs.front().stepsText(), "8");
  EXPECT_EQ(configs.front().shadowMap, 128);
  EXPECT_EQ(configs.back().backend, "vulkan");
  EXPECT_EQ(configs.back().scheme, LpvScheme::Calibrated);
  EXPECT_EQ(configs.back().grid, 64);
  EXPECT_EQ(configs.back().stepsText(), "auto");
  EXPECT_EQ(configs.back().shadowMap, 512);
  for (std::size_t i = 0; i < configs.size() / 2; ++i) EXPECT_EQ(configs[i].backend, "cpu");
}

TEST(BenchErrorConfigs, ApplyOverridesTheScenesSettings) {
  LpvSettings scene;
  scene.resolution = 16;
  scene.steps = 3;
  const LpvSettings fixedSteps = BenchConfig{"cpu", LpvScheme::Seed, 48, 12, 128}.apply(scene);
  EXPECT_EQ(fixedSteps.resolution, 48);
  EXPECT_EQ(fixedSteps.steps, 12);
  EXPECT_FALSE(fixedSteps.autoSteps);
  EXPECT_EQ(fixedSteps.shadowMap, 128);
  EXPECT_EQ(fixedSteps.scheme, LpvScheme::Seed);
  const LpvSettings automatic = BenchConfig{"cpu", LpvScheme::Calibrated, 48, std::nullopt, 128}.apply(scene);
  EXPECT_TRUE(automatic.autoSteps);
  EXPECT_EQ(automatic.scheme, LpvScheme::Calibrated);
}

TEST(BenchErrorConfigs, BadListsNameTheOption) {
  const std::vector<std::pair<std::string, std::string>> badGrids = {
      {"", "empty"}, {"32,,64", "empty item"}, {"32,", "empty item"}, {"x", "'x'"}, {"1", "'1'"},
      {"32,32", "twice"}, {"-8", "'-8'"}, {"8.5", "'8.5'"}, {" 8", "' 8'"}};
  for (const auto& [text, why] : badGrids) {
    try {
      parseIntList("--grid", text, 2, kMaxLpvResolution);
      ADD_FAILURE() << "accepted --grid '" << text << "'";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("--grid"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(parseStepsList("--steps", "0"), InputError);
  EXPECT_THROW(parseStepsList("--steps", "auto,auto"), InputError);
  EXPECT_THROW(parseStepsList("--steps", "Auto"), InputError);
  EXPECT_THROW(parseSchemeList("--scheme", "seed,magic"), InputError);
  try {
    parseNameList("--backend", "cpu,metal", {"cpu", "vulkan"});
    ADD_FAILURE() << "accepted metal";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'metal' (expected cpu, vulkan)"), std::string::npos) << e.what();
  }
}

TEST(BenchErrorConfigs, Median) {
  EXPECT_DOUBLE_EQ(median({3, 1, 2}), 2.0);
  EXPECT_DOUBLE_EQ(median({4, 1, 3, 2}), 2.5);
  EXPECT_DOUBLE_EQ(median({9}), 9.0);
}

std::vector<BenchRow> sampleRows() {
  std::vector<BenchRow> rows(2);
  rows[0].scene = "examples/a,b.json";  // a comma: the field must be quoted
  rows[0].config = {"cpu", LpvScheme::Seed, 32, 8, 256};
  rows[0].stepsRun = 8;
  rows[0].ms = {1.5, 2.25, 3, 4, 5, 6, 21.75};
  rows[0].metrics.relativeMse = 0.04;
  rows[0].metrics.meanRelativeError = 0.125;
  rows[0].metrics.meanRelativeErrorRgb = glm::dvec3(0.25, 0.0625, 0.0625);
  rows[0].metrics.rmse = 0.5;
  rows[0].metrics.ssim = 0.875;
  rows[0].metrics.meanRatio = 1.0625;
  rows[0].pareto = true;
  rows[1] = rows[0];
  rows[1].scene = "b.json";
  rows[1].config = {"vulkan", LpvScheme::Calibrated, 64, std::nullopt, 512};
  rows[1].stepsRun = 230;
  rows[1].metrics.ssim = kNaN;
  rows[1].pareto = false;
  return rows;
}

TEST(BenchErrorTables, CsvHasTheDocumentedColumnsAndValues) {
  const std::vector<std::string> rows = lines(benchCsv(sampleRows()));
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0],
            "scene,backend,scheme,grid,steps_requested,steps_run,shadow_map,voxelize_ms,resample_ms,shadow_map_ms,"
            "injection_ms,propagation_ms,shading_ms,total_ms,relative_mse,mean_relative_error,"
            "mean_relative_error_r,mean_relative_error_g,mean_relative_error_b,rmse,ssim,mean_ratio,pareto");
  const std::vector<std::string> a = splitCsvLine(rows[1]);
  const std::vector<std::string> b = splitCsvLine(rows[2]);
  ASSERT_EQ(a.size(), benchColumns().size());
  ASSERT_EQ(b.size(), benchColumns().size());
  EXPECT_EQ(a[0], "examples/a,b.json");
  EXPECT_EQ(std::vector<std::string>(a.begin() + 1, a.end()),
            (std::vector<std::string>{"cpu", "seed", "32", "8", "8", "256", "1.500", "2.250", "3.000", "4.000",
                                      "5.000", "6.000", "21.750", "0.04", "0.125", "0.25", "0.0625", "0.0625", "0.5",
                                      "0.875", "1.0625", "1"}));
  EXPECT_EQ(b[1], "vulkan");
  EXPECT_EQ(b[2], "calibrated");
  EXPECT_EQ(b[4], "auto");
  EXPECT_EQ(b[5], "230");
  EXPECT_EQ(b[6], "512");
  EXPECT_EQ(b[20], "nan");
  EXPECT_EQ(b[22], "0");
}

TEST(BenchErrorTables, JsonRowsCarryEveryCsvColumn) {
  BenchRunInfo info;
  info.spp = 64;
  info.seed = 7;
  info.block = 4;
  info.repeats = 3;
  info.references.push_back({"examples/a,b.json", "/cache/a.exr", "reused", 12.5});
  info.skipped.push_back("skipped the 8 vulkan configurations: no Vulkan device (test)");
  const nlohmann::json j = nlohmann::json::parse(benchJson(info, sampleRows()));
  EXPECT_EQ(j.at("spp"), 64);
  EXPECT_EQ(j.at("seed"), 7);
  EXPECT_EQ(j.at("block"), 4);
  EXPECT_EQ(j.at("repeats"), 3);
  EXPECT_EQ(j.at("references").at(0).at("status"), "reused");
  EXPECT_DOUBLE_EQ(j.at("references").at(0).at("seconds").get<double>(), 12.5);
  EXPECT_EQ(j.at("skipped").size(), 1u);
  ASSERT_EQ(j.at("rows").size(), 2u);
  for (const nlohmann::json& row : j.at("rows")) {
    std::vector<std::string> keys;
    for (auto it = row.begin(); it != row.end(); ++it) keys.push_back(it.key());
    std::sort(keys.begin(), keys.end());
    std::vector<std::string> columns = benchColumns();
    std::sort(columns.begin(), columns.end());
    EXPECT_EQ(keys, columns);
  }
  const nlohmann::json& a = j.at("rows").at(0);
  EXPECT_EQ(a.at("steps_requested"), "8");
  EXPECT_EQ(a.at("steps_run"), 8);
  EXPECT_DOUBLE_EQ(a.at("total_ms").get<double>(), 21.75);
  EXPECT_DOUBLE_EQ(a.at("mean_relative_error").get<double>(), 0.125);
  EXPECT_DOUBLE_EQ(a.at("mean_relative_error_r").get<double>(), 0.25);
  EXPECT_EQ(a.at("pareto"), true);
  const nlohmann::json& b = j.at("rows").at(1);
  EXPECT_EQ(b.at("steps_requested"), "auto");
  EXPECT_TRUE(b.at("ssim").is_null());  // JSON has no NaN
  EXPECT_EQ(b.at("pareto"), false);
}

const char* kSceneText = R"({
  "mesh": {"path": "tetra.obj"},
  "material": {"base": {"preset": "marble"}},
  "lights": [{"type": "point", "position": [0, 5, 5], "intensity": [100, 100, 100]}],
  "camera": {"position": [0, 0, 10], "target": [0, 0, 0], "fov_y_deg": 35, "width": 32, "height": 32}
})";
const char* kTetra = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

TEST(BenchErrorCache, KeyFollowsTheContentOfTheSceneAndTheFilesItNames) {
  TempDir dir;
  writeText(dir / "tetra.obj", kTetra);
  writeText(dir / "scene.json", kSceneText);
  const std::string original = sceneContentHash(loadScene(dir / "scene.json"));
  EXPECT_EQ(original.size(), 16u);
  EXPECT_EQ(sceneContentHash(loadScene(dir / "scene.json")), original) << "the key must be deterministic";

  // The same bytes under another name: same reference.
  writeText(dir / "copy.json", kSceneText);
  EXPECT_EQ(sceneContentHash(loadScene(dir / "copy.json")), original);

  // One changed number in the scene file: another reference.
  std::string edited = kSceneText;
  edited.replace(edited.find("[100, 100, 100]"), 15, "[100, 100, 101]");
  writeText(dir / "scene.json", edited);
  const std::string afterSceneEdit = sceneContentHash(loadScene(dir / "scene.json"));
  EXPECT_NE(afterSceneEdit, original);

  // The LPV settings do not reach the path tracer: adding, then changing them keeps the
  // key.
  std::string withLpv = edited;
  withLpv.insert(withLpv.rfind('}'), R"(, "lpv": {"resolution": 32, "steps": 8})");
  writeText(dir / "scene.json", withLpv);
  EXPECT_EQ(sceneContentHash(loadScene(dir / "scene.json")), afterSceneEdit);
  withLpv.replace(withLpv.find("\"steps\": 8"), 10, "\"steps\": \"auto\"");
  writeText(dir / "scene.json", withLpv);
  EXPECT_EQ(sceneContentHash(loadScene(dir / "scene.json")), afterSceneEdit);
  writeText(dir / "scene.json", edited);

  // The mesh file changes, the scene file does not: another reference too.
  writeText(dir / "tetra.obj", std::string(kTetra) + "# moved\n");
  const std::string afterMeshEdit = sceneContentHash(loadScene(dir / "scene.json"));
  EXPECT_NE(afterMeshEdit, afterSceneEdit);
  // The tracer's light-connection mode is part of the key when it is given.
  EXPECT_NE(sceneContentHash(loadScene(dir / "scene.json"), "exact flat-face light connections"), afterMeshEdit);
}

TEST(BenchErrorCache, ASavedAgainMaterialSetKeepsItsKeyAndAChangedVoxelDoesNot) {
  // OpenVDB writes a new random UUID into every file; only the grids may count.
  TempDir dir;
  MaterialSet set;
  set.sigmaT = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  set.sigmaS = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  set.sigmaT->tree().setValue(openvdb::Coord(0, 0, 0), openvdb::Vec3s(2.0f));
  set.sigmaS->tree().setValue(openvdb::Coord(0, 0, 0), openvdb::Vec3s(1.0f));
  saveMaterialSet(set, dir / "set.vdb");
  writeText(dir / "tetra.obj", kTetra);
  std::string text = kSceneText;
  const std::string base = R"({"preset": "marble"})";
  text.replace(text.find(base), base.size(), base + R"(, "vdb": "set.vdb")");
  writeText(dir / "scene.json", text);
  const std::string first = sceneContentHash(loadScene(dir / "scene.json"));
  const std::string firstBytes = readText(dir / "set.vdb");

  saveMaterialSet(set, dir / "set.vdb");
  ASSERT_NE(readText(dir / "set.vdb"), firstBytes) << "OpenVDB no longer writes a random UUID; this test is moot";
  EXPECT_EQ(sceneContentHash(loadScene(dir / "scene.json")), first);

  set.sigmaS->tree().setValue(openvdb::Coord(0, 0, 0), openvdb::Vec3s(1.5f));
  saveMaterialSet(set, dir / "set.vdb");
  EXPECT_NE(sceneContentHash(loadScene(dir / "scene.json")), first);
}

TEST(BenchErrorCache, FileHashSeesEveryByte) {
  TempDir dir;
  std::string bytes(4096, 'x');
  writeText(dir / "a.exr", bytes);
  const std::string original = fileContentHash(dir / "a.exr");
  bytes[2000] ^= 1;  // one flipped bit in the middle
  writeText(dir / "a.exr", bytes);
  EXPECT_NE(fileContentHash(dir / "a.exr"), original);
  EXPECT_THROW(fileContentHash(dir / "missing.exr"), InputError);
}

TEST(BenchErrorCache, StemNamesSceneHashSppAndSeed) {
  Scene scene;
  scene.file = "/x/skin_sphere.json";
  EXPECT_EQ(referenceCacheStem(scene, "0123456789abcdef", 64, 3), "skin_sphere-0123456789abcdef-spp64-seed3");
  EXPECT_NE(referenceCacheStem(scene, "0123456789abcdef", 64, 3), referenceCacheStem(scene, "0123456789abcdef", 65, 3));
  EXPECT_NE(referenceCacheStem(scene, "0123456789abcdef", 64, 3), referenceCacheStem(scene, "0123456789abcdef", 64, 4));
}

TEST(BenchErrorCache, SidecarRoundTripsAndRejectsTruncation) {
  const ReferenceSidecar s{"examples/skin_sphere.json", "0123456789abcdef", "fedcba9876543210", 64, 9, 12.25, 512,
                          384};
  const std::string text = referenceSidecarJson(s);
  const std::optional<ReferenceSidecar> back = parseReferenceSidecar(text);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->scene, s.scene);
  EXPECT_EQ(back->hash, s.hash);
  EXPECT_EQ(back->imageHash, s.imageHash);
  EXPECT_EQ(back->spp, 64);
  EXPECT_EQ(back->seed, 9u);
  EXPECT_DOUBLE_EQ(back->seconds, 12.25);
  EXPECT_EQ(back->width, 512);
  EXPECT_EQ(back->height, 384);
  EXPECT_FALSE(parseReferenceSidecar(text.substr(0, text.size() / 2)).has_value());
  EXPECT_FALSE(parseReferenceSidecar("").has_value());
  EXPECT_FALSE(parseReferenceSidecar(R"({"scene": "x"})").has_value());
}

}  // namespace
}  // namespace sslpv::test
