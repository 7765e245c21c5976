// The skinned import: as loadMesh's file path (mesh.cpp), assimp runs in a forked reader
// child, and what comes back over the pipe is plain data the parent re-validates: the
// triangles, each vertex's joint influences, the node hierarchy, the joints' bind
// matrices and the clips' keys. Nothing the child says is trusted to be in range.
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <unordered_map>

#include "volume/core/error.h"
#include "volume/core/isolated_child.h"
#include "volume/scene/mesh_import.h"
#include "volume/scene/skin.h"

namespace sslpv {
namespace {

namespace fs = std::filesystem;

/// Node and joint names longer than this are cut: they only label clips and messages.
constexpr std::size_t kMaxName = 200;

class ByteWriter {
 public:
  template <class T>
  void pod(const T& value) {
    out.append(reinterpret_cast<const char*>(&value), sizeof value);
  }
  void text(const std::string& s) {
    const std::string cut = s.substr(0, kMaxName);
    pod(std::uint32_t(cut.size()));
    out += cut;
  }
  std::string out;
};

class ByteReader {
 public:
  ByteReader(const std::string& bytes, std::string name) : bytes_(bytes), name_(std::move(name)) {}
  template <class T>
  T pod() {
    need(sizeof(T));
    T value;
    std::memcpy(&value, bytes_.data() + at_, sizeof value);
    at_ += sizeof value;
    return value;
  }
  /// A count of items of at least `itemBytes` each that must fit in what is left.
  std::size_t count(std::size_t itemBytes) {
    const auto n = pod<std::uint64_t>();
    if (n > (bytes_.size() - at_) / std::max<std::size_t>(itemBytes, 1)) damaged();
    return std::size_t(n);
  }
  std::string text() {
    const std::size_t n = pod<std::uint32_t>();
    if (n > kMaxName) damaged();
    need(n);
    std::string s = bytes_.substr(at_, n);
    at_ += n;
    return s;
  }
  double finite() {
    const double v = pod<double>();
    if (!std::isfinite(v)) damaged();
    return v;
  }
  bool done() const { return at_ == bytes_.size(); }
  [[noreturn]] void damaged() const {
    throw InputError(name_ + ": the mesh reader process returned a damaged result");
  }

