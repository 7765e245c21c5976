#include "volume/scene/mesh.h"

// Orientation note for consumers: loadMesh returns closed meshes wound counter-clockwise
// seen from outside. A file that is inside-out or has some faces reversed is reoriented
// (orientOutward) with a warning on stderr; meshes with holes keep the winding they have.

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <glm/geometric.hpp>
#include <glm/vector_relational.hpp>
#include <limits>
#include <sstream>
#include <unordered_map>

#include "volume/core/error.h"
#include "volume/core/input_file.h"
#include "volume/core/input_ranges.h"
#include "volume/core/isolated_child.h"
#include "volume/scene/mesh_import.h"

namespace sslpv {
namespace {

namespace fs = std::filesystem;

std::string formatPoint(const glm::dvec3& p) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.6g, %.6g, %.6g)", p.x, p.y, p.z);
  return text;
}

std::string coordinateRange() {
  char text[64];
  std::snprintf(text, sizeof text, "[%g, %g]", -kMaxCoordinate, kMaxCoordinate);
  return text;
}

/// A box whose faces are grids of segments[b] x segments[c] quads, welded along the edges.
TriangleMesh makeSegmentedBox(const MeshSource& source) {
  const glm::ivec3 n = source.boxSegments;
  TriangleMesh mesh;
  mesh.name = "box";
  std::unordered_map<std::size_t, std::uint32_t> indexOf;
  auto vertex = [&](const glm::ivec3& c) {
    const std::size_t key = (std::size_t(c.z) * std::size_t(n.y + 1) + std::size_t(c.y)) * std::size_t(n.x + 1) +
                            std::size_t(c.x);
    const auto [it, added] = indexOf.emplace(key, std::uint32_t(mesh.positions.size()));
    if (added) {
      glm::dvec3 p;
      for (int a = 0; a < 3; ++a)
        p[a] = c[a] == n[a] ? source.boxMax[a]
                            : source.boxMin[a] + (source.boxMax[a] - source.boxMin[a]) * double(c[a]) / double(n[a]);
      mesh.positions.emplace_back(p);
    }
    return it->second;
  };
  for (int a = 0; a < 3; ++a) {
    // (b, c) in cyclic order after a, so b x c points along +a.
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    for (int side = 0; side < 2; ++side)
      for (int i = 0; i < n[b]; ++i)
        for (int j = 0; j < n[c]; ++j) {
          glm::ivec3 p00(0);
          p00[a] = side ? n[a] : 0;
          p00[b] = i;
          p00[c] = j;
          glm::ivec3 p10 = p00, p01 = p00;
          p10[b] += 1;
          p01[c] += 1;
          glm::ivec3 p11 = p10;
          p11[c] += 1;
          const std::uint32_t v00 = vertex(p00), v10 = vertex(p10), v11 = vertex(p11), v01 = vertex(p01);
          if (side) {
            mesh.triangles.push_back({v00, v10, v11});
            mesh.triangles.push_back({v00, v11, v01});
          } else {
            mesh.triangles.push_back({v00, v11, v10});
            mesh.triangles.push_back({v00, v01, v11});
          }
        }
  }
  return mesh;
}

TriangleMesh makeBox(const MeshSource& source) {
  for (int axis = 0; axis < 3; ++axis) {
    if (!(source.boxMin[axis] < source.boxMax[axis]) || !std::isfinite(source.boxMin[axis]) ||
        !std::isfinite(source.boxMax[axis]))
      throw InputError("box: min " + formatPoint(source.boxMin) + " must be below max " +
                       formatPoint(source.boxMax) + " on every axis");
  }
  if (source.boxSegments != glm::ivec3(1)) return makeSegmentedBox(source);
  TriangleMesh mesh;
  mesh.name = "box";
  // Corner i has x from bit 0, y from bit 1, z from bit 2.
  for (int i = 0; i < 8; ++i) {
    mesh.positions.emplace_back(glm::dvec3((i & 1) ? source.boxMax.x : source.boxMin.x,
                                           (i & 2) ? source.boxMax.y : source.boxMin.y,
                                           (i & 4) ? source.boxMax.z : source.boxMin.z));
  }
  // Two triangles a face, counter-clockwise seen from outside.
  mesh.triangles = {
      {0, 4, 6}, {0, 6, 2},  // -x
      {1, 3, 7}, {1, 7, 5},  // +x
      {0, 1, 5}, {0, 5, 4},  // -y
      {2, 6, 7}, {2, 7, 3},  // +y
      {0, 2, 3}, {0, 3, 1},  // -z
      {4, 5, 7}, {4, 7, 6},  // +z
  };
  return mesh;
}

