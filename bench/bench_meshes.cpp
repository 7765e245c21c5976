#include "bench/bench_meshes.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <stdexcept>
#include <string>
#include <vector>

namespace sslpv::bench {
namespace {

/// Vertices of the cube sphere are the points of the (k+1)³ integer lattice on the cube's
/// surface, numbered layer by layer along z: the full bottom plane, a ring of 4k points
/// per inner layer, the full top plane. Shared edges and corners of the six faces thus get
/// one index without a hash map (a dense (k+1)³ table would be 1.9 GB at 7.2M triangles).
class SurfaceLattice {
 public:
  explicit SurfaceLattice(std::uint32_t k) : k_(k) {}

  std::uint32_t vertexCount() const { return 6 * k_ * k_ + 2; }

  std::uint32_t index(std::uint32_t i, std::uint32_t j, std::uint32_t l) const {
    const std::uint32_t plane = (k_ + 1) * (k_ + 1);
    if (l == 0) return j * (k_ + 1) + i;
    if (l == k_) return plane + (k_ - 1) * 4 * k_ + j * (k_ + 1) + i;
    return plane + (l - 1) * 4 * k_ + ringPosition(i, j);
  }

  /// The lattice point (i, j) of ring position p (inverse of ringPosition).
  glm::uvec2 ringPoint(std::uint32_t p) const {
    if (p < k_) return {p, 0};
    if (p < 2 * k_) return {k_, p - k_};
    if (p < 3 * k_) return {3 * k_ - p, k_};
    return {0, 4 * k_ - p};
  }

 private:
  /// Counter-clockwise walk around the square's boundary, starting at (0, 0).
  std::uint32_t ringPosition(std::uint32_t i, std::uint32_t j) const {
    if (j == 0 && i < k_) return i;
    if (i == k_ && j < k_) return k_ + j;
    if (j == k_ && i > 0) return 2 * k_ + (k_ - i);
    return 3 * k_ + (k_ - j);
  }

  std::uint32_t k_;
};

/// Radius factor of the blob in unit direction d: smooth bumps in [0.82, 1.18].
double lumpiness(const glm::dvec3& d) {
  return 1.0 + 0.08 * std::sin(3.1 * d.x + 0.7) * std::cos(2.3 * d.y - 0.4) + 0.06 * std::sin(4.7 * d.z + 1.9 * d.x) +
         0.04 * std::cos(6.1 * d.y + 2.2 * d.z + 0.3);
}

/// The blob's vertex at lattice point (i, j, l), from the lattice coordinates warped by
/// tangentWarp.
glm::vec3 blobPoint(const std::vector<double>& warped, std::uint32_t i, std::uint32_t j, std::uint32_t l,
                    const glm::vec3& center, float radius) {
  const glm::dvec3 d = glm::normalize(glm::dvec3(warped[i], warped[j], warped[l]));
  return center + glm::vec3(double(radius) * lumpiness(d) * d);
}

/// tan(π/4 · (2n/k − 1)) for n = 0..k. The tangent warp spreads the cube's lattice evenly
/// over the sphere (equal angles rather than equal cube lengths): triangle areas then
/// vary 2.2x over the blob, bumps included, against 7.7x for the plain projection.
std::vector<double> tangentWarp(std::uint32_t k) {
  std::vector<double> warped(k + 1);
  for (std::uint32_t n = 0; n <= k; ++n) warped[n] = std::tan(std::atan(1.0) * (2.0 * n / k - 1.0));
  return warped;
}

struct CubeFace {
  int axis, u, v;  ///< u x v points out of the cube, so (u, v) quads are CCW from outside
  bool high;       ///< the face at coordinate k (else 0)
};
constexpr CubeFace kFaces[6] = {{0, 1, 2, true},  {0, 2, 1, false}, {1, 2, 0, true},
                                {1, 0, 2, false}, {2, 0, 1, true},  {2, 1, 0, false}};

}  // namespace

TriangleMesh makeLumpySphere(int facets, const glm::vec3& center, float radius) {
  // 6k² + 2 vertices must fit 32-bit indices.
  if (facets < 1 || facets > 20000)
    throw std::invalid_argument("makeLumpySphere: facets must be in [1, 20000], got " + std::to_string(facets));
  const auto k = std::uint32_t(facets);
  const SurfaceLattice lattice(k);
  TriangleMesh mesh;
  mesh.name = "lumpy sphere " + std::to_string(12ull * k * k);
  mesh.positions.resize(lattice.vertexCount());
  const std::vector<double> warped = tangentWarp(k);
  tbb::parallel_for(std::uint32_t(0), k + 1, [&](std::uint32_t l) {
    if (l == 0 || l == k) {
      for (std::uint32_t j = 0; j <= k; ++j)
        for (std::uint32_t i = 0; i <= k; ++i)
          mesh.positions[lattice.index(i, j, l)] = blobPoint(warped, i, j, l, center, radius);
    } else {
      for (std::uint32_t p = 0; p < 4 * k; ++p) {
        const glm::uvec2 ij = lattice.ringPoint(p);
        mesh.positions[lattice.index(ij.x, ij.y, l)] = blobPoint(warped, ij.x, ij.y, l, center, radius);
      }
    }
  });

  mesh.triangles.resize(12 * std::size_t(k) * k);
  tbb::parallel_for(std::uint32_t(0), 6 * k, [&](std::uint32_t row) {
    const CubeFace& face = kFaces[row / k];
    const std::uint32_t b = row % k;
    std::size_t t = 2 * std::size_t(row) * k;
    for (std::uint32_t a = 0; a < k; ++a) {
      const auto corner = [&](std::uint32_t du, std::uint32_t dv) {
        std::uint32_t p[3];
        p[face.axis] = face.high ? k : 0;
        p[face.u] = a + du;
        p[face.v] = b + dv;
        return lattice.index(p[0], p[1], p[2]);
      };
      const std::uint32_t p00 = corner(0, 0), p10 = corner(1, 0), p11 = corner(1, 1), p01 = corner(0, 1);
      mesh.triangles[t++] = glm::uvec3(p00, p10, p11);
      mesh.triangles[t++] = glm::uvec3(p00, p11, p01);
    }
  });
  return mesh;
}

int lumpySphereFacets(std::size_t targetTriangles) {
  const int guess = std::max(1, int(std::lround(std::sqrt(double(targetTriangles) / 12.0))));
  int best = guess;
  for (int f = std::max(1, guess - 1); f <= guess + 1; ++f)
    if (std::llabs(12ll * f * f - (long long)targetTriangles) <
        std::llabs(12ll * best * best - (long long)targetTriangles))
      best = f;
  return best;
}

TriangleMesh makeBenchMesh(std::size_t targetTriangles, const glm::vec3& center, float radius) {
  return makeLumpySphere(lumpySphereFacets(targetTriangles), center, radius);
}

}  // namespace sslpv::bench
