#pragma once
// Skinned animation read from a mesh file (glTF 2 through assimp): the joint hierarchy,
// per-vertex joint weights, the clips' keyframes, and the pose of a clip at a time by
// linear blend skinning. The scene selects a clip with "mesh": {"path": ..., "animation":
// name or index} (docs/formats.md). As with the procedural deformers (deform.h), the
// material set stays in the rest (bind) space and each frame maps points back to it, here
// through the inverse of the skinning matrices blended around the point (SkinPose).
#include <glm/gtc/quaternion.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "volume/scene/deform.h"
#include "volume/scene/mesh.h"

namespace sslpv {

/// Keys in seconds, non-decreasing; before the first key the first value holds, after the
/// last the last value (a clip does not loop).
struct Vec3Track {
  std::vector<double> times;
  std::vector<glm::dvec3> values;
  glm::dvec3 at(double t, const glm::dvec3& fallback) const;  ///< linear; fallback when empty
};
struct RotationTrack {
  std::vector<double> times;
  std::vector<glm::dquat> values;  ///< unit quaternions
  glm::dquat at(double t, const glm::dquat& fallback) const;  ///< slerp along the shorter arc
};

struct SkinNode {
  std::int32_t parent = -1;  ///< an earlier node's index, or -1 for a root
  glm::dvec3 translation{0.0};
  glm::dquat rotation{1.0, 0.0, 0.0, 0.0};
  glm::dvec3 scale{1.0};
  std::string name;
};

struct SkinJoint {
  std::uint32_t node = 0;
  /// Rest space -> the joint's space at bind time: the file's inverse bind matrix after
  /// the inverse of the skinned mesh node's transform (rest space is the mesh as the
  /// static import lays it out, the mesh node's transform applied).
  glm::dmat4 restToJoint{1.0};
};

struct SkinChannel {
  std::uint32_t node = 0;
  Vec3Track translation, scale;
  RotationTrack rotation;
};

struct SkinClip {
  std::string name;
  std::vector<SkinChannel> channels;
  double start() const;  ///< the earliest key (0 for a clip without keys)
  double end() const;    ///< the latest key
};

/// Up to 4 influences a vertex: indices into joints, weights summing to 1 (all zero for a
/// vertex no joint moves: it stays at rest).
struct SkinInfluence {
  glm::uvec4 joints{0u};
  glm::vec4 weights{0.0f};
};

struct Skin {
  std::vector<SkinNode> nodes;  ///< parents before children
  std::vector<SkinJoint> joints;
  std::vector<SkinInfluence> influences;  ///< one per rest vertex
  std::vector<SkinClip> clips;
};

/// A mesh file's rest mesh (welded, as loadMesh's file path makes it, no transform) and its
/// skin. The rest mesh carries no skin data when the file has none (joints empty).
struct SkinnedMesh {
  TriangleMesh rest;
  Skin skin;
};

/// Reads `path` with its skin in the mesh reader child (volume/scene/skin_import.cpp).
/// InputError naming the file on a bad file.
SkinnedMesh loadSkinnedMesh(const std::filesystem::path& path);

/// The clip a scene asks for (by name, or by index when `index` >= 0). InputError
/// "<mesh file>: ..." when the mesh has no skin, no clips or not that clip (listing them).
std::size_t selectClip(const SkinnedMesh& mesh, const std::string& name, int index);

/// Rest space -> posed space of each joint at time t of `clip` (null: the nodes' own
/// transforms, the file's default pose).
std::vector<glm::dmat4> jointMatrices(const Skin& skin, const SkinClip* clip, double t);

/// Finds the nearest of a fixed set of points: a uniform grid of point lists (CSR).
class PointGrid {
 public:
  explicit PointGrid(std::vector<glm::dvec3> points);
  /// Up to k (<= kMaxK) nearest points to q, nearest first; returns how many.
  int nearest(const glm::dvec3& q, int k, std::uint32_t* index, double* distance2) const;
  static constexpr int kMaxK = 16;

 private:
  glm::ivec3 cellOf_(const glm::dvec3& p) const;
  std::vector<glm::dvec3> points_;
  glm::dvec3 origin_{0.0};
  double cell_ = 1.0;
  glm::ivec3 dims_{1};
  std::vector<std::uint32_t> start_, items_;
};

/// A clip at one time. forward() of an arbitrary point blends the skinning matrices of
/// the kNeighbours nearest rest vertices with inverse-square-distance weights and applies
/// the blend: a vertex itself maps exactly by its own matrix, and between vertices the
/// map varies smoothly, so the painted material follows the surface it was painted near.
/// inverse() starts from the same blend around the nearest posed vertices, inverted.
class SkinPose : public SpaceDeformation {
 public:
  /// `restGrid` over the rest vertices is the same for every pose: built once by the caller.
  SkinPose(const SkinnedMesh& mesh, std::shared_ptr<const PointGrid> restGrid, const SkinClip* clip, double t);
  glm::dvec3 forward(const glm::dvec3& rest) const override;
  /// blendedInverse(), then kRefinements fixed-point steps towards forward(rest) = deformed.
  glm::dvec3 inverse(const glm::dvec3& deformed) const override;
  /// The one-step inverse: the blend of the posed neighbours' matrices, inverted.
  glm::dvec3 blendedInverse(const glm::dvec3& deformed) const;
  /// The rest vertices by linear blend skinning.
  const std::vector<glm::dvec3>& posedVertices() const { return posed_; }
  static constexpr int kNeighbours = 8;
  static constexpr int kRefinements = 4;

 private:
  glm::dmat4 blended(const PointGrid& grid, const glm::dvec3& p) const;
  std::vector<glm::dmat4> vertexMatrices_;  ///< per vertex: rest -> posed
  std::vector<glm::dvec3> posed_;
  std::shared_ptr<const PointGrid> restGrid_;
  std::unique_ptr<PointGrid> posedGrid_;
};

/// The rest vertices posed, range-checked as deformPositions does. InputError
/// "<file>: mesh.animation: at t = ..." when a vertex leaves the coordinate range.
std::vector<glm::vec3> skinnedPositions(const SkinPose& pose, const std::string& file, double t);

}  // namespace sslpv
