#include "volume/scene/mesh_import.h"

#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "volume/core/error.h"
#include "volume/core/input_file.h"

namespace sslpv {
namespace {

namespace fs = std::filesystem;

/// Assimp opens an OBJ's material libraries itself and does not stop at a FIFO or a
/// device (it blocks in open()), so the `mtllib` files an OBJ names pass the mesh's own
/// regular-file check first. A missing library stays assimp's business: it goes on
/// without it, as for any OBJ whose .mtl was not copied along.
void requireRegularMaterialLibraries(const fs::path& obj) {
  std::ifstream in(obj, std::ios::binary);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string keyword;
    if (!(words >> keyword) || keyword != "mtllib") continue;
    // Assimp reads the rest of the line as one file name.
    std::string name;
    std::getline(words >> std::ws, name);
    while (!name.empty() && std::isspace(static_cast<unsigned char>(name.back()))) name.pop_back();
    if (name.empty()) continue;
    const fs::path library = obj.parent_path() / name;
    std::error_code ec;
    if (fs::exists(library, ec))
      requireRegularFile(library, ("material library of " + obj.string()).c_str());
  }
}

}  // namespace

void requireReadableMeshFile(const fs::path& path) {
  const std::string name = path.string();
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(name + ": mesh file not found");
  if (!fs::is_regular_file(path, ec)) throw InputError(name + ": mesh path is not a regular file");
  requireRegularFile(path, "mesh file");  // a /proc file passes the test above
  if (!std::ifstream(path, std::ios::binary).good())
    throw InputError(name + ": cannot read mesh file (" + std::strerror(errno) + ")");
  std::string extension = path.extension().string();
  for (char& c : extension) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (extension == ".obj") requireRegularMaterialLibraries(path);
}

}  // namespace sslpv