/// Geodesic icosphere: uniform triangles (no pole pinching, unlike a UV sphere), 20 * 4^5 =
/// 20480 triangles, enough that its volume is within 0.1 % of the true sphere's.
TriangleMesh makeSphere(const MeshSource& source) {
  if (!(source.radius > 0.0) || !std::isfinite(source.radius) ||
      !std::isfinite(glm::length(source.center)))
    throw InputError("sphere: radius must be positive and finite, got " + std::to_string(source.radius));
  constexpr int kSubdivisions = 5;
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<glm::dvec3> unit = {
      {-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
      {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1},
  };
  for (auto& p : unit) p = glm::normalize(p);
  std::vector<glm::uvec3> triangles = {
      {0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
      {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1},
  };
  for (int level = 0; level < kSubdivisions; ++level) {
    // Each edge is split once and its midpoint shared by both neighbours: the sphere stays
    // welded and closed.
    std::unordered_map<std::uint64_t, unsigned> midpoints;
    midpoints.reserve(triangles.size() * 2);
    auto midpoint = [&](unsigned a, unsigned b) {
      std::uint64_t key = (std::uint64_t(std::min(a, b)) << 32) | std::max(a, b);
      auto [it, inserted] = midpoints.try_emplace(key, unsigned(unit.size()));
      if (inserted) unit.push_back(glm::normalize(unit[a] + unit[b]));
      return it->second;
    };
    std::vector<glm::uvec3> finer;
    finer.reserve(triangles.size() * 4);
    for (const auto& tri : triangles) {
      unsigned ab = midpoint(tri.x, tri.y), bc = midpoint(tri.y, tri.z), ca = midpoint(tri.z, tri.x);
      finer.push_back({tri.x, ab, ca});
      finer.push_back({tri.y, bc, ab});
      finer.push_back({tri.z, ca, bc});
      finer.push_back({ab, bc, ca});
    }
    triangles.swap(finer);
  }
  TriangleMesh mesh;
  mesh.name = "sphere";
  mesh.positions.reserve(unit.size());
  for (const auto& p : unit) mesh.positions.emplace_back(source.center + source.radius * p);
  mesh.triangles = std::move(triangles);
  return mesh;
}

}  // namespace

/// Importers split vertices at normal and UV seams (and STL stores every triangle's
/// corners separately), which would make a closed surface look full of holes.
std::vector<unsigned> weldExactDuplicates(TriangleMesh& mesh) {
  struct KeyHash {
    std::size_t operator()(const std::array<std::uint32_t, 3>& k) const {
      std::uint64_t h = k[0] * 0x9E3779B97F4A7C15ull;
      h = (h ^ (h >> 29) ^ k[1]) * 0xBF58476D1CE4E5B9ull;
      h = (h ^ (h >> 31) ^ k[2]) * 0x94D049BB133111EBull;
      return std::size_t(h ^ (h >> 32));
    }
  };
  auto keyOf = [](const glm::vec3& p) {
    std::array<std::uint32_t, 3> key;
    for (int i = 0; i < 3; ++i) {
      float v = p[i] + 0.0f;  // -0 and +0 are the same point
      std::memcpy(&key[i], &v, sizeof v);
    }
    return key;
  };
  std::unordered_map<std::array<std::uint32_t, 3>, unsigned, KeyHash> firstIndex;
  firstIndex.reserve(mesh.positions.size());
  std::vector<unsigned> remap(mesh.positions.size());
  std::vector<glm::vec3> welded;
  welded.reserve(mesh.positions.size());
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    auto [it, inserted] = firstIndex.try_emplace(keyOf(mesh.positions[i]), unsigned(welded.size()));
    if (inserted) welded.push_back(mesh.positions[i]);
    remap[i] = it->second;
  }
  for (auto& tri : mesh.triangles) tri = glm::uvec3(remap[tri.x], remap[tri.y], remap[tri.z]);
  mesh.positions.swap(welded);
  return remap;
}

