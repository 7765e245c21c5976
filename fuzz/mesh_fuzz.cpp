// Mesh import through assimp (volume/scene/mesh.cpp) as a scene's "mesh": {"path": ...} uses it.
// Assimp picks its importer by the file's extension, so the first input byte chooses one
// of the formats users bring; the rest is the file.
#include <cstdint>
#include <iterator>

#include "fuzz/fuzz_support.h"
#include "volume/scene/mesh.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sslpv;
  if (size == 0) return 0;
  static const char* const kExtensions[] = {"obj", "ply", "stl", "off", "gltf", "glb", "dae", "fbx"};
  const char* extension = kExtensions[data[0] % std::size(kExtensions)];
  MeshSource source;
  source.kind = MeshSource::Kind::File;
  source.path = fuzz::writeScratchFile(std::string("mesh.") + extension, data + 1, size - 1);
  fuzz::expectOnlyInputErrors([&] {
    const TriangleMesh mesh = loadMesh(source, Transform{});
    (void)analyzeTopology(mesh);
    (void)signedVolume(mesh);
    requireClosedMesh(mesh);
  });
  return 0;
}
