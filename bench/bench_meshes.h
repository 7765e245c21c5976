#pragma once
// Deterministic closed test meshes for frame_bench, at the triangle counts the
// benchmark sweeps (about 32K, 110K, 323K and 7.2M), generated rather than shipped.
#include <array>
#include <cstddef>
#include <glm/vec3.hpp>

#include "volume/scene/mesh.h"

namespace sslpv::bench {

/// A lumpy blob: a cube sphere with `facets` x `facets` quads per cube face (12·facets²
/// triangles, 6·facets² + 2 shared vertices), each vertex pushed radially by a smooth,
/// fixed sum of bumps between 0.8 and 1.2 times `radius`. Radial displacement of a
/// sphere keeps it closed, free of self-intersections and wound counter-clockwise seen
/// from outside. Same arguments, same mesh, bit for bit. facets >= 1.
TriangleMesh makeLumpySphere(int facets, const glm::vec3& center = glm::vec3(0.0f), float radius = 1.0f);

/// The facets of makeLumpySphere whose triangle count is nearest `targetTriangles`.
int lumpySphereFacets(std::size_t targetTriangles);

/// The benchmark's mesh sizes (target triangle counts).
inline constexpr std::array<std::size_t, 4> kBenchTriangleTargets = {32'000, 110'000, 323'000, 7'200'000};

/// makeLumpySphere with the triangle count nearest `targetTriangles` (within 1.5 % for the
/// benchmark's targets: 32 448, 110 592, 322 752 and 7 207 500 triangles).
TriangleMesh makeBenchMesh(std::size_t targetTriangles, const glm::vec3& center = glm::vec3(0.0f), float radius = 1.0f);

}  // namespace sslpv::bench
