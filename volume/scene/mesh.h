#pragma once
// Triangle meshes in world space: loaded with assimp or built from primitives.
#include <glm/common.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <string>
#include <vector>

#include "volume/core/bounds.h"
#include "volume/scene/scene.h"

namespace sslpv {

struct TriangleMesh {
  std::string name;                  ///< file name or "box"/"sphere", for messages
  std::vector<glm::vec3> positions;  ///< world space, welded (shared vertices are shared indices)
  std::vector<glm::uvec3> triangles; ///< counter-clockwise seen from outside
  Bounds bounds() const {
    Bounds b;
    for (const auto& p : positions) b.extend(glm::dvec3(p));
    return b;
  }
};

struct MeshTopology {
  std::size_t boundaryEdges = 0;     ///< edges used by one triangle: the mesh has holes
  std::size_t nonManifoldEdges = 0;  ///< edges used by three or more triangles
  std::size_t degenerateTriangles = 0;  ///< zero-area triangles
};

/// Loads the scene's mesh (file via assimp, or a primitive), welds vertices and applies
/// `transform`. Throws InputError for a missing/unreadable/empty file or degenerate
/// primitive parameters. Triangles facing inward are turned outward, with a warning on
/// stderr unless `warnReoriented` is false (a second load of a mesh already reported).
TriangleMesh loadMesh(const MeshSource& source, const Transform& transform, bool warnReoriented = true);

MeshTopology analyzeTopology(const TriangleMesh& mesh);

/// Throws InputError naming the mesh when it is not closed (boundary or non-manifold
/// edges), has no triangles, or has zero volume.
void requireClosedMesh(const TriangleMesh& mesh);

/// Signed enclosed volume (positive for outward-facing triangles).
double signedVolume(const TriangleMesh& mesh);

/// Mean length of the chords of uniformly random lines through a closed mesh (Cauchy's
/// formula, 4 V / S); 0 for an empty mesh.
double meanChordLength(const TriangleMesh& mesh);

}  // namespace sslpv
