// The benchmark's generated meshes (bench/bench_meshes.h): triangle counts near the
// benchmark's targets, closed (requireClosedMesh and the edge census), consistently and
// outward wound, inside the stated radius band, and deterministic.
#include "bench/bench_meshes.h"

#include <gtest/gtest.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <stdexcept>

namespace {
using namespace sslpv;

const glm::vec3 kCenter(3.0f, -1.0f, 2.0f);
constexpr float kRadius = 5.0f;

/// Directed edges used twice. With every undirected edge used exactly twice (the
/// closedness check), none repeated means each edge's two triangles traverse it in
/// opposite directions: neighbours agree on orientation (requireClosedMesh counts
/// undirected edges only, so it would accept a mesh with flipped triangles).
std::size_t repeatedDirectedEdges(const TriangleMesh& mesh) {
  std::vector<std::uint64_t> directed;
  directed.reserve(mesh.triangles.size() * 3);
  for (const glm::uvec3& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) directed.push_back((std::uint64_t(t[k]) << 32) | t[(k + 1) % 3]);
  tbb::parallel_sort(directed.begin(), directed.end());
  std::size_t repeated = 0;
  for (std::size_t i = 1; i < directed.size(); ++i) repeated += directed[i] == directed[i - 1];
  return repeated;
}

/// Triangles whose geometric normal points towards the centre. The blob is a radial
/// graph around it, so an outward-wound triangle always faces away from the centre.
std::size_t inwardTriangles(const TriangleMesh& mesh) {
  std::size_t inward = 0;
  for (const glm::uvec3& t : mesh.triangles) {
    const glm::dvec3 a(mesh.positions[t.x]), b(mesh.positions[t.y]), c(mesh.positions[t.z]);
    const glm::dvec3 n = glm::cross(b - a, c - a);
    if (!(glm::dot(n, (a + b + c) / 3.0 - glm::dvec3(kCenter)) > 0.0)) ++inward;
  }
  return inward;
}

void expectClosedOutwardBlob(const TriangleMesh& mesh) {
  EXPECT_NO_THROW(requireClosedMesh(mesh));
  const MeshTopology topology = analyzeTopology(mesh);
  EXPECT_EQ(topology.boundaryEdges, 0u);
  EXPECT_EQ(topology.nonManifoldEdges, 0u);
  EXPECT_EQ(topology.degenerateTriangles, 0u);
  EXPECT_EQ(repeatedDirectedEdges(mesh), 0u);
  EXPECT_EQ(inwardTriangles(mesh), 0u);
  EXPECT_GT(signedVolume(mesh), 0.0);
  float lo = 1e30f, hi = 0.0f;
  for (const glm::vec3& p : mesh.positions) {
    lo = std::min(lo, glm::length(p - kCenter));
    hi = std::max(hi, glm::length(p - kCenter));
  }
  EXPECT_GE(lo, 0.8f * kRadius);  // the documented radius band
  EXPECT_LE(hi, 1.2f * kRadius);
}

TEST(BenchMeshes, SmallSpheresAreClosedAndOutwardWound) {
  for (int facets : {1, 2, 3, 7}) {
    const TriangleMesh mesh = bench::makeLumpySphere(facets, kCenter, kRadius);
    EXPECT_EQ(mesh.triangles.size(), 12u * facets * facets);
    EXPECT_EQ(mesh.positions.size(), 6u * facets * facets + 2);
    expectClosedOutwardBlob(mesh);
  }
}

TEST(BenchMeshes, BenchmarkSizesHitTheirTargetsClosedAndOutwardWound) {
  for (std::size_t target : bench::kBenchTriangleTargets) {
    const TriangleMesh mesh = bench::makeBenchMesh(target, kCenter, kRadius);
    const int facets = bench::lumpySphereFacets(target);
    EXPECT_EQ(mesh.triangles.size(), 12u * std::size_t(facets) * facets);
    EXPECT_EQ(mesh.positions.size(), 6u * std::size_t(facets) * facets + 2);
    EXPECT_LE(std::abs(double(mesh.triangles.size()) - double(target)), 0.015 * double(target));
    expectClosedOutwardBlob(mesh);
  }
}

// The orientation checks above can fail: one flipped triangle trips both.
TEST(BenchMeshes, OrientationChecksCatchAFlippedTriangle) {
  TriangleMesh mesh = bench::makeLumpySphere(4, kCenter, kRadius);
  std::swap(mesh.triangles[5].y, mesh.triangles[5].z);
  EXPECT_NO_THROW(requireClosedMesh(mesh));  // still closed: only the winding is wrong
  EXPECT_EQ(repeatedDirectedEdges(mesh), 3u);
  EXPECT_EQ(inwardTriangles(mesh), 1u);
}

TEST(BenchMeshes, GenerationIsDeterministic) {
  const TriangleMesh a = bench::makeBenchMesh(32'000), b = bench::makeBenchMesh(32'000);
  ASSERT_EQ(a.positions.size(), b.positions.size());
  EXPECT_TRUE(std::equal(a.positions.begin(), a.positions.end(), b.positions.begin()));
  EXPECT_TRUE(a.triangles == b.triangles);
}

TEST(BenchMeshes, RejectsImpossibleFacetCounts) {
  EXPECT_THROW(bench::makeLumpySphere(0), std::invalid_argument);
  EXPECT_THROW(bench::makeLumpySphere(20001), std::invalid_argument);
  EXPECT_EQ(bench::lumpySphereFacets(0), 1);
  EXPECT_EQ(bench::lumpySphereFacets(12), 1);
  EXPECT_EQ(bench::lumpySphereFacets(7'200'000), 775);
}

}  // namespace
