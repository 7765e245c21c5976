#include "volume/scene/ray_scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <set>
#include <utility>
#include <stdexcept>
#include <string>
#include <vector>

#include "seeded_draws.h"
#include "test_meshes.h"
#include "device_shared/ray_triangle_test.h"

namespace sslpv {
namespace {

using test::drawVec3;
using test::makeBoxMesh;
using test::makeIcosphere;

void expectVecNear(const glm::vec3& actual, const glm::vec3& expected, float tol) {
  EXPECT_NEAR(actual.x, expected.x, tol);
  EXPECT_NEAR(actual.y, expected.y, tol);
  EXPECT_NEAR(actual.z, expected.z, tol);
}

TEST(RayScene, BoxHitFromEachAxisHasDistancePositionAndOutwardNormal) {
  // Box [1,3] x [-1,2] x [0,4]; rays aimed at each face centre from 5 units outside,
  // with a direction of length 2 so t is checked in units of |dir|.
  const glm::vec3 lo(1.0f, -1.0f, 0.0f), hi(3.0f, 2.0f, 4.0f);
  const RayScene scene(makeBoxMesh(lo, hi));
  const glm::vec3 centre = 0.5f * (lo + hi);
  for (int axis = 0; axis < 3; ++axis)
    for (float side : {-1.0f, 1.0f}) {
      glm::vec3 outward(0.0f);
      outward[axis] = side;
      glm::vec3 facePoint = centre;
      facePoint[axis] = side < 0 ? lo[axis] : hi[axis];
      // Off the face centre, so the ray does not run along a triangle's diagonal.
      facePoint[(axis + 1) % 3] += 0.3f;
      const glm::vec3 origin = facePoint + 5.0f * outward;
      const RayHit hit = scene.intersect(origin, -2.0f * outward);
      ASSERT_TRUE(hit.hit) << "axis " << axis << " side " << side;
      EXPECT_NEAR(hit.t, 2.5f, 1e-5f);
      expectVecNear(hit.position, facePoint, 1e-5f);
      expectVecNear(hit.normal, outward, 1e-6f);
      EXPECT_LT(hit.triangle, 12u);
    }
}

TEST(RayScene, RayFromInsideHitsTheFarFaceWithOutwardNormal) {
  const RayScene scene(makeBoxMesh(glm::vec3(0.0f), glm::vec3(1.0f)));
  const RayHit hit = scene.intersect(glm::vec3(0.5f, 0.4f, 0.3f), glm::vec3(0.0f, 1.0f, 0.0f));
  ASSERT_TRUE(hit.hit);
  EXPECT_NEAR(hit.t, 0.6f, 1e-6f);
  expectVecNear(hit.normal, glm::vec3(0.0f, 1.0f, 0.0f), 1e-6f);  // out of the mesh, along the ray
}

TEST(RayScene, MissesReportNoHit) {
  const RayScene scene(makeBoxMesh(glm::vec3(0.0f), glm::vec3(1.0f)));
  EXPECT_FALSE(scene.intersect(glm::vec3(0.5f, 0.5f, 3.0f), glm::vec3(0.0f, 0.0f, 1.0f)).hit);  // away
  EXPECT_FALSE(scene.intersect(glm::vec3(2.0f, 0.5f, 3.0f), glm::vec3(0.0f, 0.0f, -1.0f)).hit);  // beside
}

TEST(RayScene, TNearAndTFarBoundTheAcceptedHits) {
  // Along +z through the box [0,1]^3 from z = -2: entry at t = 2, exit at t = 3.
  const RayScene scene(makeBoxMesh(glm::vec3(0.0f), glm::vec3(1.0f)));
  const glm::vec3 origin(0.4f, 0.6f, -2.0f), dir(0.0f, 0.0f, 1.0f);
  EXPECT_NEAR(scene.intersect(origin, dir).t, 2.0f, 1e-6f);
  const RayHit exit = scene.intersect(origin, dir, 2.5f);
  ASSERT_TRUE(exit.hit);
  EXPECT_NEAR(exit.t, 3.0f, 1e-6f);
  EXPECT_FALSE(scene.intersect(origin, dir, 0.0f, 1.9f).hit);
  EXPECT_FALSE(scene.intersect(origin, dir, 3.1f).hit);
}

TEST(RayScene, EmptyMeshMissesEverything) {
  const RayScene scene(TriangleMesh{});
  EXPECT_FALSE(scene.intersect(glm::vec3(0.0f), glm::vec3(1.0f, 0.0f, 0.0f)).hit);
}

TEST(RayScene, OutOfRangeVertexIndexIsRejectedNotTraced) {
  TriangleMesh broken = makeBoxMesh(glm::vec3(0.0f), glm::vec3(1.0f));
  broken.triangles[3].y = 8;  // the box has vertices 0..7
  EXPECT_THROW(RayScene{broken}, std::invalid_argument);
}

TEST(RayScene, IntersectManyEqualsIntersectForRandomAndCoherentRays) {
  const RayScene scene(makeIcosphere(glm::vec3(0.1f, 0.2f, -0.3f), 1.0f, 4));
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> uniform(-2.0f, 2.0f);
  std::vector<glm::vec3> origins, dirs;
  // Random rays (the scattered path) ...
  for (int i = 0; i < 3000; ++i) {
    origins.push_back(drawVec3<glm::vec3>([&] { return uniform(rng); }));
    dirs.push_back(drawVec3<glm::vec3>([&] { return uniform(rng); }) + glm::vec3(0.0f, 0.0f, 1e-3f));
  }
  // ... and a camera's scanlines (the packet path), with a count that is not a multiple
  // of 16 so a partial packet is exercised.
  for (int y = 0; y < 37; ++y)
    for (int x = 0; x < 41; ++x) {
      origins.emplace_back(0.0f, 0.0f, 4.0f);
      dirs.push_back(glm::normalize(glm::vec3(x / 20.0f - 1.0f, y / 18.0f - 1.0f, -3.0f)));
    }
  std::vector<RayHit> many(origins.size());
  scene.intersectMany(origins.data(), dirs.data(), many.data(), origins.size());
  int hits = 0;
  for (std::size_t i = 0; i < origins.size(); ++i) {
    const RayHit one = scene.intersect(origins[i], dirs[i]);
    ASSERT_EQ(many[i].hit, one.hit) << "ray " << i;
    if (!one.hit) continue;
    ++hits;
    // Packet and single-ray kernels may round differently in the last bit.
    EXPECT_NEAR(many[i].t, one.t, 1e-5f * (1.0f + one.t)) << "ray " << i;
    EXPECT_EQ(many[i].triangle, one.triangle) << "ray " << i;
    expectVecNear(many[i].normal, one.normal, 1e-5f);
    expectVecNear(many[i].position, one.position, 1e-4f);
  }
  EXPECT_GT(hits, 1000);  // both paths were actually exercised with hits
}

TEST(RayScene, SphereHitDistanceMatchesAnalyticWithinTessellationError) {
  const glm::vec3 centre(0.5f, -1.0f, 2.0f);
  const float radius = 2.0f;
  const TriangleMesh sphere = makeIcosphere(centre, radius, 5);
  // The tessellation error: how far the flat faces dip inside the sphere (their planes'
  // closest approach to the centre), ~2e-4 r at 5 subdivisions.
  float tessellation = 0.0f;
  for (const auto& t : sphere.triangles) {
    const glm::vec3 a = sphere.positions[t.x] - centre, b = sphere.positions[t.y] - centre,
                    c = sphere.positions[t.z] - centre;
    const float planeDistance = std::abs(glm::dot(a, glm::normalize(glm::cross(b - a, c - a))));
    tessellation = std::max(tessellation, radius - planeDistance);
  }
  ASSERT_LT(tessellation, 1e-3f * radius);
  const RayScene scene(sphere);
  std::mt19937 rng(5);
  std::normal_distribution<float> gauss;
  for (int i = 0; i < 500; ++i) {
    const glm::vec3 towards = glm::normalize(drawVec3<glm::vec3>([&] { return gauss(rng); }));
    const glm::vec3 sideways = glm::normalize(glm::cross(towards, drawVec3<glm::vec3>([&] { return gauss(rng); })));
    const float offset = 0.8f * radius * std::abs(gauss(rng)) / 3.0f;  // impact parameter < r mostly
    if (offset > 0.9f * radius) continue;
    const glm::vec3 origin = centre + 5.0f * towards + offset * sideways;
    const glm::vec3 dir = -towards;
    const RayHit hit = scene.intersect(origin, dir);
    ASSERT_TRUE(hit.hit);
    // Analytic entry distance: 5 - sqrt(r^2 - b^2).
    const float expected = 5.0f - std::sqrt(radius * radius - offset * offset);
    // Grazing rays turn a radial gap into a longer distance along the ray.
    const float cosIncidence = std::sqrt(1.0f - (offset / radius) * (offset / radius));
    EXPECT_NEAR(hit.t, expected, tessellation / cosIncidence + 1e-5f) << "ray " << i;
    EXPECT_GT(glm::dot(hit.normal, glm::normalize(hit.position - centre)), 0.999f);
  }
}


TEST(RayScene, RaysThroughSharedEdgesHitOneWatertightCrossedTriangleAndVertexRaysRarelyPass) {
  // Rays from outside aimed exactly (up to the rounding of the aim point) at shared edges
  // and vertices of a closed welded sphere, head-on to grazing. The watertight test sees
  // an edge from its two triangles with exactly opposite signs, so one of them is always
  // crossed; RayScene must report a crossed triangle there (the one the GPU's
  // pickCrossedTriangle would choose), and never a miss.
  //
  // Exactly through a vertex Embree's robust mode is not exact: its edge functions are
  // rounded in float, so around a vertex every fan edge's sign is rounding noise and a ray
  // can fall between the fan's triangles to the far side (measured: 1 of 1440 vertex rays
  // with one draw of tangents, none with another; Embree's fast mode let a third of the
  // tilted vertex rays through). Such a ray is aimed at a vertex to the last bit, which a
  // pixel or path ray practically never is, so vertex rays are held to a rate.
  const glm::vec3 centre(0.25f, -0.5f, 0.125f);
  const TriangleMesh sphere = makeIcosphere(centre, 1.5f, 2);
  const RayScene scene(sphere);
  std::set<std::pair<unsigned, unsigned>> edges;
  for (const auto& t : sphere.triangles)
    for (int c = 0; c < 3; ++c) edges.emplace(std::min(t[c], t[(c + 1) % 3]), std::max(t[c], t[(c + 1) % 3]));
  int rays = 0, antisymmetric = 0, vertexRays = 0, vertexRaysPassed = 0;
  for (const unsigned seed : {17u, 18u, 19u, 20u}) {
    std::mt19937 rng(seed);
    std::normal_distribution<float> gauss;
    for (const auto& [a, b] : edges)
      for (const float s : {0.0f, 0.5f, 1.0f / 3.0f, 0.1f}) {  // s = 0: through vertex a
        const glm::vec3 pa = sphere.positions[a], pb = sphere.positions[b];
        const glm::vec3 aim = pa + s * (pb - pa);
        const glm::vec3 outward = glm::normalize(aim - centre);
        const glm::vec3 tangent = glm::normalize(glm::cross(outward, drawVec3<glm::vec3>([&] { return gauss(rng); })));
        for (const float tilt : {0.0f, 0.7f, 3.0f}) {  // up to 72 degrees from the normal
          const glm::vec3 origin = aim + 4.0f * glm::normalize(outward + tilt * tangent);
          const glm::vec3 dir = aim - origin;
          ++rays;
          antisymmetric += raytri::rayEdgeSide(origin, dir, a, pa, b, pb) ==
                           -raytri::rayEdgeSide(origin, dir, b, pb, a, pa);
          const RayHit hit = scene.intersect(origin, dir);
          ASSERT_TRUE(hit.hit) << "edge " << a << "-" << b << " s " << s << " tilt " << tilt << " seed " << seed;
          const std::string where = "edge " + std::to_string(a) + "-" + std::to_string(b) + " s " + std::to_string(s) +
                                    " tilt " + std::to_string(tilt) + " seed " + std::to_string(seed);
          if (s == 0.0f) {
            ++vertexRays;
            if (hit.t > 1.0f + 1e-4f) {  // fell through the vertex to the far side
              ++vertexRaysPassed;
              continue;
            }
          }
          const glm::uvec3 t = sphere.triangles[hit.triangle];
          // Exactly through a vertex no fan triangle need be crossed by the shared test
          // either (the GPU then reports a miss; RayScene keeps Embree's hit).
          if (s > 0.0f) {
            EXPECT_TRUE(raytri::rayCrossesTriangle(origin, dir, t.x, sphere.positions[t.x], t.y,
                                                 sphere.positions[t.y], t.z, sphere.positions[t.z]))
              << where << " hit triangle " << hit.triangle;
          }
          // Next to the aim point: a triangle around vertex a or b, entered near t = 1.
          EXPECT_TRUE(t.x == a || t.y == a || t.z == a || t.x == b || t.y == b || t.z == b) << where;
          EXPECT_NEAR(hit.t, 1.0f, 1e-4f) << where;
          expectVecNear(hit.position, aim, 1e-4f);
          // The normal is the reported triangle's own face normal, not Embree's neighbour's.
          const glm::vec3 ng = glm::normalize(glm::cross(sphere.positions[t.y] - sphere.positions[t.x],
                                                         sphere.positions[t.z] - sphere.positions[t.x]));
          expectVecNear(hit.normal, ng, 1e-6f);
        }
      }
  }
  EXPECT_EQ(antisymmetric, rays);  // the two triangles of an edge see exactly opposite sides
  EXPECT_EQ(rays, 4 * int(edges.size()) * 12);
  std::printf("vertex rays through to the far side: %d of %d\n", vertexRaysPassed, vertexRays);
  EXPECT_LE(vertexRaysPassed * 200, vertexRays) << "more than 1 in 200 vertex rays fell through";
}

}  // namespace
}  // namespace sslpv
