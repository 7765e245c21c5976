// Writes the material-set harness's VDB seeds into the folder given (scripts/fuzz.sh runs
// it at build time: VDB files are binary and OpenVDB-version specific, so they are made,
// not committed). Small sets covering the reader's branches: each compression, with and
// without g, tiles, other units, and values the validation rejects.
#include <openvdb/io/File.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "fuzz/fuzz_support.h"
#include "volume/material/material_set.h"

namespace {
using namespace sslpv;

MaterialSet makeSet(float sigmaT, float sigmaS, bool withG) {
  MaterialSet set;
  set.sigmaT = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  set.sigmaS = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  if (withG) set.g = openvdb::FloatGrid::create(0.0f);
  for (int x = 0; x < 3; ++x)
    for (int y = 0; y < 2; ++y)
      for (int z = 0; z < 2; ++z) {
        const openvdb::Coord c(x, y, z);
        set.sigmaT->tree().setValue(c, openvdb::Vec3s(sigmaT + x, sigmaT, sigmaT + z));
        set.sigmaS->tree().setValue(c, openvdb::Vec3s(sigmaS, sigmaS + y * 0.1f, sigmaS));
        if (withG) set.g->tree().setValue(c, 0.2f * float(x - 1));
      }
  return set;
}

/// Written with openvdb::io::File directly so that each compression mode is covered.
void writeWithCompression(const MaterialSet& set, const std::filesystem::path& file, std::uint32_t compression) {
  openvdb::GridPtrVec grids{set.sigmaT, set.sigmaS};
  set.sigmaT->setName("sigma_t");
  set.sigmaS->setName("sigma_s");
  if (set.g) {
    set.g->setName("g");
    grids.push_back(set.g);
  }
  openvdb::io::File out(file.string());
  out.setCompression(compression);
  openvdb::MetaMap meta;
  meta.insertMeta("units", openvdb::StringMetadata(set.units));
  out.write(grids, meta);
  out.close();
}
}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUTPUT_DIR\n", argv[0]);
    return 2;
  }
  const std::filesystem::path dir = argv[1];
  std::filesystem::create_directories(dir);
  initializeOpenVdb();
  fuzz::writeSmallMaterialSet(dir / "valid_default.vdb");
  saveMaterialSet(makeSet(2.0f, 1.0f, false), dir / "valid_no_g.vdb");
  MaterialSet cm = makeSet(2.0f, 1.0f, true);
  cm.units = "cm";
  saveMaterialSet(cm, dir / "valid_cm.vdb");
  // σs above σt and a negative σt: the validation's own branches.
  saveMaterialSet(makeSet(1.0f, 3.0f, true), dir / "invalid_albedo.vdb");
  saveMaterialSet(makeSet(-1.0f, 0.0f, false), dir / "invalid_negative.vdb");
  MaterialSet tiles = makeSet(2.0f, 1.0f, true);
  tiles.sigmaT->tree().addTile(1, openvdb::Coord(64, 0, 0), openvdb::Vec3s(3.0f), true);
  tiles.sigmaS->tree().addTile(1, openvdb::Coord(64, 0, 0), openvdb::Vec3s(1.0f), true);
  saveMaterialSet(tiles, dir / "valid_tiles.vdb");
  writeWithCompression(makeSet(2.0f, 1.0f, true), dir / "raw.vdb", openvdb::io::COMPRESS_NONE);
  writeWithCompression(makeSet(2.0f, 1.0f, true), dir / "zip.vdb", openvdb::io::COMPRESS_ZIP | openvdb::io::COMPRESS_ACTIVE_MASK);
  if (openvdb::io::Archive::hasBloscCompression())
    writeWithCompression(makeSet(2.0f, 1.0f, true), dir / "blosc.vdb",
                         openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK);
  return 0;
}
