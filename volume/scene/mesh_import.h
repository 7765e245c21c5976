#pragma once
// What the static mesh import (mesh.cpp) shares with the skinned one (skin_import.cpp):
// the checks a mesh file passes before a reader child opens it, and the vertex welding.
#include <filesystem>
#include <vector>

#include "volume/scene/mesh.h"

namespace sslpv {

/// InputError naming the file unless it is a readable regular file (and an OBJ's material
/// libraries are regular files): assimp blocks on a FIFO or a device.
void requireReadableMeshFile(const std::filesystem::path& path);

/// Merges vertices at bit-identical positions; returns each old vertex's new index.
std::vector<unsigned> weldExactDuplicates(TriangleMesh& mesh);

}  // namespace sslpv
