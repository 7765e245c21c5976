#pragma once
// The CLI failure contract shared by the CLI test binaries: a small valid scene, material
// sets written with OpenVDB directly (so they can be invalid), and the CliRejects fixture
// whose expectRejected checks exit code, the one-line message, the untouched output and
// that no file was left behind.
#include <gtest/gtest.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "test_support.h"

namespace sslpv::test {

/// What out.png holds before each failing run; it must hold exactly this afterwards.
inline const std::string kPreexistingOutput = "not a png: bytes a failed run must leave untouched\n";

/// A small valid scene that renders in a fraction of a second.
inline nlohmann::json smallScene() {
  return nlohmann::json::parse(R"({
    "units": "mm",
    "mesh": {"primitive": "box", "min": [-5, -5, -5], "max": [5, 5, 5]},
    "material": {"base": {"sigma_t": [1.0, 1.2, 1.4], "sigma_s": [0.9, 1.0, 1.1], "g": 0.0},
                 "ior": 1.3},
    "lights": [{"type": "point", "position": [20, 30, 40], "intensity": [1000, 1000, 1000]}],
    "camera": {"position": [0, 10, 40], "target": [0, 0, 0], "up": [0, 1, 0],
               "fov_y_deg": 35, "width": 64, "height": 64},
    "lpv": {"resolution": 8, "steps": 4, "shadow_map": 64}
  })");
}

/// `word` occurs with no identifier character on either side ("g" in "grid 'g'" but not
/// in "sigma_t"), so short grid names can be checked without false positives.
inline bool mentionsWord(const std::string& text, const std::string& word) {
  auto isIdent = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  for (std::size_t at = text.find(word); at != std::string::npos; at = text.find(word, at + 1)) {
    const bool left = at == 0 || !isIdent(text[at - 1]);
    const std::size_t end = at + word.size();
    const bool right = end == text.size() || !isIdent(text[end]);
    if (left && right) return true;
  }
  return false;
}

inline std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// --- material-set files written with OpenVDB directly, so they can be invalid ---------

struct MaterialGrids {
  openvdb::Vec3SGrid::Ptr sigmaT, sigmaS;
  openvdb::FloatGrid::Ptr g;
};

/// A valid set: a 4^3 block of voxels at (0..3) inside the small box, albedo < 1, g 0.3.
inline MaterialGrids validGrids() {
  openvdb::initialize();
  MaterialGrids grids{openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f)), openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f)),
                      openvdb::FloatGrid::create(0.0f)};
  grids.sigmaT->setName("sigma_t");
  grids.sigmaS->setName("sigma_s");
  grids.g->setName("g");
  auto t = grids.sigmaT->getAccessor();
  auto s = grids.sigmaS->getAccessor();
  auto g = grids.g->getAccessor();
  for (int z = 0; z < 4; ++z)
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 4; ++x) {
        t.setValue(openvdb::Coord(x, y, z), openvdb::Vec3s(1.5f, 1.6f, 1.7f));
        s.setValue(openvdb::Coord(x, y, z), openvdb::Vec3s(1.2f, 1.3f, 1.4f));
        g.setValue(openvdb::Coord(x, y, z), 0.3f);
      }
  return grids;
}

inline void writeVdb(const std::filesystem::path& file, const openvdb::GridPtrVec& grids) {
  openvdb::initialize();
  openvdb::MetaMap meta;
  meta.insertMeta("units", openvdb::StringMetadata("mm"));
  meta.insertMeta("creator", openvdb::StringMetadata("sslpv cli_test"));
  meta.insertMeta("version", openvdb::StringMetadata("1"));
  openvdb::io::File out(file.string());
  out.write(grids, meta);
  out.close();
}

inline void writeVdb(const std::filesystem::path& file, const MaterialGrids& grids) {
  writeVdb(file, openvdb::GridPtrVec{grids.sigmaT, grids.sigmaS, grids.g});
}

/// The voxel every "bad voxel" test spoils; messages are expected to name it.
inline const openvdb::Coord kBadVoxel(1, 2, 3);

// --- fixture ---------------------------------------------------------------------------

class CliRejects : public ::testing::Test {
 protected:
  void SetUp() override { writeText(out(), kPreexistingOutput); }

  std::filesystem::path out() const { return dir_ / "out.png"; }
  std::filesystem::path scenePath() const { return dir_ / "scene.json"; }

  std::filesystem::path writeScene(const nlohmann::json& scene) {
    writeText(scenePath(), scene.dump(2));
    return scenePath();
  }

  /// The small scene using material set `vdbName` (relative to the scene's folder).
  std::filesystem::path writeSceneWithVdb(const std::string& vdbName) {
    nlohmann::json scene = smallScene();
    scene["material"]["vdb"] = vdbName;
    return writeScene(scene);
  }

  /// Runs sslpv, remembering which files existed just before.
  RunResult run(const std::vector<std::string>& args) {
    filesBefore_ = listing();
    return runSslpv(args);
  }

  RunResult render(const std::vector<std::string>& extra = {}) {
    std::vector<std::string> args{"render", scenePath().string(), "-o", out().string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return run(args);
  }

  /// The failure contract: exit code, no signal, one stderr line naming every `needle`,
  /// the pre-existing output untouched and no new file in the directory.
  void expectRejected(const RunResult& r, const std::vector<std::string>& needles,
                      int expectedExit = 2) {
    expectOneLineError(r, needles, expectedExit);
    EXPECT_EQ(readText(out()), kPreexistingOutput) << "the existing output file was modified";
    EXPECT_EQ(listing(), filesBefore_) << "files were created or removed in the output folder";
  }

  /// For voxel problems: the file, the grid (as a word) and "voxel".
  void expectVoxelRejected(const RunResult& r, const std::string& file, const std::string& grid) {
    expectRejected(r, {file, "voxel"});
    EXPECT_TRUE(mentionsWord(r.stderrText, grid)) << "should name grid '" << grid << "': " << r.stderrText;
  }

  std::set<std::string> listing() const {
    std::set<std::string> names;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(dir_.path()))
      names.insert(std::filesystem::relative(entry.path(), dir_.path()).string());
    return names;
  }

  TempDir dir_;
  std::set<std::string> filesBefore_;
};

}  // namespace sslpv::test
