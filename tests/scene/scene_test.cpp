// The strict scene contract (docs/design.md §3 "Scene contract"): every value of a full scene is read,
// optional keys take their documented defaults, and every bad input is an InputError whose
// one-line message names the file and the key path.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/constants.hpp>
#include <nlohmann/json.hpp>

#include "test_support.h"
#include "volume/core/error.h"
#include "volume/scene/scene.h"

namespace sslpv {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const fs::path kSceneFile = fs::path("/scenes/project") / "scene.json";

json fullScene() {
  return json::parse(R"({
    "units": "mm",
    "mesh": {"path": "meshes/bunny.ply"},
    "transform": {"translate": [1, 2, 3], "rotate_deg": [10, 20, 30], "scale": 2.5},
    "material": {
      "base": {"sigma_t": [1.0, 2.0, 3.0], "sigma_s": [0.5, 1.5, 3.0], "g": 0.25},
      "vdb": "veins.vdb",
      "ior": 1.4
    },
    "lights": [
      {"type": "point", "position": [0, 5, 0], "intensity": [10, 20, 30]},
      {"type": "spot", "position": [1, 2, 3], "direction": [0, 0, -2], "fov_deg": 40,
       "intensity": [1, 2, 3]},
      {"type": "directional", "direction": [0, -3, 4], "irradiance": [0.5, 0.25, 0]}
    ],
    "camera": {"position": [0, 1, 10], "target": [0, 1, 0], "up": [0, 2, 0],
               "fov_y_deg": 35, "width": 640, "height": 480},
    "lpv": {"resolution": 64, "steps": 12, "shadow_map": 512}
  })");
}

json minimalScene() {
  return json::parse(R"({
    "mesh": {"primitive": "sphere", "center": [0, 0, 0], "radius": 1},
    "material": {"base": {"preset": "marble"}},
    "lights": [{"type": "point", "position": [0, 5, 0], "intensity": [1, 1, 1]}],
    "camera": {"position": [0, 0, 5], "target": [0, 0, 0], "fov_y_deg": 30,
               "width": 64, "height": 32}
  })");
}

Scene parse(const json& scene) { return parseScene(scene.dump(), kSceneFile); }

