// Mesh import through assimp (volume/scene/mesh.cpp) as a scene's "mesh": {"path": ...} uses it,
// and the skinned import (volume/scene/skin_import.cpp) that "animation" adds.
// Assimp picks its importer by the file's extension, so the first input byte chooses one
// of the formats users bring; the rest is the file.
#include <cstdint>
#include <iterator>

#include "fuzz/fuzz_support.h"
#include "volume/scene/mesh.h"
#include "volume/scene/skin.h"

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
  // The skinned import of the same file (mesh.animation), and its poses.
  fuzz::expectOnlyInputErrors([&] {
    const SkinnedMesh skinned = loadSkinnedMesh(source.path);
    const auto grid = std::make_shared<const PointGrid>(
        std::vector<glm::dvec3>(skinned.rest.positions.begin(), skinned.rest.positions.end()));
    for (std::size_t clip = 0; clip < skinned.skin.clips.size() && clip < 4; ++clip) {
      const SkinClip& c = skinned.skin.clips[selectClip(skinned, "", int(clip))];
      for (double t : {c.start(), 0.5 * (c.start() + c.end()), c.end()}) {
        const SkinPose pose(skinned, grid, &c, t);
        (void)skinnedPositions(pose, "", t);
        (void)pose.inverse(pose.posedVertices().empty() ? glm::dvec3(0.0) : pose.posedVertices()[0]);
      }
    }
  });
  return 0;
}