namespace {

/// The assimp import proper; runs in the reader child (see loadMeshFile).
TriangleMesh importWithAssimp(const fs::path& path) {
  const std::string name = path.string();
  Assimp::Importer importer;
  auto failure = [&] {
    std::string reason = importer.GetErrorString();
    std::replace(reason.begin(), reason.end(), '\n', ' ');
    return InputError(name + ": cannot load mesh: " + (reason.empty() ? "unknown assimp error" : reason));
  };
  // No aiProcess_JoinIdenticalVertices: it merges vertices closer than an absolute 1e-5,
  // which folds a small (but valid) mesh into a non-manifold one; weldExactDuplicates
  // joins only bit-identical positions, whatever the mesh's size.
  // Face indices are range-checked below rather than with aiProcess_ValidateDataStructure,
  // whose messages ("aiScene::mNumMeshes is 0") would only confuse a user.
  const aiScene* scene = importer.ReadFile(path.string(), aiProcess_Triangulate);
  if (!scene) throw failure();
  bool anyFace = false;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m)
    anyFace = anyFace || (scene->mMeshes[m] && scene->mMeshes[m]->mNumFaces > 0);
  // Checked before PreTransformVertices, which reports a point cloud as "all meshes are
  // orphaned" instead.
  if (!anyFace) throw InputError(name + ": mesh file contains no triangles");
  // Bakes the node hierarchy into the vertices, so multi-part files (FBX, glTF) come out
  // in their authored layout, all parts in one frame.
  scene = importer.ApplyPostProcessing(aiProcess_PreTransformVertices);
  if (!scene) throw failure();

  TriangleMesh mesh;
  mesh.name = name;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* part = scene->mMeshes[m];
    if (!part || !part->mVertices || (part->mNumFaces > 0 && !part->mFaces)) continue;
    const std::size_t base = mesh.positions.size();
    if (base + part->mNumVertices > std::numeric_limits<unsigned>::max())
      throw InputError(name + ": too many vertices for 32-bit indices");
    for (unsigned v = 0; v < part->mNumVertices; ++v) {
      const aiVector3D& p = part->mVertices[v];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        throw InputError(name + ": vertex " + std::to_string(base + v) + " has a non-finite coordinate");
      mesh.positions.emplace_back(p.x, p.y, p.z);
    }
    // Points and lines (faces with 1 or 2 indices) bound no volume; they are not surface.
    for (unsigned f = 0; f < part->mNumFaces; ++f) {
      const aiFace& face = part->mFaces[f];
      if (face.mNumIndices != 3 || !face.mIndices) continue;
      for (unsigned k = 0; k < 3; ++k) {
        if (face.mIndices[k] >= part->mNumVertices)
          throw InputError(name + ": face " + std::to_string(f) + " of mesh " + std::to_string(m) +
                           " indexes a missing vertex");
      }
      mesh.triangles.emplace_back(base + face.mIndices[0], base + face.mIndices[1],
                                  base + face.mIndices[2]);
    }
  }
  if (mesh.triangles.empty()) throw InputError(name + ": mesh file contains no triangles");
  return mesh;
}