std::string errorOfText(const std::string& text) {
  try {
    parseScene(text, kSceneFile);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError for: " << text;
  return {};
}

std::string errorOf(const json& scene) { return errorOfText(scene.dump()); }

/// The message names the file and the key path, is one line, and contains `reason` if given.
void expectError(const json& scene, const std::string& keyPath, const std::string& reason = "") {
  std::string message = errorOf(scene);
  EXPECT_EQ(message.rfind(kSceneFile.string() + ": ", 0), 0u) << message;
  EXPECT_NE(message.find(keyPath + ": "), std::string::npos) << "want key path " << keyPath << " in: " << message;
  EXPECT_NE(message.find(reason), std::string::npos) << "want '" << reason << "' in: " << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

TEST(Scene, FullSceneReadsEveryValue) {
  Scene s = parse(fullScene());
  EXPECT_EQ(s.file, kSceneFile);
  EXPECT_EQ(s.units, "mm");
  EXPECT_EQ(s.unitInMm, 1.0);

  EXPECT_EQ(s.mesh.kind, MeshSource::Kind::File);
  EXPECT_EQ(s.mesh.path, fs::path("/scenes/project/meshes/bunny.ply"));

  EXPECT_EQ(s.transform.translate, glm::dvec3(1, 2, 3));
  EXPECT_EQ(s.transform.rotateDeg, glm::dvec3(10, 20, 30));
  EXPECT_EQ(s.transform.scale, 2.5);

  EXPECT_EQ(s.material.presetName, "");
  EXPECT_EQ(s.material.base.sigmaT, glm::vec3(1, 2, 3));
  EXPECT_EQ(s.material.base.sigmaS, glm::vec3(0.5f, 1.5f, 3.0f));
  EXPECT_FLOAT_EQ(s.material.base.g, 0.25f);
  ASSERT_TRUE(s.material.vdb.has_value());
  EXPECT_EQ(*s.material.vdb, fs::path("/scenes/project/veins.vdb"));
  EXPECT_DOUBLE_EQ(s.material.ior, 1.4);

  ASSERT_EQ(s.lights.size(), 3u);
  EXPECT_EQ(s.lights[0].type, Light::Type::Point);
  EXPECT_EQ(s.lights[0].position, glm::dvec3(0, 5, 0));
  EXPECT_EQ(s.lights[0].intensity, glm::vec3(10, 20, 30));
  EXPECT_EQ(s.lights[1].type, Light::Type::Spot);
  EXPECT_EQ(s.lights[1].position, glm::dvec3(1, 2, 3));
  EXPECT_EQ(s.lights[1].direction, glm::dvec3(0, 0, -1));  // normalized
  EXPECT_DOUBLE_EQ(s.lights[1].fovDeg, 40.0);
  EXPECT_EQ(s.lights[1].intensity, glm::vec3(1, 2, 3));
  EXPECT_EQ(s.lights[2].type, Light::Type::Directional);
  EXPECT_NEAR(s.lights[2].direction.y, -0.6, 1e-15);
  EXPECT_NEAR(s.lights[2].direction.z, 0.8, 1e-15);
  EXPECT_EQ(s.lights[2].irradiance, glm::vec3(0.5f, 0.25f, 0.0f));

  EXPECT_EQ(s.camera.position, glm::dvec3(0, 1, 10));
  EXPECT_EQ(s.camera.target, glm::dvec3(0, 1, 0));
  EXPECT_EQ(s.camera.up, glm::dvec3(0, 1, 0));  // normalized
  EXPECT_DOUBLE_EQ(s.camera.fovYDeg, 35.0);
  EXPECT_EQ(s.camera.width, 640);
  EXPECT_EQ(s.camera.height, 480);

  EXPECT_EQ(s.lpv.resolution, 64);
  EXPECT_EQ(s.lpv.steps, 12);
  EXPECT_FALSE(s.lpv.autoSteps);
  EXPECT_EQ(s.lpv.shadowMap, 512);
}

TEST(Scene, OptionalKeysTakeDocumentedDefaults) {
  Scene s = parse(minimalScene());
  EXPECT_EQ(s.units, "mm");
  EXPECT_EQ(s.unitInMm, 1.0);
  EXPECT_EQ(s.transform.translate, glm::dvec3(0.0));
  EXPECT_EQ(s.transform.rotateDeg, glm::dvec3(0.0));
  EXPECT_EQ(s.transform.scale, 1.0);
  EXPECT_EQ(s.transform.matrix(), glm::dmat4(1.0));
  EXPECT_FALSE(s.material.vdb.has_value());
  EXPECT_EQ(s.material.ior, 1.0);
  EXPECT_EQ(s.material.presetName, "marble");
  EXPECT_EQ(s.material.base.g, 0.0f);
  EXPECT_EQ(s.camera.up, glm::dvec3(0, 1, 0));
  EXPECT_EQ(s.lpv.resolution, 32);
  EXPECT_TRUE(s.lpv.autoSteps) << "no lpv block: propagate until converged, not a fixed 8 steps";
  EXPECT_EQ(s.lpv.shadowMap, 256);
  EXPECT_EQ(s.mesh.kind, MeshSource::Kind::Sphere);
  EXPECT_EQ(s.mesh.center, glm::dvec3(0.0));
  EXPECT_EQ(s.mesh.radius, 1.0);
}

TEST(Scene, PartialTransformAndLpvBlocksDefaultTheRest) {
  json j = minimalScene();
  j["transform"] = {{"scale", 3}};
  j["lpv"] = {{"steps", 20}};
  Scene s = parse(j);
  EXPECT_EQ(s.transform.scale, 3.0);
  EXPECT_EQ(s.transform.translate, glm::dvec3(0.0));
  EXPECT_EQ(s.lpv.steps, 20);
  EXPECT_EQ(s.lpv.resolution, 32);
  EXPECT_EQ(s.lpv.shadowMap, 256);
  j["lpv"] = {{"resolution", 16}};
  s = parse(j);
  EXPECT_EQ(s.lpv.steps, 8);
  EXPECT_FALSE(s.lpv.autoSteps) << "an lpv block without steps keeps the fixed default";
}

TEST(Scene, ExplicitBaseGDefaultsToZero) {
  json j = minimalScene();
  j["material"]["base"] = {{"sigma_t", {1, 1, 1}}, {"sigma_s", {1, 1, 1}}};
  Scene s = parse(j);
  EXPECT_EQ(s.material.base.g, 0.0f);
  EXPECT_EQ(s.material.base.sigmaS, s.material.base.sigmaT);  // albedo exactly 1 is valid
}

TEST(Scene, StepsAutoSetsAutoSteps) {
  json j = minimalScene();
  j["lpv"] = {{"steps", "auto"}};
  EXPECT_TRUE(parse(j).lpv.autoSteps);
}

TEST(Scene, BoxPrimitive) {
  json j = minimalScene();
  j["mesh"] = json::parse(R"({"primitive": "box", "min": [-1, -2, -3], "max": [1, 2, 3]})");
  Scene s = parse(j);
  EXPECT_EQ(s.mesh.kind, MeshSource::Kind::Box);
  EXPECT_EQ(s.mesh.boxMin, glm::dvec3(-1, -2, -3));
  EXPECT_EQ(s.mesh.boxMax, glm::dvec3(1, 2, 3));
}

TEST(Scene, PresetInCentimetresIsTenTimesPerMillimetre) {
  json j = minimalScene();
  j["units"] = "cm";
  j["material"]["base"] = {{"preset", "skin1"}, {"g", 0.5}};
  Scene s = parse(j);
  EXPECT_EQ(s.unitInMm, 10.0);
  EXPECT_EQ(s.material.presetName, "skin1");
  EXPECT_FLOAT_EQ(s.material.base.g, 0.5f);
  // skin1 red: sigma_s' = 0.74 /mm, sigma_a = 0.032 /mm; g = 0.5 doubles sigma_s.
  EXPECT_NEAR(s.material.base.sigmaS.r, 0.74 / 0.5 * 10.0, 1e-4);
  EXPECT_NEAR(s.material.base.sigmaT.r, (0.74 / 0.5 + 0.032) * 10.0, 1e-4);
}

TEST(Scene, UnitsAcceptEveryListedUnit) {
  for (auto [name, mm] : {std::pair{"mm", 1.0}, {"cm", 10.0}, {"m", 1000.0}, {"in", 25.4}}) {
    json j = minimalScene();
    j["units"] = name;
    EXPECT_EQ(parse(j).unitInMm, mm) << name;
  }
}

TEST(Scene, PathsResolveAgainstSceneFolderNotWorkingDirectory) {
  json j = minimalScene();
  j["mesh"] = {{"path", "../meshes/mesh.obj"}};
  j["material"]["vdb"] = "sets/a.vdb";
  Scene s = parseScene(j.dump(), fs::path("/data/scenes/s.json"));
  EXPECT_EQ(s.mesh.path, fs::path("/data/meshes/mesh.obj"));
  EXPECT_EQ(*s.material.vdb, fs::path("/data/scenes/sets/a.vdb"));

  j["mesh"]["path"] = "/abs/m.ply";
  Scene absolute = parseScene(j.dump(), fs::path("/data/scenes/s.json"));
  EXPECT_EQ(absolute.mesh.path, fs::path("/abs/m.ply"));
}

TEST(Scene, LoadSceneReadsFileAndResolvesRelativeToIt) {
  test::TempDir dir;
  fs::create_directories(dir / "sub");
  json j = minimalScene();
  j["mesh"] = {{"path", "bunny.ply"}};
  test::writeText(dir / "sub" / "scene.json", j.dump(2));
  Scene s = loadScene(dir / "sub" / "scene.json");
  EXPECT_EQ(s.mesh.path, dir.path() / "sub" / "bunny.ply");  // the file need not exist yet
  EXPECT_EQ(s.file, dir / "sub" / "scene.json");
}

TEST(Scene, MissingFileNamesFileAndReason) {
  test::TempDir dir;
  fs::path missing = dir / "nope.json";
  try {
    loadScene(missing);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), missing.string() + ": cannot read scene file (No such file or directory)");
  }
  try {
    loadScene(dir.path());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot read scene file (Is a directory)"), std::string::npos) << e.what();
  }
}

