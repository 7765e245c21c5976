// Writes the skinned example into the folder given as argv[1] (the build runs it into
// build/examples/skinned_finger): a rigged finger as glTF 2 with a "Curl" clip, a painted
// nail as a material set, and the scene that plays the clip. Generated at build time
// rather than committed, so the repository holds no base64 or VDB blob for it:
//
//   build/examples/make_skinned_example build/examples/skinned_finger
//   build/sslpv render build/examples/skinned_finger/skinned_finger.json --time 1 -o finger.png
#include <openvdb/openvdb.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "volume/material/material_set.h"
#include "volume/scene/gltf_writer.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// A 40 x 8 x 8 mm finger along x with three phalanges (joints at 0, 13.3 and 26.7 mm),
// each joint's weights blended over 4 mm either side.
constexpr double kLength = 40.0, kWidth = 8.0, kBlend = 4.0;

void writeText(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
  if (!out.flush()) throw std::runtime_error("cannot write " + file.string());
}

/// "Curl": the middle joint turns 40 degrees and the last 50 towards +y over the first
/// second, then both straighten again by t = 2 s.
sslpv::GltfRig finger() {
  sslpv::GltfRig rig = sslpv::skinnedBar(kLength, kWidth, 60, 3, kBlend);
  rig.joints[0].name = "knuckle";
  rig.joints[1].name = "middle";
  rig.joints[2].name = "tip";
  sslpv::GltfRig::Clip curl{"Curl", {}};
  for (const auto& [joint, degrees] : {std::pair{1, 40.0}, std::pair{2, 50.0}})
    curl.channels.push_back(sslpv::gltfTurnZ(joint, {0.0, 1.0, 2.0}, {0.0, degrees, 0.0}));
  rig.clips = {curl};
  return rig;
}

/// A pale, denser nail on the back (-y) face of the last 7 mm, in the finger's rest space:
/// the finger curls towards +y, the palm side, so the nail ends up on the outside.
std::size_t writeNail(const fs::path& file) {
  auto set = std::make_shared<sslpv::MaterialSet>();
  set->sigmaT = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  set->sigmaS = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  set->sigmaT->setName("sigma_t");
  set->sigmaS->setName("sigma_s");
  for (auto& grid : {set->sigmaT, set->sigmaS})
    grid->setTransform(openvdb::math::Transform::createLinearTransform(0.5));
  set->units = "mm";
  set->creator = "sslpv make_skinned_example";
  auto t = set->sigmaT->getAccessor();
  auto s = set->sigmaS->getAccessor();
  std::size_t voxels = 0;
  // x 33 to 40.5 mm, y from one voxel past the back face to -2 mm, z within ±3 mm.
  for (int i = 66; i <= 81; ++i)
    for (int j = -9; j <= -4; ++j)
      for (int k = -6; k <= 6; ++k) {
        t.setValue(openvdb::Coord(i, j, k), openvdb::Vec3s(4.0f, 4.2f, 4.4f));
        s.setValue(openvdb::Coord(i, j, k), openvdb::Vec3s(3.9f, 4.0f, 4.1f));
        ++voxels;
      }
  sslpv::saveMaterialSet(*set, file);
  return voxels;
}

json scene() {
  return json::parse(R"({
    "units": "mm",
    "mesh": {"path": "skinned_finger.gltf", "animation": "Curl"},
    "material": {"base": {"preset": "skin1"}, "vdb": "skinned_finger_nail.vdb", "ior": 1.4},
    "lights": [
      {"type": "spot", "position": [-20, 70, 60], "direction": [0.4025, -0.6418, -0.6527], "fov_deg": 45,
       "intensity": [16000, 15500, 15000]},
      {"type": "point", "position": [50, 10, -50], "intensity": [5000, 4800, 4500]}
    ],
    "camera": {"position": [17, 12, 80], "target": [17, 11, 0], "up": [0, 1, 0], "fov_y_deg": 40,
               "width": 512, "height": 512},
    "lpv": {"resolution": 32, "steps": "auto", "shadow_map": 256}
  })");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: make_skinned_example OUTPUT_DIR\n";
    return 2;
  }
  try {
    const fs::path dir = argv[1];
    fs::create_directories(dir);
    openvdb::initialize();
    writeText(dir / "skinned_finger.gltf", sslpv::writeGltf(finger()));
    const std::size_t voxels = writeNail(dir / "skinned_finger_nail.vdb");
    writeText(dir / "skinned_finger.json", scene().dump(2) + "\n");
    std::cout << "make_skinned_example: wrote " << dir.string()
              << ": skinned_finger.gltf, skinned_finger_nail.vdb (" << voxels << " voxels), skinned_finger.json\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "make_skinned_example: error: " << e.what() << "\n";
    return 1;
  }
}