/// The child's result on its pipe: vertex and triangle counts (u64), then the float
/// positions and the u32 indices.
int importInChild(const fs::path& path, int fd) {
  TriangleMesh mesh;
  try {
    mesh = importWithAssimp(path);
  } catch (const InputError& e) {
    const std::string message = e.what();
    writeFully(fd, message.data(), message.size());
    return kChildParseError;
  }
  const std::uint64_t counts[2] = {mesh.positions.size(), mesh.triangles.size()};
  const bool written =
      writeFully(fd, reinterpret_cast<const char*>(counts), sizeof counts) &&
      writeFully(fd, reinterpret_cast<const char*>(mesh.positions.data()), mesh.positions.size() * sizeof(glm::vec3)) &&
      writeFully(fd, reinterpret_cast<const char*>(mesh.triangles.data()), mesh.triangles.size() * sizeof(glm::uvec3));
  return written ? kChildOk : kChildWriteError;
}

TriangleMesh decodeChildMesh(const std::string& bytes, const std::string& name) {
  const InputError damaged(name + ": the mesh reader process returned a damaged result");
  std::uint64_t counts[2];
  if (bytes.size() < sizeof counts) throw damaged;
  std::memcpy(counts, bytes.data(), sizeof counts);
  if (counts[0] > bytes.size() || counts[1] > bytes.size() ||
      bytes.size() != sizeof counts + counts[0] * sizeof(glm::vec3) + counts[1] * sizeof(glm::uvec3))
    throw damaged;
  TriangleMesh mesh;
  mesh.name = name;
  mesh.positions.resize(counts[0]);
  mesh.triangles.resize(counts[1]);
  const char* data = bytes.data() + sizeof counts;
  std::memcpy(mesh.positions.data(), data, counts[0] * sizeof(glm::vec3));
  std::memcpy(mesh.triangles.data(), data + counts[0] * sizeof(glm::vec3), counts[1] * sizeof(glm::uvec3));
  for (const glm::uvec3& t : mesh.triangles)
    if (t.x >= counts[0] || t.y >= counts[0] || t.z >= counts[0]) throw damaged;
  return mesh;
}

/// Assimp is not hardened against corrupt files: fuzzing found malformed PLY faces that
/// end in its internal assertions (abort), and its importers are large C++ parsers of
/// untrusted input. So, like VDB files (volume/material/vdb_isolated_read.h), the import runs in a
/// forked child and only the triangle soup it produced comes back.
TriangleMesh loadMeshFile(const fs::path& path) {
  const std::string name = path.string();
  std::error_code ec;
  requireReadableMeshFile(path);

  static const IsolatedParser kParser{"mesh file", "the assimp importer", "the mesh reader process"};
  const std::size_t bytes = fs::file_size(path, ec);
  const std::size_t size = ec ? 0 : bytes;
  // Fuzzing also found a 200-byte PLY (a property line cut in half) on which assimp never
  // returns. Importers read at tens of MB/s, so 5 s plus 1 s per MiB only stops such a
  // loop, well before a user would give up on the tool.
  const auto timeout = std::chrono::seconds(5 + size / (1u << 20));
  // Assimp's scene graph plus post-processing copies: tens of bytes per byte of text.
  ChildOutput output = runIsolated(name, kParser, isolatedMemoryBudget(size, 64), timeout,
                                   [&path](int fd) { return importInChild(path, fd); });
  if (output.parseError)
    throw InputError(output.bytes.empty() ? name + ": cannot load mesh: unknown error" : output.bytes);
  TriangleMesh mesh = decodeChildMesh(output.bytes, name);
  weldExactDuplicates(mesh);
  return mesh;
}

struct TopologyDetails {
  MeshTopology counts;
  glm::dvec3 boundaryExample{0.0};     ///< midpoint of one boundary edge
  glm::dvec3 nonManifoldExample{0.0};  ///< midpoint of one non-manifold edge
};