TEST(Scene, EmptyFile) {
  test::TempDir dir;
  test::writeText(dir / "empty.json", "");
  try {
    loadScene(dir / "empty.json");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), (dir / "empty.json").string() + ": empty file");
  }
  EXPECT_EQ(errorOfText("  \n\t "), kSceneFile.string() + ": empty file");
}

TEST(Scene, MalformedJsonReportsLineAndColumn) {
  // The missing comma is detected when the parser has read the second key: the location
  // is the last character of that token ("mesh" ends at line 3, column 8).
  std::string message = errorOfText("{\n  \"units\": \"mm\"\n  \"mesh\": {}\n}");
  EXPECT_EQ(message.rfind(kSceneFile.string() + ": line 3, column 8: malformed JSON: ", 0), 0u) << message;
  EXPECT_EQ(message.find("[json.exception"), std::string::npos) << message;

  message = errorOfText("{\"units\": \"mm\",");
  EXPECT_NE(message.find("line 1, column "), std::string::npos) << message;
  EXPECT_NE(message.find("malformed JSON"), std::string::npos) << message;

  message = errorOfText("{\"lpv\": {\"steps\": 1e999}}");
  EXPECT_NE(message.find("malformed JSON: number overflow"), std::string::npos) << message;
}

TEST(Scene, DuplicateKeyIsNamedWithItsPath) {
  EXPECT_EQ(errorOfText(R"({"lpv": {"steps": 4, "steps": 5}})"),
            kSceneFile.string() + ": lpv.steps: duplicate key");
  std::string message = errorOfText(
      R"({"lights": [{"type": "point"}, {"type": "point", "intensity": [1,1,1], "intensity": [2,2,2]}]})");
  EXPECT_EQ(message, kSceneFile.string() + ": lights[1].intensity: duplicate key");
}

