// Updating one value of a scene file leaves every other byte as the author wrote it
// (volume/scene/scene_file_edit.h): the expected texts below are the inputs with exactly the
// one value changed, compared byte for byte.
#include <gtest/gtest.h>

#include "test_support.h"
#include "volume/core/error.h"
#include "volume/scene/scene.h"
#include "volume/scene/scene_file_edit.h"

namespace sslpv::test {
namespace {

namespace fs = std::filesystem;

// Hand formatting a generic JSON writer would not reproduce: arrays on one line, aligned
// values, a number spelt "1e3", a tab, CRLF nowhere but in one line, no final newline.
const std::string kScene =
    "{\n"
    "  \"units\":    \"mm\",\n"
    "  \"mesh\": {\"primitive\": \"box\", \"min\": [-5, -5, -5], \"max\": [5, 5, 5]},\n"
    "  \"material\": {\n"
    "    \"base\": {\"preset\": \"marble\"},\n"
    "    \"vdb\":  \"old set.vdb\",\n"
    "\t\"ior\": 1.3\r\n"
    "  },\n"
    "  \"lights\": [{\"type\": \"point\", \"position\": [20, 30, 40], \"intensity\": 1e3}],\n"
    "  \"camera\": {\"position\": [0, 10, 40], \"target\": [0, 0, 0],\n"
    "             \"fov_y_deg\": 35, \"width\": 64, \"height\": 64}\n"
    "}";

std::string replaced(const std::string& text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  EXPECT_EQ(text.find(from, at + 1), std::string::npos) << "ambiguous: " << from;
  return text.substr(0, at) + to + text.substr(at + from.size());
}

TEST(SpliceJsonValue, ReplacesOnlyTheValueOfAnExistingKey) {
  const std::string out = spliceJsonValue(kScene, {"material", "vdb"}, "\"painted.vdb\"", "scene.json");
  EXPECT_EQ(out, replaced(kScene, "\"old set.vdb\"", "\"painted.vdb\""));
}

TEST(SpliceJsonValue, ReplacesAnArrayAndANestedNumber) {
  const std::string position =
      spliceJsonValue(kScene, {"camera", "position"}, "[1.5, 2, -3]", "scene.json");
  EXPECT_EQ(position, replaced(kScene, "[0, 10, 40], \"target\"", "[1.5, 2, -3], \"target\""));
  const std::string fov = spliceJsonValue(kScene, {"camera", "fov_y_deg"}, "40", "scene.json");
  EXPECT_EQ(fov, replaced(kScene, "\"fov_y_deg\": 35", "\"fov_y_deg\": 40"));
}

TEST(SpliceJsonValue, AMissingKeyIsAddedLaidOutLikeTheMemberBeforeIt) {
  const std::string noVdb = replaced(kScene, "    \"vdb\":  \"old set.vdb\",\n", "");
  const std::string out = spliceJsonValue(noVdb, {"material", "vdb"}, "\"a.vdb\"", "scene.json");
  // The last member was "\t\"ior\": 1.3" after ",\n": the new one follows it the same way.
  EXPECT_EQ(out, replaced(noVdb, "\t\"ior\": 1.3\r\n", "\t\"ior\": 1.3,\n\t\"vdb\": \"a.vdb\"\r\n"));
  EXPECT_NO_THROW(parseScene(out, "scene.json"));
  const std::string up = spliceJsonValue(kScene, {"camera", "up"}, "[0, 1, 0]", "scene.json");
  EXPECT_EQ(up, replaced(kScene, "\"height\": 64}", "\"height\": 64, \"up\": [0, 1, 0]}"));
}

TEST(SpliceJsonValue, KeysInsideStringsAndEscapesDoNotConfuseIt) {
  const std::string text = "{\"a\": \"\\\"vdb\\\": {\", \"b\": {\"vdb\": [\"}\", {\"x\": 1}], \"c\": true}, \"vdb\": 2}";
  EXPECT_EQ(spliceJsonValue(text, {"vdb"}, "3", "f.json"),
            "{\"a\": \"\\\"vdb\\\": {\", \"b\": {\"vdb\": [\"}\", {\"x\": 1}], \"c\": true}, \"vdb\": 3}");
  EXPECT_EQ(spliceJsonValue(text, {"b", "c"}, "false", "f.json"),
            "{\"a\": \"\\\"vdb\\\": {\", \"b\": {\"vdb\": [\"}\", {\"x\": 1}], \"c\": false}, \"vdb\": 2}");
  EXPECT_EQ(spliceJsonValue("{}", {"k"}, "1", "f.json"), "{\"k\": 1}");
}

TEST(SpliceJsonValue, RefusesTextThatIsNotJsonOrAMissingParentNamingTheKey) {
  try {
    spliceJsonValue("{\"material\": ", {"material", "vdb"}, "1", "s.json");
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("s.json"), std::string::npos) << e.what();
  }
  try {
    spliceJsonValue("{\"units\": \"mm\"}", {"material", "vdb"}, "1", "s.json");
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("s.json: material: missing"), std::string::npos) << e.what();
  }
}

TEST(SceneTextNamingVdb, NamesTheSetRelativeToTheSceneFolder) {
  TempDir dir;
  const fs::path scene = dir / "scene.json";
  fs::create_directories(dir / "sets");
  const std::string out = sceneTextNamingVdb(scene, kScene, dir / "sets" / "painted.vdb");
  EXPECT_EQ(out, replaced(kScene, "\"old set.vdb\"", "\"sets/painted.vdb\""));
}

}  // namespace
}  // namespace sslpv::test
