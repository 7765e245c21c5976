// Material-set files (load, save, validation, inspect, corrupt input) and the point
// sampling of the material field (docs/design.md §4).
#include "volume/material/material_field.h"

#include <gtest/gtest.h>
#include <openvdb/io/File.h>
#include <openvdb/tools/Interpolation.h>

#include <cmath>
#include <fstream>
#include <glm/glm.hpp>
#include <limits>
#include <random>
#include <sstream>

#include "seeded_draws.h"
#include "test_support.h"
#include "volume/core/error.h"

namespace sslpv {
namespace {
namespace fs = std::filesystem;
using openvdb::Coord;
using openvdb::Vec3s;
using test::drawVec3;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

openvdb::Vec3SGrid::Ptr vec3Grid(const std::string& name, const std::vector<std::pair<Coord, Vec3s>>& voxels,
                                 double voxelSize = 1.0) {
  auto grid = openvdb::Vec3SGrid::create(Vec3s(0.0f));
  grid->setName(name);
  grid->setTransform(openvdb::math::Transform::createLinearTransform(voxelSize));
  auto accessor = grid->getAccessor();
  for (const auto& [xyz, v] : voxels) accessor.setValue(xyz, v);
  return grid;
}

openvdb::FloatGrid::Ptr floatGrid(const std::string& name, const std::vector<std::pair<Coord, float>>& voxels) {
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setName(name);
  auto accessor = grid->getAccessor();
  for (const auto& [xyz, v] : voxels) accessor.setValue(xyz, v);
  return grid;
}

/// Writes grids with OpenVDB directly, so tests can produce files sslpv would not write.
void writeVdb(const fs::path& file, const openvdb::GridPtrVec& grids, const openvdb::MetaMap& meta = {}) {
  initializeOpenVdb();
  openvdb::io::File out(file.string());
  out.write(grids, meta);
  out.close();
}

/// A valid set: σt 2, σs 1 (albedo 1/2) at a few voxels, g 0.3 at one.
MaterialSet validSet() {
  MaterialSet set;
  set.sigmaT = vec3Grid("sigma_t", {{Coord(0, 0, 0), Vec3s(2, 2, 2)}, {Coord(3, 4, 5), Vec3s(2, 3, 4)}});
  set.sigmaS = vec3Grid("sigma_s", {{Coord(0, 0, 0), Vec3s(1, 1, 1)}, {Coord(3, 4, 5), Vec3s(1, 2, 3)}});
  set.g = floatGrid("g", {{Coord(3, 4, 5), 0.3f}});
  return set;
}

std::string loadError(const fs::path& file) {
  try {
    loadMaterialSet(file);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << file << " loaded without error";
  return {};
}

void expectContains(const std::string& text, const std::string& part) {
  EXPECT_NE(text.find(part), std::string::npos) << "expected \"" << part << "\" in: " << text;
}

std::string readBytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void writeBytes(const fs::path& file, const std::string& bytes) {
  std::ofstream out(file, std::ios::binary);
  out << bytes;
}

// --- save / load ---------------------------------------------------------------------

TEST(MaterialSetFile, RoundTripKeepsValuesTransformsMetadataAndG) {
  test::TempDir dir;
  MaterialSet set = validSet();
  set.sigmaS->setTransform(openvdb::math::Transform::createLinearTransform(0.5));
  set.sigmaS->transform().postTranslate(openvdb::Vec3d(1, 2, 3));
  set.sigmaT->tree().addTile(1, Coord(16, 0, 0), Vec3s(5, 5, 5), true);
  set.sigmaS->tree().addTile(1, Coord(16, 0, 0), Vec3s(4, 4, 4), true);
  set.units = "cm";
  set.creator = "unit test";
  saveMaterialSet(set, dir / "set.vdb");

  auto loaded = loadMaterialSet(dir / "set.vdb");
  EXPECT_EQ(loaded->units, "cm");
  EXPECT_EQ(loaded->creator, "unit test");
  ASSERT_TRUE(loaded->sigmaT && loaded->sigmaS && loaded->g);
  EXPECT_EQ(loaded->sigmaT->tree().activeVoxelCount(), set.sigmaT->tree().activeVoxelCount());
  EXPECT_EQ(loaded->sigmaT->tree().activeTileCount(), 1u);
  EXPECT_EQ(loaded->sigmaT->tree().getValue(Coord(3, 4, 5)), Vec3s(2, 3, 4));
  EXPECT_EQ(loaded->sigmaT->tree().getValue(Coord(20, 1, 1)), Vec3s(5, 5, 5));
  EXPECT_EQ(loaded->sigmaS->tree().getValue(Coord(3, 4, 5)), Vec3s(1, 2, 3));
  EXPECT_EQ(loaded->g->tree().getValue(Coord(3, 4, 5)), 0.3f);
  EXPECT_EQ(loaded->sigmaT->constTransform(), set.sigmaT->constTransform());
  EXPECT_EQ(loaded->sigmaS->constTransform(), set.sigmaS->constTransform());
  EXPECT_NE(loaded->sigmaT->constTransform(), loaded->sigmaS->constTransform());

  // File-level metadata as the contract names it; the caller's grids keep their names.
  openvdb::io::File raw((dir / "set.vdb").string());
  raw.open(false);
  auto meta = raw.getMetadata();
  EXPECT_EQ(meta->metaValue<std::string>("units"), "cm");
  EXPECT_EQ(meta->metaValue<std::string>("creator"), "unit test");
  EXPECT_EQ(meta->metaValue<int32_t>("version"), 1);
}

TEST(MaterialSetFile, RoundTripWithoutGLeavesGAbsentAndCreatorDefaults) {
  test::TempDir dir;
  MaterialSet set = validSet();
  set.g.reset();
  set.sigmaT->setName("renamed by the caller");
  saveMaterialSet(set, dir / "set.vdb");
  EXPECT_EQ(set.sigmaT->getName(), "renamed by the caller");  // save renames a shallow copy only
  auto loaded = loadMaterialSet(dir / "set.vdb");
  EXPECT_FALSE(loaded->g);
  EXPECT_EQ(loaded->units, "mm");
  EXPECT_EQ(loaded->creator, "sslpv");
}

TEST(MaterialSetFile, MissingUnitsMeanMillimetres) {
  test::TempDir dir;
  MaterialSet set = validSet();
  writeVdb(dir / "nounits.vdb", {set.sigmaT, set.sigmaS});
  EXPECT_EQ(loadMaterialSet(dir / "nounits.vdb")->units, "mm");
  std::ostringstream report;
  EXPECT_TRUE(inspectVdbFile(dir / "nounits.vdb", report));
  expectContains(report.str(), "units: not in the file, assumed mm");
}

TEST(MaterialSetFile, UnknownUnitsAreRejectedNamingTheKey) {
  test::TempDir dir;
  MaterialSet set = validSet();
  openvdb::MetaMap meta;
  meta.insertMeta("units", openvdb::StringMetadata("furlong"));
  writeVdb(dir / "units.vdb", {set.sigmaT, set.sigmaS}, meta);
  const std::string message = loadError(dir / "units.vdb");
  expectContains(message, (dir / "units.vdb").string());
  expectContains(message, "'units'");
  expectContains(message, "furlong");
}

// --- validation ------------------------------------------------------------------------

struct BadVoxelCase {
  const char* name;
  const char* grid;      ///< the grid the message must name
  Vec3s sigmaT, sigmaS;  ///< values at voxel (3,4,5)
  float g;
  const char* why;  ///< part of the message saying what is wrong
};

class MaterialSetValidation : public ::testing::TestWithParam<BadVoxelCase> {};

// Each invalid voxel value is rejected with file, grid, voxel index and world position.
TEST_P(MaterialSetValidation, RejectsBadVoxelNamingFileGridAndVoxel) {
  const BadVoxelCase& c = GetParam();
  test::TempDir dir;
  auto sigmaT = vec3Grid("sigma_t", {{Coord(0, 0, 0), Vec3s(1)}, {Coord(3, 4, 5), c.sigmaT}}, 0.1);
  auto sigmaS = vec3Grid("sigma_s", {{Coord(0, 0, 0), Vec3s(0.5f)}, {Coord(3, 4, 5), c.sigmaS}}, 0.1);
  auto g = floatGrid("g", {{Coord(3, 4, 5), c.g}});
  g->setTransform(sigmaT->transform().copy());
  const fs::path file = dir / (std::string(c.name) + ".vdb");
  writeVdb(file, {sigmaT, sigmaS, g});
  const std::string message = loadError(file);
  expectContains(message, file.string() + ": ");
  expectContains(message, std::string("grid '") + c.grid + "'");
  expectContains(message, "voxel (3,4,5)");
  expectContains(message, "world (0.3, 0.4, 0.5)");
  expectContains(message, c.why);
  EXPECT_EQ(message.find('\n'), std::string::npos) << "one-line message";
}

INSTANTIATE_TEST_SUITE_P(
    EachRule, MaterialSetValidation,
    ::testing::Values(
        BadVoxelCase{"negative_sigma_t", "sigma_t", Vec3s(1, -0.5f, 1), Vec3s(0), 0, "negative in channel g"},
        BadVoxelCase{"negative_sigma_s", "sigma_s", Vec3s(1), Vec3s(0.5f, 0.5f, -1e-3f), 0, "negative in channel b"},
        BadVoxelCase{"albedo_above_one", "sigma_s", Vec3s(1, 2, 3), Vec3s(1.5f, 1, 1), 0, "albedo > 1"},
        BadVoxelCase{"g_one", "g", Vec3s(1), Vec3s(0.5f), 1.0f, "|g| must be below 1"},
        BadVoxelCase{"g_below_minus_one", "g", Vec3s(1), Vec3s(0.5f), -1.5f, "|g| must be below 1"},
        BadVoxelCase{"nan_sigma_t", "sigma_t", Vec3s(1, kNaN, 1), Vec3s(0.5f), 0, "not finite"},
        BadVoxelCase{"inf_sigma_s", "sigma_s", Vec3s(1), Vec3s(kInf, 0, 0), 0, "not finite"},
        BadVoxelCase{"nan_g", "g", Vec3s(1), Vec3s(0.5f), kNaN, "not finite"}),
    [](const auto& testInfo) { return std::string(testInfo.param.name); });

TEST(MaterialSetValidation, WrongGridTypeIsNamed) {
  test::TempDir dir;
  auto sigmaT = floatGrid("sigma_t", {{Coord(0, 0, 0), 1.0f}});
  auto sigmaS = vec3Grid("sigma_s", {{Coord(0, 0, 0), Vec3s(0.5f)}});
  writeVdb(dir / "type.vdb", {sigmaT, sigmaS});
  const std::string message = loadError(dir / "type.vdb");
  EXPECT_EQ(message, (dir / "type.vdb").string() + ": grid 'sigma_t' is FloatGrid, expected Vec3SGrid");

  auto g = vec3Grid("g", {});
  writeVdb(dir / "gtype.vdb", {vec3Grid("sigma_t", {}), sigmaS, g});
  EXPECT_EQ(loadError(dir / "gtype.vdb"), (dir / "gtype.vdb").string() + ": grid 'g' is Vec3SGrid, expected FloatGrid");
}

TEST(MaterialSetValidation, DuplicateGridNamesAreAmbiguous) {
  test::TempDir dir;
  MaterialSet set = validSet();
  auto second = vec3Grid("sigma_t", {{Coord(0, 0, 0), Vec3s(9)}});
  writeVdb(dir / "dup.vdb", {set.sigmaT, set.sigmaS, second});
  EXPECT_EQ(loadError(dir / "dup.vdb"), (dir / "dup.vdb").string() + ": more than one grid is named 'sigma_t'");
}

TEST(MaterialSetValidation, MissingRequiredGridsAreNamed) {
  test::TempDir dir;
  MaterialSet set = validSet();
  writeVdb(dir / "no_sigma_t.vdb", {set.sigmaS, set.g});
  expectContains(loadError(dir / "no_sigma_t.vdb"), "no_sigma_t.vdb: missing required grid 'sigma_t'");
  writeVdb(dir / "no_sigma_s.vdb", {set.sigmaT});
  expectContains(loadError(dir / "no_sigma_s.vdb"), "no_sigma_s.vdb: missing required grid 'sigma_s'");
}

TEST(MaterialSetValidation, BadActiveTileIsNamedAsATileAtItsOrigin) {
  MaterialSet set = validSet();
  set.sigmaT->tree().addTile(1, Coord(8, 16, 0), Vec3s(1, -1, 1), true);
  auto problems = validateMaterialSet(set, "tile.vdb");
  ASSERT_EQ(problems.size(), 1u);
  expectContains(problems[0].message, "tile.vdb: grid 'sigma_t' tile of 8x8x8 voxels at (8,16,0)");
  expectContains(problems[0].message, "negative");
}

TEST(MaterialSetValidation, InvalidBackgroundIsRejected) {
  MaterialSet set = validSet();
  set.sigmaS->tree().root().setBackground(Vec3s(kNaN), /*updateChildNodes=*/true);
  auto problems = validateMaterialSet(set, "bg.vdb");
  ASSERT_EQ(problems.size(), 1u);
  expectContains(problems[0].message, "bg.vdb: grid 'sigma_s' background: sigma_s (nan, nan, nan) is not finite");
}

// σs slightly above σt by float round-off (relative 1e-7) is accepted; 1e-5 is not.
TEST(MaterialSetValidation, AlbedoToleranceCoversFloatRoundOffOnly) {
  MaterialSet set = validSet();
  set.sigmaS->tree().setValue(Coord(3, 4, 5), Vec3s(2, 3, 4 * (1 + 1e-7f)));
  EXPECT_TRUE(validateMaterialSet(set, "f.vdb").empty());
  set.sigmaS->tree().setValue(Coord(3, 4, 5), Vec3s(2, 3, 4 * (1 + 1e-5f)));
  EXPECT_EQ(validateMaterialSet(set, "f.vdb").size(), 1u);
}

// σs <= σt compares both grids where both are active at the same index, also when one
// side is a tile covering the other's voxels; where one side is inactive the base decides.
TEST(MaterialSetValidation, AlbedoIsComparedAcrossTilesAndOnlyWhereBothAreActive) {
  MaterialSet set = validSet();
  set.sigmaS->tree().addTile(1, Coord(8, 8, 8), Vec3s(3, 3, 3), true);
  set.sigmaT->tree().setValue(Coord(9, 10, 11), Vec3s(3, 3, 2));      // σt voxel inside the σs tile
  set.sigmaS->tree().setValue(Coord(20, 20, 20), Vec3s(50, 50, 50));  // σt inactive there
  auto problems = validateMaterialSet(set, "tiles.vdb");
  ASSERT_EQ(problems.size(), 1u);
  expectContains(problems[0].message, "tiles.vdb: grid 'sigma_s' voxel (9,10,11)");
  expectContains(problems[0].message, "in channel b (albedo > 1)");
}

TEST(MaterialSetValidation, ReportsEveryProblemUpToTheLimit) {
  MaterialSet set = validSet();
  for (int i = 0; i < 5; ++i) set.sigmaT->tree().setValue(Coord(100 + i, 0, 0), Vec3s(-1));
  EXPECT_EQ(validateMaterialSet(set, "many.vdb").size(), 5u);
  EXPECT_EQ(validateMaterialSet(set, "many.vdb", 2).size(), 2u);
  MaterialSet empty;
  auto missing = validateMaterialSet(empty, "empty.vdb");
  ASSERT_EQ(missing.size(), 2u);
  expectContains(missing[0].message, "'sigma_t'");
  expectContains(missing[1].message, "'sigma_s'");
}

// --- inspect -------------------------------------------------------------------------------

TEST(InspectVdb, ListsGridsMetadataAndUnknownGrids) {
  test::TempDir dir;
  MaterialSet set = validSet();
  set.sigmaT->tree().addTile(1, Coord(16, 0, 0), Vec3s(5, 6, 7), true);
  auto density = floatGrid("density", {{Coord(1, 1, 1), 0.25f}});
  openvdb::MetaMap meta;
  meta.insertMeta("units", openvdb::StringMetadata("mm"));
  meta.insertMeta("creator", openvdb::StringMetadata("painter"));
  writeVdb(dir / "set.vdb", {set.sigmaT, set.sigmaS, set.g, density}, meta);
  std::ostringstream report;
  EXPECT_TRUE(inspectVdbFile(dir / "set.vdb", report));
  const std::string text = report.str();
  expectContains(text, "creator (string): painter");
  expectContains(text, "grids: 4");
  expectContains(text, "grid 'sigma_t': Vec3SGrid, sslpv: extinction");
  expectContains(text, "active voxels: 514 (2 in leaves), active tiles: 1");
  expectContains(text, "voxel size: 1");
  expectContains(text, "value range (active): r [2, 5], g [2, 6], b [2, 7]");
  expectContains(text, "index bounding box: (0,0,0) .. (23,7,7)");
  expectContains(text, "world bounding box: (-0.5, -0.5, -0.5) .. (23.5, 7.5, 7.5)");
  expectContains(text, "grid 'density': FloatGrid, not used by sslpv");
  expectContains(text, "value range (active): [0.25, 0.25]");
  expectContains(text, "validation: OK");
}

TEST(InspectVdb, ListsEveryProblemAndReturnsFalse) {
  test::TempDir dir;
  MaterialSet set = validSet();
  set.sigmaT->tree().setValue(Coord(1, 2, 3), Vec3s(-1));
  set.g->tree().setValue(Coord(0, 0, 0), 2.0f);
  writeVdb(dir / "bad.vdb", {set.sigmaT, set.sigmaS, set.g});
  std::ostringstream report;
  EXPECT_FALSE(inspectVdbFile(dir / "bad.vdb", report));
  const std::string text = report.str();
  expectContains(text, "validation: 2 problems");
  expectContains(text, "grid 'sigma_t' voxel (1,2,3)");
  expectContains(text, "grid 'g' voxel (0,0,0)");
}

TEST(InspectVdb, UnreadableFileIsAnInputError) {
  test::TempDir dir;
  std::ostringstream report;
  EXPECT_THROW(inspectVdbFile(dir / "absent.vdb", report), InputError);
  writeBytes(dir / "junk.vdb", "definitely not a vdb");
  EXPECT_THROW(inspectVdbFile(dir / "junk.vdb", report), InputError);
}

// --- missing, empty, truncated and corrupt files ------------------------------------------

TEST(MaterialSetCorruptFiles, MissingEmptyAndRandomFilesAreInputErrors) {
  test::TempDir dir;
  EXPECT_EQ(loadError(dir / "absent.vdb"), (dir / "absent.vdb").string() + ": no such file");
  writeBytes(dir / "empty.vdb", "");
  expectContains(loadError(dir / "empty.vdb"), "empty.vdb: empty file");
  std::mt19937 rng(7);
  std::string random(4096, '\0');
  for (char& c : random) c = char(rng());
  writeBytes(dir / "random.vdb", random);
  expectContains(loadError(dir / "random.vdb"), "random.vdb: not a VDB file");
  // Random bytes behind a valid magic number reach OpenVDB's parser.
  std::string magic = readBytes([&] {
                        saveMaterialSet(validSet(), dir / "valid.vdb");
                        return dir / "valid.vdb";
                      }())
                          .substr(0, 8);
  writeBytes(dir / "random_after_magic.vdb", magic + random);
  expectContains(loadError(dir / "random_after_magic.vdb"), "random_after_magic.vdb: ");
}

/// A set big enough that its grids span many compressed chunks.
MaterialSet largerSet() {
  MaterialSet set;
  set.sigmaT = vec3Grid("sigma_t", {});
  set.sigmaS = vec3Grid("sigma_s", {});
  set.g = floatGrid("g", {});
  std::mt19937 rng(3);
  auto t = set.sigmaT->getAccessor();
  auto s = set.sigmaS->getAccessor();
  auto g = set.g->getAccessor();
  for (int i = 0; i < 4000; ++i) {
    Coord xyz = drawVec3<Coord>([&] { return int(rng() % 48); });
    float v = 1.0f + float(rng() % 1000) / 100.0f;
    t.setValue(xyz, Vec3s(v, v * 1.5f, v * 2.0f));
    s.setValue(xyz, Vec3s(v * 0.5f, v, v));
    g.setValue(xyz, float(rng() % 100) / 200.0f);
  }
  return set;
}

TEST(MaterialSetCorruptFiles, TruncatedFilesAreInputErrors) {
  test::TempDir dir;
  saveMaterialSet(largerSet(), dir / "valid.vdb");
  const std::string bytes = readBytes(dir / "valid.vdb");
  ASSERT_NO_THROW(loadMaterialSet(dir / "valid.vdb"));
  for (std::size_t length : {bytes.size() / 10, bytes.size() / 2, bytes.size() * 9 / 10, bytes.size() - 1}) {
    const fs::path file = dir / ("truncated_" + std::to_string(length) + ".vdb");
    writeBytes(file, bytes.substr(0, length));
    const std::string message = loadError(file);
    expectContains(message, file.string() + ": ");
    expectContains(message, "truncated");
  }
}

TEST(MaterialSetCorruptFiles, ByteFlippedInTheMiddleIsAnInputErrorOrStillValid) {
  test::TempDir dir;
  saveMaterialSet(largerSet(), dir / "valid.vdb");
  std::string bytes = readBytes(dir / "valid.vdb");
  bytes[bytes.size() / 2] = char(bytes[bytes.size() / 2] ^ 0x5a);
  writeBytes(dir / "flipped.vdb", bytes);
  // A flip inside voxel data can leave a readable file whose values then must validate.
  try {
    auto set = loadMaterialSet(dir / "flipped.vdb");
    EXPECT_TRUE(validateMaterialSet(*set, "flipped.vdb").empty());
  } catch (const InputError& e) {
    expectContains(e.what(), (dir / "flipped.vdb").string() + ": ");
  }
}

// OpenVDB 10's reader overflows heap buffers and aborts on some corrupt inputs (seen
// with blosc and zip chunks), and allocates gigabytes on others (uncompressed). Every
// mutation of a valid file must end as a loaded, valid set or an InputError, and this
// process must survive to check it.
TEST(MaterialSetCorruptFiles, MutatedFilesNeverCrashTheProcess) {
  test::TempDir dir;
  initializeOpenVdb();
  std::vector<uint32_t> codecs = {openvdb::io::COMPRESS_ZIP | openvdb::io::COMPRESS_ACTIVE_MASK,
                                  openvdb::io::COMPRESS_NONE};
  if (openvdb::io::Archive::hasBloscCompression())
    codecs.push_back(openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK);
  MaterialSet set = largerSet();
  std::mt19937 rng(11);
  int crashesReported = 0, rejected = 0, loaded = 0;
  for (uint32_t codec : codecs) {
    const fs::path validFile = dir / ("codec_" + std::to_string(codec) + ".vdb");
    openvdb::io::File out(validFile.string());
    out.setCompression(codec);
    out.write(openvdb::GridCPtrVec{set.sigmaT, set.sigmaS, set.g});
    out.close();
    const std::string valid = readBytes(validFile);
    for (int k = 0; k < 40; ++k) {
      std::string bytes = valid;
      for (int flips = 1 + int(rng() % 4); flips > 0; --flips) bytes[rng() % bytes.size()] = char(rng());
      const fs::path file = dir / "mutated.vdb";
      writeBytes(file, bytes);
      try {
        auto mutated = loadMaterialSet(file);
        ++loaded;
      } catch (const InputError& e) {
        ++rejected;
        const std::string message = e.what();
        EXPECT_EQ(message.rfind(file.string() + ": ", 0), 0u) << message;
        if (message.find("crashed") != std::string::npos) ++crashesReported;
      }
    }
  }
  std::cout << "mutations: " << loaded << " loaded, " << rejected << " rejected (" << crashesReported
            << " crashed the isolated reader)\n";
  EXPECT_EQ(loaded + rejected, 40 * int(codecs.size()));
}

// --- MaterialField::sample -------------------------------------------------------------

MaterialSample baseMaterial() { return MaterialSample{glm::vec3(2.0f, 3.0f, 4.0f), glm::vec3(1.0f, 1.5f, 2.0f), 0.1f}; }

/// A set whose σs and g grids are empty: the field is the base there.
std::shared_ptr<MaterialSet> setWithSigmaT(openvdb::Vec3SGrid::Ptr sigmaT) {
  auto set = std::make_shared<MaterialSet>();
  set->sigmaT = std::move(sigmaT);
  set->sigmaS = vec3Grid("sigma_s", {});
  return set;
}

// Voxel values 1 + i + 2j + 4k + 8ijk on the 2x2x2 block are reproduced between the
// centres by the trilinear field as 1 + x + 2y + 4z + 8xyz (exact for trilinear data).
TEST(MaterialFieldSample, TrilinearBetweenVoxelCentresOfA2x2x2Grid) {
  std::vector<std::pair<Coord, Vec3s>> voxels;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        float v = float(1 + i + 2 * j + 4 * k + 8 * i * j * k);
        voxels.push_back({Coord(i, j, k), Vec3s(v, 2 * v, 3 * v)});
      }
  MaterialField field(baseMaterial(), setWithSigmaT(vec3Grid("sigma_t", voxels)), glm::dmat4(1.0), 1.0);
  auto sampler = field.sampler();
  for (glm::dvec3 p : {glm::dvec3(0, 0, 0), glm::dvec3(1, 1, 1), glm::dvec3(0.5, 0.5, 0.5), glm::dvec3(0.25, 0.5, 0.75),
                       glm::dvec3(0.9, 0.1, 0.3), glm::dvec3(1, 0, 0.5)}) {
    const double expected = 1 + p.x + 2 * p.y + 4 * p.z + 8 * p.x * p.y * p.z;
    MaterialSample m = sampler.sample(p);
    EXPECT_NEAR(m.sigmaT.x, expected, 1e-5) << p.x << " " << p.y << " " << p.z;
    EXPECT_NEAR(m.sigmaT.y, 2 * expected, 2e-5);
    EXPECT_NEAR(m.sigmaT.z, 3 * expected, 3e-5);
    EXPECT_EQ(m.sigmaS, baseMaterial().sigmaS);  // empty σs grid: base everywhere
    EXPECT_EQ(m.g, baseMaterial().g);            // no g grid: base g
  }
}

// Inactive voxels and everything outside take the base value, whatever the grid stores
// there (inactive value, background): half-way from an active voxel to an inactive one
// the field is the mean of the voxel value and the base.
TEST(MaterialFieldSample, InactiveAndOutsideTakeTheBase) {
  auto sigmaT = vec3Grid("sigma_t", {{Coord(0, 0, 0), Vec3s(10, 20, 30)}});
  sigmaT->tree().setValueOff(Coord(1, 0, 0), Vec3s(100, 100, 100));
  sigmaT->tree().root().setBackground(Vec3s(50, 50, 50), true);
  MaterialField field(baseMaterial(), setWithSigmaT(sigmaT), glm::dmat4(1.0), 1.0);
  auto sampler = field.sampler();
  const glm::vec3 base = baseMaterial().sigmaT;
  EXPECT_EQ(sampler.sample({0, 0, 0}).sigmaT, glm::vec3(10, 20, 30));
  const glm::vec3 half = sampler.sample({0.5, 0, 0}).sigmaT;
  EXPECT_NEAR(half.x, 0.5 * (10 + base.x), 1e-5);
  EXPECT_NEAR(half.z, 0.5 * (30 + base.z), 1e-5);
  EXPECT_NEAR(sampler.sample({-0.25, 0, 0}).sigmaT.y, 0.75 * 20 + 0.25 * base.y, 1e-5);
  EXPECT_EQ(sampler.sample({1, 0, 0}).sigmaT, base);
  EXPECT_EQ(sampler.sample({7, -3, 1000}).sigmaT, base);
  EXPECT_EQ(sampler.sample({1e30, 0, 0}).sigmaT, base);
}

// σt and σs are each sampled through their own transform, after worldToRest: with a
// ramp v = i along x, the value read is the x index coordinate of each grid.
TEST(MaterialFieldSample, EachGridThroughItsOwnTransform) {
  std::vector<std::pair<Coord, Vec3s>> ramp;
  for (int i = -4; i < 40; ++i)
    for (int j = -2; j <= 2; ++j)
      for (int k = -2; k <= 2; ++k) ramp.push_back({Coord(i, j, k), Vec3s(float(i + 100))});
  auto set = std::make_shared<MaterialSet>();
  set->sigmaT = vec3Grid("sigma_t", ramp, 0.5);  // index = rest / 0.5
  set->sigmaS = vec3Grid("sigma_s", ramp, 2.0);
  set->sigmaS->transform().postTranslate(openvdb::Vec3d(1, 0, 0));  // index = (rest - 1) / 2
  glm::dmat4 worldToRest(1.0);
  worldToRest[3] = glm::dvec4(-10, 0, 0, 1);  // rest = world - (10, 0, 0)
  MaterialField field(baseMaterial(), set, worldToRest, 1.0);
  auto sampler = field.sampler();
  for (double rest : {0.3, 2.0, 5.75, 11.1}) {
    MaterialSample m = sampler.sample({10 + rest, 0.1, -0.2});
    EXPECT_NEAR(m.sigmaT.x, 100 + rest / 0.5, 1e-4) << rest;
    EXPECT_NEAR(m.sigmaS.x, 100 + (rest - 1) / 2.0, 1e-4) << rest;
  }
}

// A rotation in worldToRest is followed exactly: the world point that maps to rest
// point p reads the value at p.
TEST(MaterialFieldSample, RotatedWorldToRestReadsTheRestPoint) {
  std::vector<std::pair<Coord, Vec3s>> voxels;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      for (int k = 0; k < 6; ++k) voxels.push_back({Coord(i, j, k), Vec3s(float(1 + i + 3 * j + 5 * k))});
  const double angle = 0.6;
  glm::dmat4 restToWorld(1.0);
  restToWorld[0] = glm::dvec4(std::cos(angle), std::sin(angle), 0, 0);
  restToWorld[1] = glm::dvec4(-std::sin(angle), std::cos(angle), 0, 0);
  restToWorld[3] = glm::dvec4(5, -2, 1, 1);
  MaterialField field(baseMaterial(), setWithSigmaT(vec3Grid("sigma_t", voxels)), glm::inverse(restToWorld), 1.0);
  auto sampler = field.sampler();
  const glm::dvec3 rest(2.3, 1.6, 3.1);
  const glm::dvec3 world = glm::dvec3(restToWorld * glm::dvec4(rest, 1.0));
  EXPECT_NEAR(sampler.sample(world).sigmaT.x, 1 + rest.x + 3 * rest.y + 5 * rest.z, 1e-4);
}

// The grid's own affine transform (rotation, scale, translation) is followed as OpenVDB
// defines it, and inside a fully active region the field is OpenVDB's BoxSampler.
TEST(MaterialFieldSample, MatchesOpenVdbTransformAndBoxSamplerInsideActiveRegion) {
  std::vector<std::pair<Coord, Vec3s>> voxels;
  std::mt19937 rng(4);
  for (int i = -1; i < 12; ++i)
    for (int j = -1; j < 12; ++j)
      for (int k = -1; k < 12; ++k) voxels.push_back({Coord(i, j, k), Vec3s(float(rng() % 1000) / 100.0f)});
  auto sigmaT = vec3Grid("sigma_t", voxels, 0.5);
  sigmaT->transform().postRotate(0.7, openvdb::math::Y_AXIS);
  sigmaT->transform().postScale(openvdb::Vec3d(1.0, 2.0, 1.5));
  sigmaT->transform().postTranslate(openvdb::Vec3d(3, -1, 2));
  MaterialField field(baseMaterial(), setWithSigmaT(sigmaT), glm::dmat4(1.0), 1.0);
  auto sampler = field.sampler();
  openvdb::tools::GridSampler<openvdb::Vec3SGrid, openvdb::tools::BoxSampler> reference(*sigmaT);
  std::uniform_real_distribution<double> inside(0.5, 9.5);
  for (int n = 0; n < 50; ++n) {
    const openvdb::Vec3d index = drawVec3<openvdb::Vec3d>(inside, rng);
    const openvdb::Vec3d world = sigmaT->transform().indexToWorld(index);
    const Vec3s expected = reference.wsSample(world);
    EXPECT_NEAR(sampler.sample({world[0], world[1], world[2]}).sigmaT.x, expected[0], 2e-5);
  }
}

// An active tile is a block of voxels with one value: inside it the field is that
// value, and half a voxel beyond its face it blends half-way to the base.
TEST(MaterialFieldSample, ActiveTileIsReadAsItsValue) {
  auto sigmaT = vec3Grid("sigma_t", {});
  sigmaT->tree().addTile(1, Coord(8, 8, 8), Vec3s(7, 7, 7), true);
  MaterialField field(baseMaterial(), setWithSigmaT(sigmaT), glm::dmat4(1.0), 1.0);
  auto sampler = field.sampler();
  EXPECT_EQ(sampler.sample({11.3, 12.7, 9.1}).sigmaT, glm::vec3(7, 7, 7));
  EXPECT_EQ(sampler.sample({15.0, 8.0, 12.5}).sigmaT, glm::vec3(7, 7, 7));
  EXPECT_NEAR(sampler.sample({15.5, 10, 10}).sigmaT.x, 0.5 * (7 + baseMaterial().sigmaT.x), 1e-6);
  EXPECT_NEAR(sampler.sample({10, 7.5, 10}).sigmaT.y, 0.5 * (7 + baseMaterial().sigmaT.y), 1e-6);
}

// sigmaScale converts the file's σ units: it multiplies grid values, not the base (which
// is already per scene unit), and not g.
TEST(MaterialFieldSample, SigmaScaleMultipliesGridValuesOnly) {
  auto set = std::make_shared<MaterialSet>();
  set->sigmaT = vec3Grid("sigma_t", {{Coord(0, 0, 0), Vec3s(1, 2, 3)}});
  set->sigmaS = vec3Grid("sigma_s", {{Coord(0, 0, 0), Vec3s(0.5f, 1, 1)}});
  set->g = floatGrid("g", {{Coord(0, 0, 0), 0.5f}});
  MaterialField field(baseMaterial(), set, glm::dmat4(1.0), 10.0);
  auto sampler = field.sampler();
  MaterialSample m = sampler.sample({0, 0, 0});
  EXPECT_EQ(m.sigmaT, glm::vec3(10, 20, 30));
  EXPECT_EQ(m.sigmaS, glm::vec3(5, 10, 10));
  EXPECT_EQ(m.g, 0.5f);
  MaterialSample between = sampler.sample({0.5, 0, 0});
  EXPECT_NEAR(between.sigmaT.x, 0.5 * (10 + baseMaterial().sigmaT.x), 1e-5);
  EXPECT_NEAR(between.g, 0.5 * (0.5 + baseMaterial().g), 1e-6);
  EXPECT_EQ(sampler.sample({5, 5, 5}).sigmaT, baseMaterial().sigmaT);
}

TEST(MaterialFieldSample, NoSetIsHomogeneousBase) {
  MaterialField field(baseMaterial(), nullptr, glm::dmat4(1.0), 1.0);
  EXPECT_TRUE(field.homogeneous());
  MaterialSample m = field.sampler().sample({1, 2, 3});
  EXPECT_EQ(m.sigmaT, baseMaterial().sigmaT);
  EXPECT_EQ(m.sigmaS, baseMaterial().sigmaS);
  EXPECT_EQ(m.g, baseMaterial().g);
}

}  // namespace
}  // namespace sslpv