TEST(Scene, TopLevelMustBeObject) {
  expectError(json::array(), "", "expected a JSON object at the top level");
}

TEST(Scene, UnknownKeysAreNamedWithTheAcceptedKeys) {
  json j = fullScene();
  j["lihgts"] = json::array();
  expectError(j, "lihgts", "unknown key (accepted keys: \"units\", \"mesh\"");

  j = fullScene();
  j["camera"]["fov"] = 30;
  expectError(j, "camera.fov", "\"fov_y_deg\"");

  j = fullScene();
  j["lights"][2]["position"] = {0, 0, 0};  // directional lights have no position
  expectError(j, "lights[2].position", "accepted keys: \"type\", \"direction\", \"irradiance\"");

  j = fullScene();
  j["material"]["base"]["albedo"] = 0.5;
  expectError(j, "material.base.albedo", "unknown key");

  j = fullScene();
  j["lpv"]["grid"] = 4;
  expectError(j, "lpv.grid", "unknown key");

  j = fullScene();
  j["transform"]["rotate"] = {0, 0, 0};
  expectError(j, "transform.rotate", "unknown key");

  j = fullScene();
  j["mesh"]["radius"] = 1;
  expectError(j, "mesh.radius", "unknown key");

  j = minimalScene();
  j["material"]["base"]["sigma_t"] = {1, 1, 1};  // mixing a preset with explicit sigmas
  expectError(j, "material.base.sigma_t", "unknown key");
}

