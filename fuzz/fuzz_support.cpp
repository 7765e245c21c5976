#include "fuzz/fuzz_support.h"

#include <unistd.h>

#include <fstream>
#include <system_error>

#include "volume/material/material_set.h"

namespace sslpv::fuzz {
namespace fs = std::filesystem;

namespace {
void removeScratch() {
  std::error_code ec;
  fs::remove_all(scratchDir(), ec);
}
}  // namespace

const fs::path& scratchDir() {
  static const fs::path dir = [] {
    std::string pattern = (fs::temp_directory_path() / "sslpv-fuzz-XXXXXX").string();
    if (!::mkdtemp(pattern.data())) {
      std::perror("sslpv fuzz: mkdtemp");
      std::abort();
    }
    return fs::path(pattern);
  }();
  static const bool registered = (std::atexit(removeScratch), true);
  (void)registered;
  return dir;
}

fs::path writeScratchFile(const std::string& name, const std::uint8_t* data, std::size_t size) {
  const fs::path file = scratchDir() / name;
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  out.close();
  if (!out) {
    std::fprintf(stderr, "sslpv fuzz: cannot write %s\n", file.c_str());
    std::abort();
  }
  return file;
}

void writeSmallMaterialSet(const fs::path& file) {
  initializeOpenVdb();
  MaterialSet set;
  set.sigmaT = openvdb::Vec3SGrid::create(openvdb::Vec3s(1.0f));
  set.sigmaS = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.5f));
  set.g = openvdb::FloatGrid::create(0.0f);
  auto t = set.sigmaT->getAccessor();
  auto s = set.sigmaS->getAccessor();
  auto g = set.g->getAccessor();
  for (int x = -3; x < 3; ++x)
    for (int y = -3; y < 3; ++y)
      for (int z = -3; z < 3; ++z) {
        const openvdb::Coord c(x, y, z);
        const float v = 1.0f + 0.25f * float((x + 3) + 2 * (y + 3) + 3 * (z + 3));
        t.setValue(c, openvdb::Vec3s(v, v * 1.5f, v * 2.0f));
        s.setValue(c, openvdb::Vec3s(0.9f * v, v, 1.2f * v));
        g.setValue(c, 0.1f * float(x));
      }
  saveMaterialSet(set, file);
}

const char* smallClosedObj() {
  return "v -1 -1 -1\nv 1 -1 -1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\n"
         "f 1 5 7\nf 1 7 3\nf 2 4 8\nf 2 8 6\nf 1 2 6\nf 1 6 5\n"
         "f 3 7 8\nf 3 8 4\nf 1 3 4\nf 1 4 2\nf 5 6 8\nf 5 8 7\n";
}

}  // namespace sslpv::fuzz
