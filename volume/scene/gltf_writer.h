#pragma once
// A small glTF 2 writer for rigged meshes: one mesh, one skin, a joint chain or tree and
// keyframed clips, the buffer embedded as base64 in the JSON. The tests and the example
// generator make their skinned inputs with it at run time, so no binary asset lives in git.
#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>
#include <string>
#include <vector>

namespace sslpv {

struct GltfRig {
  std::vector<glm::vec3> positions;
  std::vector<glm::uvec3> triangles;
  /// Per vertex, up to 4 joints and their weights; both empty: a mesh without a skin.
  std::vector<glm::uvec4> vertexJoints;
  std::vector<glm::vec4> vertexWeights;

  struct Joint {
    std::string name;
    int parent = -1;  ///< an earlier joint, or -1 for a root
    glm::dvec3 translation{0.0};  ///< bind pose, relative to the parent
    glm::dquat rotation{1.0, 0.0, 0.0, 0.0};
  };
  std::vector<Joint> joints;

  struct Channel {
    int joint = 0;
    std::string path = "rotation";  ///< "translation", "rotation" or "scale"
    std::vector<double> times;      ///< seconds, increasing
    std::vector<glm::dvec4> values; ///< xyz (w unused) or a quaternion as (x, y, z, w)
  };
  struct Clip {
    std::string name;
    std::vector<Channel> channels;
  };
  std::vector<Clip> clips;
};

/// The rig as glTF 2 JSON text (.gltf).
std::string writeGltf(const GltfRig& rig);

/// A bar from x = 0 to `length`, `width` square across, centred on the x axis, with
/// `segments` quads along its length (welded, closed, counter-clockwise outward) and a
/// chain of `jointCount` joints at x = i * length / jointCount. Each vertex is weighted to
/// the joint whose span holds it, blended linearly with the neighbour over `blend` either
/// side of a joint's start. No clips.
GltfRig skinnedBar(double length, double width, int segments, int jointCount, double blend);

/// `angleDeg` about z as a glTF rotation value (x, y, z, w).
glm::dvec4 gltfRotationZ(double angleDeg);

/// A rotation channel of `joint` about z through `degrees` at `times`. Rigs are built with
/// this rather than braced lists of dvec4: GCC 12.2 at -O3 with AVX-512 (SSLPV_NATIVE on
/// an AVX-512 machine) builds a braced list of constant dvec4s as copies of the first.
GltfRig::Channel gltfTurnZ(int joint, const std::vector<double>& times, const std::vector<double>& degrees);

}  // namespace sslpv