 private:
  void need(std::size_t n) const {
    if (n > bytes_.size() - at_) damaged();
  }
  const std::string& bytes_;
  std::string name_;
  std::size_t at_ = 0;
};

glm::dmat4 toGlm(const aiMatrix4x4& m) {
  glm::dmat4 r;
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 4; ++col) r[col][row] = m[row][col];  // assimp is row-major
  return r;
}

glm::dquat toGlm(const aiQuaternion& q) {
  const glm::dquat r(q.w, q.x, q.y, q.z);
  const double n = glm::length(r);
  return n > 1e-12 && std::isfinite(n) ? r / n : glm::dquat(1.0, 0.0, 0.0, 0.0);
}

bool finiteMatrix(const glm::dmat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return false;
  return true;
}

template <class Key, class Value>
void writeKeys(ByteWriter& w, const Key* keys, unsigned count, double ticksPerSecond, int components,
               Value (*value)(const Key&)) {
  std::vector<unsigned> order(keys ? count : 0u);
  std::iota(order.begin(), order.end(), 0u);
  // Keys out of time order would make interpolation run backwards; a DCC exports them sorted.
  std::stable_sort(order.begin(), order.end(), [&](unsigned a, unsigned b) { return keys[a].mTime < keys[b].mTime; });
  w.pod(std::uint64_t(order.size()));
  for (unsigned k : order) {
    w.pod(double(keys[k].mTime) / ticksPerSecond);
    const Value v = value(keys[k]);
    for (int c = 0; c < components; ++c) w.pod(double(v[c]));
  }
}

glm::dvec3 vectorKey(const aiVectorKey& k) { return {k.mValue.x, k.mValue.y, k.mValue.z}; }
glm::dvec4 quatKey(const aiQuatKey& k) {
  const glm::dquat q = toGlm(k.mValue);
  return {q.w, q.x, q.y, q.z};
}

/// The import proper, in the reader child.
std::string importSkinned(const fs::path& path) {
  const std::string name = path.string();
  Assimp::Importer importer;
  auto failure = [&] {
    std::string reason = importer.GetErrorString();
    std::replace(reason.begin(), reason.end(), '\n', ' ');
    return InputError(name + ": cannot load mesh: " + (reason.empty() ? "unknown assimp error" : reason));
  };
  // LimitBoneWeights keeps the 4 largest influences of a vertex and renormalises them.
  const aiScene* scene = importer.ReadFile(name, aiProcess_Triangulate | aiProcess_LimitBoneWeights);
  if (!scene || !scene->mRootNode) throw failure();

  // Nodes in pre-order (parents first), with an explicit stack: a hostile file's hierarchy
  // may be deeper than the call stack.
  std::vector<const aiNode*> nodes;
  std::vector<std::int32_t> parents;
  std::unordered_map<std::string, std::uint32_t> nodeByName;
  std::vector<std::pair<const aiNode*, std::int32_t>> stack{{scene->mRootNode, -1}};
  while (!stack.empty()) {
    const auto [node, parent] = stack.back();
    stack.pop_back();
    if (!node) continue;
    const auto index = std::uint32_t(nodes.size());
    nodes.push_back(node);
    parents.push_back(parent);
    nodeByName.emplace(node->mName.C_Str(), index);
    for (unsigned c = node->mNumChildren; c-- > 0;)
      if (node->mChildren) stack.emplace_back(node->mChildren[c], std::int32_t(index));
  }
  std::vector<glm::dmat4> global(nodes.size());
  for (std::size_t n = 0; n < nodes.size(); ++n) {
    const glm::dmat4 local = toGlm(nodes[n]->mTransformation);
    global[n] = parents[n] >= 0 ? global[std::size_t(parents[n])] * local : local;
    if (!finiteMatrix(global[n])) throw InputError(name + ": node '" + nodes[n]->mName.C_Str() + "' has a non-finite transform");
  }

  // Each mesh a node holds, posed by that node as the static import's PreTransformVertices does.
  std::vector<glm::vec3> positions;
  std::vector<glm::uvec3> triangles;
  std::vector<SkinInfluence> influences;
  std::vector<SkinJoint> joints;
  for (std::size_t n = 0; n < nodes.size(); ++n) {
    const aiNode* node = nodes[n];
    for (unsigned i = 0; node->mMeshes && i < node->mNumMeshes; ++i) {
      if (node->mMeshes[i] >= scene->mNumMeshes || !scene->mMeshes) continue;
      const aiMesh* part = scene->mMeshes[node->mMeshes[i]];
      if (!part || !part->mVertices || (part->mNumFaces > 0 && !part->mFaces)) continue;
      const std::size_t base = positions.size();
      if (base + part->mNumVertices > std::numeric_limits<std::uint32_t>::max())
        throw InputError(name + ": too many vertices for 32-bit indices");
      for (unsigned v = 0; v < part->mNumVertices; ++v) {
        const aiVector3D& p = part->mVertices[v];
        const glm::dvec3 rest(global[n] * glm::dvec4(p.x, p.y, p.z, 1.0));
        if (!std::isfinite(rest.x) || !std::isfinite(rest.y) || !std::isfinite(rest.z))
          throw InputError(name + ": vertex " + std::to_string(base + v) + " has a non-finite coordinate");
        positions.emplace_back(rest);
      }
      for (unsigned f = 0; f < part->mNumFaces; ++f) {
        const aiFace& face = part->mFaces[f];
        if (face.mNumIndices != 3 || !face.mIndices) continue;
        for (unsigned k = 0; k < 3; ++k)
          if (face.mIndices[k] >= part->mNumVertices)
            throw InputError(name + ": face " + std::to_string(f) + " indexes a missing vertex");
        triangles.emplace_back(base + face.mIndices[0], base + face.mIndices[1], base + face.mIndices[2]);
      }
      influences.resize(positions.size());
      const glm::dmat4 meshToRest = global[n];
      for (unsigned b = 0; part->mBones && b < part->mNumBones; ++b) {
        const aiBone* bone = part->mBones[b];
        if (!bone) continue;
        const auto found = nodeByName.find(bone->mName.C_Str());
        if (found == nodeByName.end())
          throw InputError(name + ": joint '" + std::string(bone->mName.C_Str()).substr(0, kMaxName) +
                           "' names no node of the hierarchy");
        SkinJoint joint;
        joint.node = found->second;
        joint.restToJoint = toGlm(bone->mOffsetMatrix) * glm::inverse(meshToRest);
        if (!finiteMatrix(joint.restToJoint))
          throw InputError(name + ": joint '" + std::string(bone->mName.C_Str()).substr(0, kMaxName) +
                           "' has a non-finite inverse bind matrix");
        const auto jointIndex = std::uint32_t(joints.size());
        joints.push_back(joint);
        for (unsigned w = 0; bone->mWeights && w < bone->mNumWeights; ++w) {
          const aiVertexWeight& weight = bone->mWeights[w];
          if (weight.mVertexId >= part->mNumVertices || !(weight.mWeight > 0.0f) || !std::isfinite(weight.mWeight))
            continue;
          // Keep the 4 largest, replacing the smallest when full.
          SkinInfluence& in = influences[base + weight.mVertexId];
          int slot = 0;
          for (int s = 1; s < 4; ++s)
            if (in.weights[s] < in.weights[slot]) slot = s;
          if (weight.mWeight > in.weights[slot]) {
            in.weights[slot] = weight.mWeight;
            in.joints[slot] = jointIndex;
          }
        }
      }
    }
  }
  if (triangles.empty()) throw InputError(name + ": mesh file contains no triangles");
  influences.resize(positions.size());
  for (SkinInfluence& in : influences) {
    const float total = in.weights[0] + in.weights[1] + in.weights[2] + in.weights[3];
    in.weights = total > 0.0f ? in.weights / total : glm::vec4(0.0f);
  }

  ByteWriter w;
  w.pod(std::uint64_t(positions.size()));
  w.pod(std::uint64_t(triangles.size()));
  for (const glm::vec3& p : positions) w.pod(p);
  for (const glm::uvec3& t : triangles) w.pod(t);
  for (const SkinInfluence& in : influences) {
    w.pod(in.joints);
    w.pod(in.weights);
  }
  w.pod(std::uint64_t(nodes.size()));
  for (std::size_t n = 0; n < nodes.size(); ++n) {
    aiVector3D scale, position;
    aiQuaternion rotation;
    nodes[n]->mTransformation.Decompose(scale, rotation, position);
    const glm::dquat q = toGlm(rotation);
    w.pod(parents[n]);
    for (double v : {double(position.x), double(position.y), double(position.z), q.w, q.x, q.y, q.z,
                     double(scale.x), double(scale.y), double(scale.z)})
      w.pod(std::isfinite(v) ? v : 0.0);
    w.text(nodes[n]->mName.C_Str());
  }
  w.pod(std::uint64_t(joints.size()));
  for (const SkinJoint& j : joints) {
    w.pod(j.node);
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) w.pod(j.restToJoint[c][r]);
  }
  const unsigned clips = scene->mAnimations ? scene->mNumAnimations : 0u;
  w.pod(std::uint64_t(clips));
  for (unsigned a = 0; a < clips; ++a) {
    const aiAnimation* anim = scene->mAnimations[a];
    w.text(anim ? anim->mName.C_Str() : "");
    // Keys are in ticks; a file that gives no rate is read as seconds.
    const double ticksPerSecond = anim && anim->mTicksPerSecond > 0.0 && std::isfinite(anim->mTicksPerSecond)
                                      ? anim->mTicksPerSecond
                                      : 1.0;
    std::vector<std::pair<const aiNodeAnim*, std::uint32_t>> channels;
    for (unsigned c = 0; anim && anim->mChannels && c < anim->mNumChannels; ++c) {
      const aiNodeAnim* channel = anim->mChannels[c];
      if (!channel) continue;
      // A channel of a node the hierarchy lacks moves nothing.
      const auto found = nodeByName.find(channel->mNodeName.C_Str());
      if (found != nodeByName.end()) channels.emplace_back(channel, found->second);
    }
    w.pod(std::uint64_t(channels.size()));
    for (const auto& [channel, node] : channels) {
      w.pod(node);
      writeKeys(w, channel->mPositionKeys, channel->mNumPositionKeys, ticksPerSecond, 3, vectorKey);
      writeKeys(w, channel->mRotationKeys, channel->mNumRotationKeys, ticksPerSecond, 4, quatKey);
      writeKeys(w, channel->mScalingKeys, channel->mNumScalingKeys, ticksPerSecond, 3, vectorKey);
    }
  }
  return w.out;
}