TopologyDetails analyze(const TriangleMesh& mesh) {
  TopologyDetails details;
  // Sorting packed 64-bit edge keys is several times faster than hashing index pairs and
  // keeps 1M-triangle meshes well under a second.
  std::vector<std::uint64_t> edges;
  edges.reserve(mesh.triangles.size() * 3);
  for (const auto& tri : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      std::uint32_t a = tri[k], b = tri[(k + 1) % 3];
      edges.push_back((std::uint64_t(std::min(a, b)) << 32) | std::max(a, b));
    }
    glm::dvec3 p0(mesh.positions[tri.x]), p1(mesh.positions[tri.y]), p2(mesh.positions[tri.z]);
    glm::dvec3 e1 = p1 - p0, e2 = p2 - p0;
    double longest2 = std::max({glm::dot(e1, e1), glm::dot(e2, e2), glm::dot(p2 - p1, p2 - p1)});
    // Relative test: float vertices on a line give a cross product of rounding size only.
    double area2 = glm::length(glm::cross(e1, e2));
    if (!(area2 > 1e-12 * longest2)) ++details.counts.degenerateTriangles;
  }
  tbb::parallel_sort(edges.begin(), edges.end());
  auto midpoint = [&](std::uint64_t key) {
    return 0.5 * (glm::dvec3(mesh.positions[key >> 32]) + glm::dvec3(mesh.positions[key & 0xffffffffu]));
  };
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i + 1;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    std::size_t uses = j - i;
    if (uses == 1) {
      if (details.counts.boundaryEdges++ == 0) details.boundaryExample = midpoint(edges[i]);
    } else if (uses >= 3) {
      if (details.counts.nonManifoldEdges++ == 0) details.nonManifoldExample = midpoint(edges[i]);
    }
    i = j;
  }
  return details;
}

/// Does the ray o + t d, t > 0, cross triangle abc?
bool rayCrosses(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& a, const glm::dvec3& b,
                const glm::dvec3& c) {
  // Möller–Trumbore, counting crossings ahead of the origin only.
  const glm::dvec3 e1 = b - a, e2 = c - a, p = glm::cross(d, e2);
  const double det = glm::dot(e1, p);
  if (std::abs(det) < 1e-300) return false;
  const glm::dvec3 s = o - a;
  const double u = glm::dot(s, p) / det;
  if (u < 0.0 || u > 1.0) return false;
  const glm::dvec3 q = glm::cross(s, e1);
  const double v = glm::dot(d, q) / det;
  if (v < 0.0 || u + v > 1.0) return false;
  return glm::dot(e2, q) / det > 0.0;
}

