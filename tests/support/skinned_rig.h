#pragma once
// The rigged bar the skinning tests generate at run time (volume/scene/gltf_writer.h): no
// binary glTF lives in the repository.
#include <string>

#include "volume/scene/gltf_writer.h"

namespace sslpv::test {

/// Bar length, width, the joints' spacing and the blend half-width of the test rig.
inline constexpr double kBarLength = 2.0, kBarWidth = 0.5, kJointSpan = 2.0 / 3.0, kBlend = 0.25;

/// A 2 x 0.5 x 0.5 bar along x from the origin, 40 segments long, with a chain of three
/// joints at x = 0, 2/3 and 4/3. Clip 0 "Idle" holds the bind pose; clip 1 "Bend" turns
/// the last joint about z from 0 to 90 degrees over t in [0, 1] s, lifting the bar's last
/// third towards +y.
inline GltfRig bendingBarRig() {
  GltfRig rig = skinnedBar(kBarLength, kBarWidth, 40, 3, kBlend);
  GltfRig::Clip idle{"Idle", {gltfTurnZ(0, {0.0, 1.0}, {0.0, 0.0})}};
  GltfRig::Clip bend{"Bend", {gltfTurnZ(2, {0.0, 1.0}, {0.0, 90.0})}};
  rig.clips = {idle, bend};
  return rig;
}

/// A scene around a mesh file (the small CLI scene's lights and camera scaled to the bar);
/// `animation` is the mesh.animation value as JSON text, empty for none.
inline std::string skinnedBarScene(const std::string& meshPath, const std::string& animation,
                                   const std::string& extraMaterial = "") {
  return std::string(R"({
    "mesh": {"path": ")") + meshPath + "\"" + (animation.empty() ? "" : ", \"animation\": " + animation) + R"(},
    "material": {"base": {"sigma_t": 1, "sigma_s": 0.5})" + extraMaterial + R"(},
    "lights": [{"type": "directional", "direction": [0, -1, -0.3], "irradiance": 1}],
    "camera": {"position": [1, 0.5, 6], "target": [1, 0.5, 0], "fov_y_deg": 40, "width": 40, "height": 40},
    "lpv": {"resolution": 16, "steps": "auto"}
  })";
}

}  // namespace sslpv::test