TEST(Scene, UnknownKeyWithControlCharacterStaysOneLine) {
  json j = minimalScene();
  j["camera"]["a\nb"] = 1;
  expectError(j, "camera.a\\u000ab", "unknown key");
}

TEST(Scene, MissingRequiredKeys) {
  for (const char* key : {"mesh", "material", "lights", "camera"}) {
    json j = minimalScene();
    j.erase(key);
    expectError(j, kSceneFile.string(), std::string("missing required key \"") + key + "\"");
  }
  json j = minimalScene();
  j["camera"].erase("width");
  expectError(j, "camera", "missing required key \"width\"");
  j = fullScene();
  j["lights"][1].erase("fov_deg");
  expectError(j, "lights[1]", "missing required key \"fov_deg\"");
  j = fullScene();
  j["material"]["base"].erase("sigma_s");
  expectError(j, "material.base", "missing required key \"sigma_s\"");
  j = fullScene();
  j["material"].erase("base");
  expectError(j, "material", "missing required key \"base\"");
  j = fullScene();
  j["mesh"] = json::object();
  expectError(j, "mesh", "\"path\" or \"primitive\"");
  j = fullScene();
  j["mesh"] = {{"primitive", "sphere"}, {"center", {0, 0, 0}}};
  expectError(j, "mesh", "missing required key \"radius\"");
  j = fullScene();
  j["lights"][0].erase("type");
  expectError(j, "lights[0]", "missing required key \"type\"");
}

TEST(Scene, WrongTypes) {
  json j = fullScene();
  j["camera"]["width"] = "640";
  expectError(j, "camera.width", "expected an integer in [1, 16384], got a string");
  j = fullScene();
  j["camera"]["width"] = 640.5;
  expectError(j, "camera.width", "expected an integer");
  j = fullScene();
  j["lights"][1]["intensity"] = {1, 2};
  expectError(j, "lights[1].intensity", "expected an array of 3 non-negative numbers, got an array of 2");
  j = fullScene();
  j["lights"][1]["intensity"] = {1, "2", 3};
  expectError(j, "lights[1].intensity[1]", "got a string");
  j = fullScene();
  j["lights"] = json::object();
  expectError(j, "lights", "expected an array of lights, got an object");
  j = fullScene();
  j["camera"] = json::array();
  expectError(j, "camera", "expected an object");
  j = fullScene();
  j["units"] = 1;
  expectError(j, "units", "expected a string");
  j = fullScene();
  j["mesh"]["path"] = true;
  expectError(j, "mesh.path", "expected a string, got a boolean");
  j = fullScene();
  j["material"]["ior"] = nullptr;
  expectError(j, "material.ior", "expected a number, got null");
  j = fullScene();
  j["lights"][0]["type"] = 3;
  expectError(j, "lights[0].type", "expected a string");
  j = fullScene();
  j["lights"][0] = 3;
  expectError(j, "lights[0]", "expected an object");
}

TEST(Scene, WholeNumberWrittenAsFloatIsAnInteger) {
  json j = minimalScene();
  j["camera"]["width"] = 128.0;
  EXPECT_EQ(parse(j).camera.width, 128);
}

TEST(Scene, NegativeRadiometricValues) {
  json j = fullScene();
  j["lights"][1]["intensity"] = {1, -2, 3};
  expectError(j, "lights[1].intensity[1]", "expected a non-negative number, got -2");
  j = fullScene();
  j["lights"][2]["irradiance"] = {-0.5, 0, 0};
  expectError(j, "lights[2].irradiance[0]", "non-negative");
  j = fullScene();
  j["material"]["base"]["sigma_t"] = {1, -1, 1};
  expectError(j, "material.base.sigma_t[1]", "non-negative");
  j = fullScene();
  j["material"]["base"]["sigma_s"] = {0.5, 1.5, -3};
  expectError(j, "material.base.sigma_s[2]", "non-negative");
}

TEST(Scene, AlbedoAboveOneIsRejected) {
  json j = fullScene();
  j["material"]["base"]["sigma_s"] = {0.5, 2.5, 3.0};  // sigma_t.g is 2
  expectError(j, "material.base.sigma_s[1]", "exceeds sigma_t (2.5 > 2): albedo above 1");
}