int importSkinnedInChild(const fs::path& path, int fd) {
  std::string bytes;
  try {
    bytes = importSkinned(path);
  } catch (const InputError& e) {
    const std::string message = e.what();
    writeFully(fd, message.data(), message.size());
    return kChildParseError;
  }
  return writeFully(fd, bytes.data(), bytes.size()) ? kChildOk : kChildWriteError;
}

template <int N>
void readKeys(ByteReader& in, std::vector<double>& times, std::vector<glm::vec<N, double>>& values) {
  const std::size_t count = in.count(sizeof(double) * (N + 1));
  for (std::size_t k = 0; k < count; ++k) {
    times.push_back(in.finite());
    if (k > 0 && times[k] < times[k - 1]) in.damaged();
    glm::vec<N, double> v;
    for (int c = 0; c < N; ++c) v[c] = in.finite();
    values.push_back(v);
  }
}

SkinnedMesh decodeSkinned(const std::string& bytes, const std::string& name) {
  ByteReader in(bytes, name);
  SkinnedMesh mesh;
  mesh.rest.name = name;
  constexpr std::size_t kVertexBytes = sizeof(glm::vec3) + sizeof(glm::uvec4) + sizeof(glm::vec4);
  const std::size_t vertices = in.count(kVertexBytes);
  const std::size_t triangles = in.count(sizeof(glm::uvec3));
  for (std::size_t v = 0; v < vertices; ++v) {
    const auto p = in.pod<glm::vec3>();
    if (!std::isfinite(p.x + p.y + p.z)) in.damaged();
    mesh.rest.positions.push_back(p);
  }
  for (std::size_t t = 0; t < triangles; ++t) {
    const auto tri = in.pod<glm::uvec3>();
    if (tri.x >= vertices || tri.y >= vertices || tri.z >= vertices) in.damaged();
    mesh.rest.triangles.push_back(tri);
  }
  for (std::size_t v = 0; v < vertices; ++v) {
    SkinInfluence influence;
    influence.joints = in.pod<glm::uvec4>();
    influence.weights = in.pod<glm::vec4>();
    mesh.skin.influences.push_back(influence);
  }
  const std::size_t nodes = in.count(sizeof(std::int32_t) + 10 * sizeof(double) + sizeof(std::uint32_t));
  for (std::size_t n = 0; n < nodes; ++n) {
    SkinNode node;
    node.parent = in.pod<std::int32_t>();
    if (node.parent < -1 || node.parent >= std::int32_t(n)) in.damaged();
    for (int c = 0; c < 3; ++c) node.translation[c] = in.finite();
    node.rotation.w = in.finite();
    node.rotation.x = in.finite();
    node.rotation.y = in.finite();
    node.rotation.z = in.finite();
    for (int c = 0; c < 3; ++c) node.scale[c] = in.finite();
    node.name = in.text();
    mesh.skin.nodes.push_back(node);
  }
  const std::size_t joints = in.count(sizeof(std::uint32_t) + 16 * sizeof(double));
  for (std::size_t j = 0; j < joints; ++j) {
    SkinJoint joint;
    joint.node = in.pod<std::uint32_t>();
    if (joint.node >= nodes) in.damaged();
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) joint.restToJoint[c][r] = in.finite();
    mesh.skin.joints.push_back(joint);
  }
  for (const SkinInfluence& influence : mesh.skin.influences)
    for (int i = 0; i < 4; ++i)
      if (!(influence.weights[i] >= 0.0f && influence.weights[i] <= 1.0f) ||
          (influence.weights[i] > 0.0f && influence.joints[i] >= joints))
        in.damaged();
  const std::size_t clips = in.count(sizeof(std::uint32_t) + sizeof(std::uint64_t));
  for (std::size_t a = 0; a < clips; ++a) {
    SkinClip clip;
    clip.name = in.text();
    const std::size_t channels = in.count(sizeof(std::uint32_t) + 3 * sizeof(std::uint64_t));
    for (std::size_t c = 0; c < channels; ++c) {
      SkinChannel channel;
      channel.node = in.pod<std::uint32_t>();
      if (channel.node >= nodes) in.damaged();
      readKeys<3>(in, channel.translation.times, channel.translation.values);
      std::vector<glm::dvec4> rotations;
      readKeys<4>(in, channel.rotation.times, rotations);
      for (const glm::dvec4& q : rotations) channel.rotation.values.emplace_back(q.x, q.y, q.z, q.w);
      readKeys<3>(in, channel.scale.times, channel.scale.values);
      clip.channels.push_back(std::move(channel));
    }
    mesh.skin.clips.push_back(std::move(clip));
  }
  if (!in.done()) in.damaged();
  return mesh;
}

}  // namespace