/// Makes a closed mesh's winding consistent and outward: neighbours across each edge must
/// traverse it in opposite directions (else one of them is flipped, found by a walk over
/// the edge adjacency), and each connected part then faces outward, which its signed
/// volume decides (positive, or negative for a part nested an odd number of times inside
/// others: a cavity's surface faces into the cavity). The shadow maps and the shading take
/// "outside" from the winding, so an inward or partly reversed mesh rendered black or dark.
/// Returns how many triangles were flipped; a mesh with holes, non-manifold edges or no
/// consistent orientation is left as it is (requireClosedMesh names the first two).
std::size_t orientOutward(TriangleMesh& mesh) {
  const std::size_t count = mesh.triangles.size();
  struct HalfEdge {
    std::uint64_t key;
    std::uint32_t triangle;
    bool forward;  ///< traversed from the smaller vertex index to the larger
    bool operator<(const HalfEdge& o) const { return key < o.key || (key == o.key && triangle < o.triangle); }
  };
  std::vector<HalfEdge> halves;
  halves.reserve(count * 3);
  for (std::size_t t = 0; t < count; ++t)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = mesh.triangles[t][k], b = mesh.triangles[t][(k + 1) % 3];
      halves.push_back({(std::uint64_t(std::min(a, b)) << 32) | std::max(a, b), std::uint32_t(t), a < b});
    }
  tbb::parallel_sort(halves.begin(), halves.end());
  // Each edge joins exactly two triangles; `same` says whether they traverse it alike.
  struct Link {
    std::uint32_t other;
    bool same;
  };
  std::vector<std::array<Link, 3>> links(count);
  std::vector<int> linkCount(count, 0);
  for (std::size_t i = 0; i < halves.size(); i += 2) {
    if (i + 1 >= halves.size() || halves[i + 1].key != halves[i].key ||
        (i + 2 < halves.size() && halves[i + 2].key == halves[i].key))
      return 0;
    const HalfEdge& x = halves[i];
    const HalfEdge& y = halves[i + 1];
    const bool same = x.forward == y.forward;
    if (linkCount[x.triangle] == 3 || linkCount[y.triangle] == 3) return 0;
    links[x.triangle][std::size_t(linkCount[x.triangle]++)] = {y.triangle, same};
    links[y.triangle][std::size_t(linkCount[y.triangle]++)] = {x.triangle, same};
  }
  // Flip relative to each component's first triangle.
  constexpr int kUnset = -1;
  std::vector<int> flip(count, kUnset), component(count, kUnset);
  std::vector<std::uint32_t> firstOf, stack;
  for (std::size_t seed = 0; seed < count; ++seed) {
    if (flip[seed] != kUnset) continue;
    const int id = int(firstOf.size());
    firstOf.push_back(std::uint32_t(seed));
    flip[seed] = 0;
    component[seed] = id;
    stack.assign(1, std::uint32_t(seed));
    while (!stack.empty()) {
      const std::uint32_t t = stack.back();
      stack.pop_back();
      for (int k = 0; k < linkCount[t]; ++k) {
        const Link& link = links[t][std::size_t(k)];
        const int wanted = flip[t] ^ int(link.same);
        if (flip[link.other] == kUnset) {
          flip[link.other] = wanted;
          component[link.other] = id;
          stack.push_back(link.other);
        } else if (flip[link.other] != wanted) {
          return 0;  // not orientable (a one-sided surface): nothing consistent to restore
        }
      }
    }
  }
  const auto corner = [&](std::size_t t, int k) { return glm::dvec3(mesh.positions[mesh.triangles[t][k]]); };
  const Bounds bounds = mesh.bounds();
  const glm::dvec3 ref = 0.5 * (bounds.min + bounds.max);
  std::vector<double> volume(firstOf.size(), 0.0);
  for (std::size_t t = 0; t < count; ++t) {
    const double six = glm::dot(corner(t, 0) - ref, glm::cross(corner(t, 1) - ref, corner(t, 2) - ref));
    volume[std::size_t(component[t])] += flip[t] ? -six : six;
  }
  // Nesting parity by a ray from a point on each part through the other parts. It costs
  // parts × triangles, so beyond kMaxNestingParts every part counts as outermost.
  constexpr std::size_t kMaxNestingParts = 64;
  std::vector<bool> nested(firstOf.size(), false);
  if (firstOf.size() > 1 && firstOf.size() <= kMaxNestingParts) {
    const glm::dvec3 direction = glm::normalize(glm::dvec3(0.5773, 0.6168, 0.5350));
    for (std::size_t c = 0; c < firstOf.size(); ++c) {
      const std::size_t t0 = firstOf[c];
      const glm::dvec3 origin = (corner(t0, 0) + corner(t0, 1) + corner(t0, 2)) / 3.0;
      bool odd = false;
      for (std::size_t t = 0; t < count; ++t)
        if (std::size_t(component[t]) != c && rayCrosses(origin, direction, corner(t, 0), corner(t, 1), corner(t, 2)))
          odd = !odd;
      nested[c] = odd;
    }
  }
  std::size_t flipped = 0;
  for (std::size_t t = 0; t < count; ++t) {
    const std::size_t c = std::size_t(component[t]);
    const bool outward = (volume[c] > 0.0) != nested[c];
    if ((flip[t] != 0) == outward) {
      std::swap(mesh.triangles[t].y, mesh.triangles[t].z);
      ++flipped;
    }
  }
  return flipped;
}

}  // namespace