TEST(Scene, AsymmetryMustBeInsideOpenUnitInterval) {
  for (double g : {1.0, -1.0, 1.5}) {
    json j = fullScene();
    j["material"]["base"]["g"] = g;
    expectError(j, "material.base.g", "must be in (-1, 1)");
    j = minimalScene();
    j["material"]["base"]["g"] = g;
    expectError(j, "material.base.g", "must be in (-1, 1)");
  }
}

TEST(Scene, IorRange) {
  for (double ior : {0.1, 0.0, -1.5, 15.0}) {
    json j = fullScene();
    j["material"]["ior"] = ior;
    expectError(j, "material.ior", "must be in [0.2, 5]");
  }
  json j = fullScene();
  j["material"]["ior"] = 0.75;  // an object less dense than its surrounding is valid
  EXPECT_DOUBLE_EQ(parse(j).material.ior, 0.75);
}

TEST(Scene, AnglesMustBeInsideOpenInterval) {
  for (double fov : {0.0, 180.0, -10.0, 200.0}) {
    json j = fullScene();
    j["lights"][1]["fov_deg"] = fov;
    expectError(j, "lights[1].fov_deg", "must be in (0, 180)");
    j = fullScene();
    j["camera"]["fov_y_deg"] = fov;
    expectError(j, "camera.fov_y_deg", "must be in (0, 180)");
  }
}

TEST(Scene, IntegerLimits) {
  struct Case {
    const char* block;
    const char* key;
    std::vector<json> bad;
  };
  std::vector<Case> cases = {
      {"camera", "width", {0, -1, kMaxImageSide + 1}},
      {"camera", "height", {0, kMaxImageSide + 1, 1e12}},
      {"lpv", "resolution", {1, kMaxLpvResolution + 1}},
      {"lpv", "steps", {0, kMaxSteps + 1, "many"}},
      {"lpv", "shadow_map", {0, kMaxShadowMap + 1}},
  };
  for (const auto& c : cases) {
    for (const auto& value : c.bad) {
      json j = fullScene();
      j[c.block][c.key] = value;
      expectError(j, std::string(c.block) + "." + c.key, "expected an integer in [");
    }
  }
  json j = fullScene();
  j["camera"]["width"] = kMaxImageSide;
  j["lpv"]["resolution"] = 2;
  j["lpv"]["steps"] = kMaxSteps;
  j["lpv"]["shadow_map"] = kMaxShadowMap;
  Scene s = parse(j);
  EXPECT_EQ(s.camera.width, kMaxImageSide);
  EXPECT_EQ(s.lpv.resolution, 2);
  EXPECT_EQ(s.lpv.steps, kMaxSteps);
  EXPECT_EQ(s.lpv.shadowMap, kMaxShadowMap);
}

TEST(Scene, StepsStringOtherThanAutoNamesBothForms) {
  json j = fullScene();
  j["lpv"]["steps"] = "Auto";
  expectError(j, "lpv.steps", "or \"auto\", got \"Auto\"");
}

TEST(Scene, BoxMustHavePositiveExtentOnEveryAxis) {
  json j = minimalScene();
  j["mesh"] = json::parse(R"({"primitive": "box", "min": [0, 0, 0], "max": [1, 0, 1]})");
  expectError(j, "mesh.max", "y: 0 <= 0");
  j["mesh"] = json::parse(R"({"primitive": "box", "min": [0, 0, 2], "max": [1, 1, 1]})");
  expectError(j, "mesh.max", "z: 1 <= 2");
}

TEST(Scene, SphereRadiusMustBePositive) {
  for (double r : {0.0, -1.0}) {
    json j = minimalScene();
    j["mesh"]["radius"] = r;
    expectError(j, "mesh.radius", "must be positive");
  }
}