SkinnedMesh loadSkinnedMesh(const fs::path& path) {
  const std::string name = path.string();
  requireReadableMeshFile(path);
  static const IsolatedParser kParser{"mesh file", "the assimp importer", "the mesh reader process"};
  std::error_code ec;
  const std::size_t bytes = fs::file_size(path, ec);
  const std::size_t size = ec ? 0 : bytes;
  // The static import's limits (mesh.cpp): a loop in assimp ends, a bomb meets the budget.
  const auto timeout = std::chrono::seconds(5 + size / (1u << 20));
  ChildOutput output = runIsolated(name, kParser, isolatedMemoryBudget(size, 64), timeout,
                                   [&path](int fd) { return importSkinnedInChild(path, fd); });
  if (output.parseError)
    throw InputError(output.bytes.empty() ? name + ": cannot load mesh: unknown error" : output.bytes);
  SkinnedMesh mesh = decodeSkinned(output.bytes, name);
  // Welded as the static import welds; a vertex split at a UV seam has its twin's weights.
  const std::vector<unsigned> remap = weldExactDuplicates(mesh.rest);
  std::vector<SkinInfluence> welded(mesh.rest.positions.size());
  std::vector<bool> set(welded.size(), false);
  for (std::size_t i = 0; i < remap.size(); ++i)
    if (!set[remap[i]]) {
      welded[remap[i]] = mesh.skin.influences[i];
      set[remap[i]] = true;
    }
  mesh.skin.influences = std::move(welded);
  // Without joints the file has no skin: clips then animate rigid nodes, which a skinned
  // scene does not play (selectClip says so).
  return mesh;
}

}  // namespace sslpv