TriangleMesh loadMesh(const MeshSource& source, const Transform& transform, bool warnReoriented) {
  TriangleMesh mesh;
  switch (source.kind) {
    case MeshSource::Kind::Box: mesh = makeBox(source); break;
    case MeshSource::Kind::Sphere: mesh = makeSphere(source); break;
    case MeshSource::Kind::File: mesh = loadMeshFile(source.path); break;
    case MeshSource::Kind::InMemory:
      if (!source.mesh) throw InputError("mesh: in-memory mesh missing");
      mesh = *source.mesh;
      break;
  }
  if (!(transform.scale > 0.0) || !std::isfinite(transform.scale))
    throw InputError(mesh.name + ": transform scale must be positive, got " + std::to_string(transform.scale));
  const glm::dmat4 toWorld = transform.matrix();
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    const glm::dvec3 world(toWorld * glm::dvec4(glm::dvec3(mesh.positions[i]), 1.0));
    // Checked in double, before float rounding could turn an overflow into Inf.
    if (!(glm::all(glm::lessThanEqual(glm::abs(world), glm::dvec3(kMaxCoordinate)))))
      throw InputError(mesh.name + ": vertex " + std::to_string(i) + " lies at " + formatPoint(world) +
                       " after the transform, outside the coordinate range " + coordinateRange());
    mesh.positions[i] = glm::vec3(world);
  }
  if (const std::size_t flipped = orientOutward(mesh); flipped > 0 && warnReoriented)
    std::cerr << "sslpv: warning: " << mesh.name << ": " << flipped << " of " << mesh.triangles.size()
              << " triangles faced inward or against their neighbours; reoriented them to face outward\n";
  return mesh;
}

MeshTopology analyzeTopology(const TriangleMesh& mesh) { return analyze(mesh).counts; }

double signedVolume(const TriangleMesh& mesh) {
  if (mesh.positions.empty()) return 0.0;
  // Divergence theorem: sum of tetrahedra from a reference point to each triangle. Using
  // the bounds centre instead of the origin avoids cancellation for meshes far from it.
  const Bounds bounds = mesh.bounds();
  const glm::dvec3 ref = 0.5 * (bounds.min + bounds.max);
  double sixTimesVolume = 0.0;
  for (const auto& tri : mesh.triangles) {
    glm::dvec3 a = glm::dvec3(mesh.positions[tri.x]) - ref;
    glm::dvec3 b = glm::dvec3(mesh.positions[tri.y]) - ref;
    glm::dvec3 c = glm::dvec3(mesh.positions[tri.z]) - ref;
    sixTimesVolume += glm::dot(a, glm::cross(b, c));
  }
  return sixTimesVolume / 6.0;
}

double meanChordLength(const TriangleMesh& mesh) {
  double area = 0.0;
  for (const auto& tri : mesh.triangles) {
    const glm::dvec3 a(mesh.positions[tri.x]), b(mesh.positions[tri.y]), c(mesh.positions[tri.z]);
    area += 0.5 * glm::length(glm::cross(b - a, c - a));
  }
  return area > 0.0 ? 4.0 * std::abs(signedVolume(mesh)) / area : 0.0;
}

void requireClosedMesh(const TriangleMesh& mesh) {
  const std::string watertight = "; SSLPV needs a watertight surface";
  if (mesh.triangles.empty()) throw InputError(mesh.name + ": mesh has no triangles");
  const TopologyDetails details = analyze(mesh);
  if (details.counts.boundaryEdges > 0)
    throw InputError(mesh.name + ": mesh is not closed: " + std::to_string(details.counts.boundaryEdges) +
                     " boundary edges (a hole near " + formatPoint(details.boundaryExample) + ")" +
                     watertight);
  if (details.counts.nonManifoldEdges > 0)
    throw InputError(mesh.name + ": mesh is not manifold: " +
                     std::to_string(details.counts.nonManifoldEdges) +
                     " edges shared by 3 or more triangles (one near " +
                     formatPoint(details.nonManifoldExample) + ")" + watertight);
  // Relative to the bounding box so that the check is independent of the scene's units.
  const glm::dvec3 extent = mesh.bounds().extent();
  const double volume = std::abs(signedVolume(mesh));
  if (!(volume > 1e-9 * extent.x * extent.y * extent.z) || !(volume > 0.0))
    throw InputError(mesh.name + ": mesh encloses no volume (its triangles cancel out or are flat)" +
                     watertight);
}

}  // namespace sslpv