TEST(Scene, UnknownPrimitiveListsAccepted) {
  json j = minimalScene();
  j["mesh"] = {{"primitive", "torus"}};
  expectError(j, "mesh.primitive", "unknown primitive \"torus\" (accepted: \"box\", \"sphere\")");
  j["mesh"] = {{"primitive", "box"}, {"path", "a.obj"}};
  expectError(j, "mesh", "not both");
}

TEST(Scene, TransformScaleMustBePositive) {
  for (double scale : {0.0, -2.0}) {
    json j = fullScene();
    j["transform"]["scale"] = scale;
    expectError(j, "transform.scale", "must be positive");
  }
  json j = fullScene();
  j["transform"]["scale"] = {1, 2, 3};
  expectError(j, "transform.scale", "expected a number, got an array");
}

TEST(Scene, ZeroDirectionsAreRejected) {
  json j = fullScene();
  j["lights"][1]["direction"] = {0, 0, 0};
  expectError(j, "lights[1].direction", "non-zero direction");
  j = fullScene();
  j["lights"][2]["direction"] = {0, 0, 0};
  expectError(j, "lights[2].direction", "non-zero direction");
  j = fullScene();
  j["camera"]["up"] = {0, 0, 0};
  expectError(j, "camera.up", "non-zero direction");
}

TEST(Scene, CameraUpParallelToViewIsRejected) {
  json j = fullScene();  // looks along -z
  j["camera"]["up"] = {0, 0, 3};
  expectError(j, "camera.up", "parallel to the view direction");
  j["camera"]["up"] = {0, 0, -1};
  expectError(j, "camera.up", "parallel");
}

TEST(Scene, CameraTargetAtPositionIsRejected) {
  json j = fullScene();
  j["camera"]["target"] = j["camera"]["position"];
  expectError(j, "camera.target", "equals camera.position");
}

TEST(Scene, LightsMustBeNonEmptyWithKnownTypes) {
  json j = fullScene();
  j["lights"] = json::array();
  expectError(j, "lights", "at least one light");
  j = fullScene();
  j["lights"][1]["type"] = "area";
  expectError(j, "lights[1].type", "unknown light type \"area\" (accepted: \"point\", \"spot\", \"directional\")");
}

TEST(Scene, UnknownPresetListsPresetNames) {
  json j = minimalScene();
  j["material"]["base"]["preset"] = "jade";
  expectError(j, "material.base.preset", "unknown preset \"jade\" (accepted: apple, chicken1, chicken2");
}

TEST(Scene, UnknownUnitsListsAccepted) {
  json j = minimalScene();
  j["units"] = "ft";
  expectError(j, "units", "unknown unit \"ft\" (accepted: \"mm\", \"cm\", \"m\", \"in\")");
}

TEST(Scene, EmptyPathsAreRejected) {
  json j = minimalScene();
  j["mesh"] = {{"path", ""}};
  expectError(j, "mesh.path", "non-empty");
  j = fullScene();
  j["material"]["vdb"] = "";
  expectError(j, "material.vdb", "non-empty");
}

TEST(Transform, ScaleThenRotateXYZThenTranslate) {
  Transform t;
  t.scale = 2.0;
  t.rotateDeg = {90, 90, 0};
  t.translate = {10, 20, 30};
  // (0,1,0) scaled: (0,2,0); about X by 90: (0,0,2); about Y by 90: (2,0,0); then moved.
  glm::dvec4 p = t.matrix() * glm::dvec4(0, 1, 0, 1);
  EXPECT_NEAR(p.x, 12.0, 1e-12);
  EXPECT_NEAR(p.y, 20.0, 1e-12);
  EXPECT_NEAR(p.z, 30.0, 1e-12);

  Transform z;
  z.rotateDeg = {0, 0, 90};  // right-handed: +x goes to +y
  glm::dvec4 q = z.matrix() * glm::dvec4(1, 0, 0, 1);
  EXPECT_NEAR(q.x, 0.0, 1e-12);
  EXPECT_NEAR(q.y, 1.0, 1e-12);
}

}  // namespace
}  // namespace sslpv
