#include "volume/scene/gltf_writer.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat4x4.hpp>
#include <nlohmann/json.hpp>

#include "volume/scene/mesh.h"

namespace sslpv {
namespace {

using nlohmann::json;

constexpr int kFloat = 5126, kUnsignedShort = 5123, kUnsignedInt = 5125;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;

std::string base64(const std::string& bytes) {
  static const char* const kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    std::uint32_t v = std::uint32_t(std::uint8_t(bytes[i])) << 16;
    if (i + 1 < bytes.size()) v |= std::uint32_t(std::uint8_t(bytes[i + 1])) << 8;
    if (i + 2 < bytes.size()) v |= std::uint32_t(std::uint8_t(bytes[i + 2]));
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? kAlphabet[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kAlphabet[v & 63] : '=';
  }
  return out;
}

/// Appends views and accessors to one buffer.
struct Builder {
  std::string buffer;
  json views = json::array(), accessors = json::array();

  template <class T>
  int add(const std::vector<T>& items, int componentType, const char* type, int count, int target = 0) {
    while (buffer.size() % 4) buffer += '\0';
    json view = {{"buffer", 0}, {"byteOffset", buffer.size()}, {"byteLength", items.size() * sizeof(T)}};
    if (target) view["target"] = target;
    buffer.append(reinterpret_cast<const char*>(items.data()), items.size() * sizeof(T));
    views.push_back(view);
    accessors.push_back({{"bufferView", views.size() - 1}, {"componentType", componentType}, {"count", count},
                         {"type", type}});
    return int(accessors.size() - 1);
  }
};

glm::dmat4 jointLocal(const GltfRig::Joint& j) {
  return glm::translate(glm::dmat4(1.0), j.translation) * glm::mat4_cast(j.rotation);
}

}  // namespace

glm::dvec4 gltfRotationZ(double angleDeg) {
  const double half = 0.5 * angleDeg * M_PI / 180.0;
  return {0.0, 0.0, std::sin(half), std::cos(half)};
}

GltfRig::Channel gltfTurnZ(int joint, const std::vector<double>& times, const std::vector<double>& degrees) {
  GltfRig::Channel channel;
  channel.joint = joint;
  channel.path = "rotation";
  channel.times = times;
  for (double d : degrees) channel.values.push_back(gltfRotationZ(d));
  return channel;
}

std::string writeGltf(const GltfRig& rig) {
  Builder b;
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const glm::vec3& p : rig.positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  const int position = b.add(rig.positions, kFloat, "VEC3", int(rig.positions.size()), kArrayBuffer);
  b.accessors[std::size_t(position)]["min"] = {lo.x, lo.y, lo.z};
  b.accessors[std::size_t(position)]["max"] = {hi.x, hi.y, hi.z};
  const int indices = b.add(rig.triangles, kUnsignedInt, "SCALAR", int(rig.triangles.size() * 3), kElementArrayBuffer);
  json attributes = {{"POSITION", position}};
  const bool skinned = !rig.joints.empty() && rig.vertexJoints.size() == rig.positions.size();
  json nodes = json::array();
  json meshNode = {{"name", "mesh"}, {"mesh", 0}};
  json sceneNodes = {0};
  json doc;
  if (skinned) {
    std::vector<glm::u16vec4> joints16;
    for (const glm::uvec4& j : rig.vertexJoints) joints16.emplace_back(j);
    attributes["JOINTS_0"] = b.add(joints16, kUnsignedShort, "VEC4", int(joints16.size()), kArrayBuffer);
    attributes["WEIGHTS_0"] = b.add(rig.vertexWeights, kFloat, "VEC4", int(rig.vertexWeights.size()), kArrayBuffer);
    // Inverse bind matrices: the inverse of each joint's global transform in the bind pose.
    std::vector<glm::dmat4> global(rig.joints.size());
    std::vector<glm::mat4> inverseBind;
    for (std::size_t j = 0; j < rig.joints.size(); ++j) {
      const int parent = rig.joints[j].parent;
      global[j] = (parent >= 0 ? global[std::size_t(parent)] : glm::dmat4(1.0)) * jointLocal(rig.joints[j]);
      inverseBind.emplace_back(glm::inverse(global[j]));
    }
    const int ibm = b.add(inverseBind, kFloat, "MAT4", int(inverseBind.size()));
    json jointNodes = json::array();
    for (std::size_t j = 0; j < rig.joints.size(); ++j) jointNodes.push_back(j + 1);
    meshNode["skin"] = 0;
    nodes.push_back(meshNode);
    for (std::size_t j = 0; j < rig.joints.size(); ++j) {
      const GltfRig::Joint& joint = rig.joints[j];
      json node = {{"name", joint.name},
                   {"translation", {joint.translation.x, joint.translation.y, joint.translation.z}},
                   {"rotation", {joint.rotation.x, joint.rotation.y, joint.rotation.z, joint.rotation.w}}};
      json children = json::array();
      for (std::size_t c = 0; c < rig.joints.size(); ++c)
        if (rig.joints[c].parent == int(j)) children.push_back(c + 1);
      if (!children.empty()) node["children"] = children;
      nodes.push_back(node);
      if (joint.parent < 0) sceneNodes.push_back(j + 1);
    }
    json skin = {{"joints", jointNodes}, {"inverseBindMatrices", ibm}};
    json gltfSkins = json::array({skin});
    json animations = json::array();
    for (const GltfRig::Clip& clip : rig.clips) {
      json samplers = json::array(), channels = json::array();
      for (const GltfRig::Channel& c : clip.channels) {
        std::vector<float> times(c.times.begin(), c.times.end());
        const int input = b.add(times, kFloat, "SCALAR", int(times.size()));
        b.accessors[std::size_t(input)]["min"] = {times.front()};
        b.accessors[std::size_t(input)]["max"] = {times.back()};
        const bool rotation = c.path == "rotation";
        std::vector<float> values;
        for (const glm::dvec4& v : c.values)
          for (int k = 0; k < (rotation ? 4 : 3); ++k) values.push_back(float(v[k]));
        const int output = b.add(values, kFloat, rotation ? "VEC4" : "VEC3", int(c.values.size()));
        samplers.push_back({{"input", input}, {"output", output}, {"interpolation", "LINEAR"}});
        channels.push_back({{"sampler", samplers.size() - 1}, {"target", {{"node", c.joint + 1}, {"path", c.path}}}});
      }
      animations.push_back({{"name", clip.name}, {"samplers", samplers}, {"channels", channels}});
    }
    doc["skins"] = gltfSkins;
    if (!animations.empty()) doc["animations"] = animations;
  } else {
    nodes.push_back(meshNode);
  }
  doc["asset"] = {{"version", "2.0"}, {"generator", "sslpv gltf_writer"}};
  doc["scene"] = 0;
  doc["scenes"] = {{{"nodes", sceneNodes}}};
  doc["nodes"] = nodes;
  doc["meshes"] = {{{"name", "mesh"}, {"primitives", {{{"attributes", attributes}, {"indices", indices}}}}}};
  doc["accessors"] = b.accessors;
  doc["bufferViews"] = b.views;
  doc["buffers"] = {{{"byteLength", b.buffer.size()},
                     {"uri", "data:application/octet-stream;base64," + base64(b.buffer)}}};
  return doc.dump(1);
}

GltfRig skinnedBar(double length, double width, int segments, int jointCount, double blend) {
  MeshSource box;
  box.kind = MeshSource::Kind::Box;
  box.boxMin = glm::dvec3(0.0, -0.5 * width, -0.5 * width);
  box.boxMax = glm::dvec3(length, 0.5 * width, 0.5 * width);
  box.boxSegments = glm::ivec3(segments, 2, 2);
  const TriangleMesh mesh = loadMesh(box, Transform{}, false);
  GltfRig rig;
  rig.positions = mesh.positions;
  rig.triangles = mesh.triangles;
  const double span = length / jointCount;
  for (int j = 0; j < jointCount; ++j)
    rig.joints.push_back({"joint" + std::to_string(j), j - 1, glm::dvec3(j == 0 ? 0.0 : span, 0.0, 0.0)});
  for (const glm::vec3& p : rig.positions) {
    const int j = std::clamp(int(std::floor(p.x / span)), 0, jointCount - 1);
    glm::uvec4 joints(unsigned(j), 0u, 0u, 0u);
    glm::vec4 weights(1.0f, 0.0f, 0.0f, 0.0f);
    // Across a joint's start (x = j span) the weight goes linearly from the parent to it.
    const double fromStart = p.x - j * span, toEnd = (j + 1) * span - p.x;
    if (j > 0 && fromStart < blend) {
      const float w = float(0.5 + 0.5 * fromStart / blend);
      joints = {unsigned(j), unsigned(j - 1), 0u, 0u};
      weights = {w, 1.0f - w, 0.0f, 0.0f};
    } else if (j + 1 < jointCount && toEnd < blend) {
      const float w = float(0.5 + 0.5 * toEnd / blend);
      joints = {unsigned(j), unsigned(j + 1), 0u, 0u};
      weights = {w, 1.0f - w, 0.0f, 0.0f};
    }
    rig.vertexJoints.push_back(joints);
    rig.vertexWeights.push_back(weights);
  }
  return rig;
}

}  // namespace sslpv
