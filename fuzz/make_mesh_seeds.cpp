// Writes skinned glTF seeds for mesh_fuzz (first byte: the harness's extension index of
// "gltf"), made at fuzz time with the writer the tests use rather than committed: a rig
// with clips, one without a skin, and one whose clip animates a node with no joint.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "volume/scene/gltf_writer.h"

namespace {

void writeSeed(const std::filesystem::path& file, const std::string& gltf) {
  std::ofstream out(file, std::ios::binary);
  out << char(4) << gltf;  // mesh_fuzz: kExtensions[4] is "gltf"
}

}  // namespace

int main(int argc, char** argv) {
  using namespace sslpv;
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUTPUT_DIR\n", argv[0]);
    return 2;
  }
  const std::filesystem::path dir = argv[1];
  std::filesystem::create_directories(dir);
  GltfRig rig = skinnedBar(2.0, 0.5, 4, 2, 0.2);
  // Key values pushed one by one: GCC 12.2 at -O3 with AVX-512 builds a braced list of
  // constant dvec4s as copies of the first.
  const GltfRig::Channel turn = gltfTurnZ(1, {0.0, 1.0}, {0.0, 90.0});
  GltfRig::Channel move{0, "translation", {0.0, 0.5}, {}}, grow{1, "scale", {0.0, 2.0}, {}};
  move.values.push_back(glm::dvec4(0.0));
  move.values.push_back(glm::dvec4(0.0, 1.0, 0.0, 0.0));
  grow.values.push_back(glm::dvec4(1.0));
  grow.values.push_back(glm::dvec4(2.0, 1.0, 1.0, 0.0));
  rig.clips = {{"Bend", {turn, move}}, {"Scale", {grow}}};
  writeSeed(dir / "skinned_bar.gltf", writeGltf(rig));
  GltfRig plain = rig;
  plain.vertexJoints.clear();
  plain.vertexWeights.clear();
  writeSeed(dir / "unskinned_bar.gltf", writeGltf(plain));
  return 0;
}
