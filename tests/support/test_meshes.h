#pragma once
// Meshes built by hand for tests, independent of the mesh loader: an axis-aligned box and
// an icosphere, both closed and wound counter-clockwise seen from outside.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <glm/geometric.hpp>
#include <unordered_map>
#include <vector>

#include "volume/lpv/lpv_grid.h"
#include "volume/scene/mesh.h"

namespace sslpv::test {

inline TriangleMesh makeBoxMesh(const glm::vec3& lo, const glm::vec3& hi) {
  TriangleMesh mesh;
  mesh.name = "test box";
  for (int i = 0; i < 8; ++i)
    mesh.positions.emplace_back(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
  // Two triangles per face, vertex bit 0 = x, 1 = y, 2 = z; each quad listed CCW from outside.
  const unsigned quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5},   // -x, +x
                                {0, 1, 5, 4}, {2, 6, 7, 3},   // -y, +y
                                {0, 2, 3, 1}, {4, 5, 7, 6}};  // -z, +z
  for (const auto& q : quads) {
    mesh.triangles.emplace_back(q[0], q[1], q[2]);
    mesh.triangles.emplace_back(q[0], q[2], q[3]);
  }
  return mesh;
}

/// Icosahedron subdivided `levels` times (20 * 4^levels triangles), vertices on the sphere.
inline TriangleMesh makeIcosphere(const glm::vec3& center, float radius, int levels) {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  std::vector<glm::vec3> unit = {{-1, t, 0}, {1, t, 0},  {-1, -t, 0}, {1, -t, 0},
                                 {0, -1, t}, {0, 1, t},  {0, -1, -t}, {0, 1, -t},
                                 {t, 0, -1}, {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  for (auto& v : unit) v = glm::normalize(v);
  std::vector<glm::uvec3> faces = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                   {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                   {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                   {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int level = 0; level < levels; ++level) {
    std::unordered_map<std::uint64_t, unsigned> midpoints;
    midpoints.reserve(faces.size() * 2);
    auto midpoint = [&](unsigned a, unsigned b) {
      const std::uint64_t key = (std::uint64_t(std::min(a, b)) << 32) | std::max(a, b);
      auto [it, inserted] = midpoints.emplace(key, unsigned(unit.size()));
      if (inserted) unit.push_back(glm::normalize(unit[a] + unit[b]));
      return it->second;
    };
    std::vector<glm::uvec3> finer;
    finer.reserve(faces.size() * 4);
    for (const auto& f : faces) {
      const unsigned ab = midpoint(f.x, f.y), bc = midpoint(f.y, f.z), ca = midpoint(f.z, f.x);
      finer.emplace_back(f.x, ab, ca);
      finer.emplace_back(f.y, bc, ab);
      finer.emplace_back(f.z, ca, bc);
      finer.emplace_back(ab, bc, ca);
    }
    faces.swap(finer);
  }
  TriangleMesh mesh;
  mesh.name = "test icosphere";
  mesh.positions.reserve(unit.size());
  for (const auto& v : unit) mesh.positions.push_back(center + radius * v);
  mesh.triangles = std::move(faces);
  return mesh;
}

/// Enclosed volume by the divergence theorem (positive for outward winding); computed
/// here rather than through mesh.cpp so these tests do not depend on it.
inline double enclosedVolume(const TriangleMesh& mesh) {
  double sixTimes = 0.0;
  for (const auto& t : mesh.triangles)
    sixTimes += glm::dot(glm::dvec3(mesh.positions[t.x]),
                         glm::cross(glm::dvec3(mesh.positions[t.y]), glm::dvec3(mesh.positions[t.z])));
  return sixTimes / 6.0;
}

/// Coverage of a sphere of `radius` about the origin against s³ point samples per cell:
/// the worst cell's error and the mean error over boundary cells (0 < expected < 1).
struct SupersampledSphereError {
  double worst = 0.0, meanBoundary = 0.0;
  int boundaryCells = 0;
};

inline SupersampledSphereError compareWithSupersampledSphere(const std::vector<float>& coverage,
                                                             const GridFrame& frame, double radius, int s = 12) {
  SupersampledSphereError result;
  double sumError = 0.0;
  for (int z = 0; z < frame.dims.z; ++z)
    for (int y = 0; y < frame.dims.y; ++y)
      for (int x = 0; x < frame.dims.x; ++x) {
        int inside = 0;
        for (int k = 0; k < s * s * s; ++k) {
          const glm::dvec3 sub((k % s + 0.5) / s, ((k / s) % s + 0.5) / s, (k / (s * s) + 0.5) / s);
          if (glm::length(frame.cellMin(x, y, z) + sub * frame.cellSize) < radius) ++inside;
        }
        const double expected = double(inside) / (s * s * s);
        const double error = std::abs(coverage[frame.index(x, y, z)] - expected);
        result.worst = std::max(result.worst, error);
        if (expected > 0.0 && expected < 1.0) {
          sumError += error;
          ++result.boundaryCells;
        }
      }
  if (result.boundaryCells > 0) result.meanBoundary = sumError / result.boundaryCells;
  return result;
}

}  // namespace sslpv::test
