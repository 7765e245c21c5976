// Exact light connections through a flat dielectric face (volume/reference/refracted_connection.h):
// Snell's law at the refracting point, the straight line at η = 1, and the geometry
// factor against a forward simulation of the light's rays.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>
#include <iostream>
#include <random>

#include "seeded_draws.h"
#include "test_meshes.h"
#include "volume/core/fresnel.h"
#include "volume/reference/refracted_connection.h"

namespace sslpv::test {
namespace {

const BoundaryPlane kTop{glm::dvec3(0.0, 0.0, 1.0), 0.0};  // the medium is z < 0

TEST(RefractedConnection, IndexMatchedIsTheStraightLine) {
  const glm::dvec3 x(0.3, -0.2, -1.5), light(2.0, 1.0, 4.0);
  const auto c = connectPointLight(x, light, kTop, 1.0);
  ASSERT_TRUE(c);
  const double r = glm::length(light - x);
  EXPECT_NEAR(c->geometry, 1.0 / (r * r), 1e-12);
  EXPECT_NEAR(glm::dot(c->toLightInside, (light - x) / r), 1.0, 1e-12);
  EXPECT_NEAR(c->insideDistance + c->outsideDistance, r, 1e-9);
  EXPECT_NEAR(c->surfacePoint.z, 0.0, 1e-12);
  const auto d = connectDirectionalLight(x, glm::normalize(glm::dvec3(0.3, 0.1, -1.0)), kTop, 1.0);
  ASSERT_TRUE(d);
  EXPECT_NEAR(d->geometry, 1.0, 1e-12);
}

TEST(RefractedConnection, RefractingPointObeysSnell) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  for (double eta : {0.8, 1.3, 1.5}) {
    for (int k = 0; k < 50; ++k) {
      glm::dvec3 x = drawVec3<glm::dvec3>(u, rng);
      x.z = -0.05 - std::abs(x.z);
      glm::dvec3 light = drawVec3<glm::dvec3>(u, rng);
      light.z = 0.05 + std::abs(light.z);
      const auto c = connectPointLight(x, light, kTop, eta);
      if (!c) {
        ADD_FAILURE() << "no connection for a light above and a point below";
        continue;
      }
      EXPECT_NEAR(c->surfacePoint.z, 0.0, 1e-12);
      const double sinOutside = std::sqrt(std::max(0.0, 1.0 - c->cosOutside * c->cosOutside));
      const double sinInside = glm::length(glm::cross(c->toLightInside, kTop.normal));
      EXPECT_NEAR(sinOutside, eta * sinInside, 1e-9) << "eta " << eta;
      // Both segments and the normal lie in one plane.
      EXPECT_NEAR(glm::dot(glm::cross(c->toLightInside, c->toLightOutside), kTop.normal), 0.0, 1e-9);
    }
    const glm::dvec3 direction = glm::normalize(glm::dvec3(0.5, -0.2, -0.8));
    const auto d = connectDirectionalLight(glm::dvec3(0.4, 0.1, -2.0), direction, kTop, eta);
    ASSERT_TRUE(d);
    EXPECT_NEAR(d->surfacePoint.z, 0.0, 1e-12);
    EXPECT_NEAR(glm::dot(-d->toLightInside, refractInto(direction, kTop.normal, eta)), 1.0, 1e-12);
    EXPECT_NEAR(d->geometry, 0.8 / glm::length(glm::dvec3(0.5, -0.2, -0.8)) / -refractInto(direction, kTop.normal, eta).z,
                1e-12);
  }
  EXPECT_FALSE(connectPointLight(glm::dvec3(0, 0, 1), glm::dvec3(0, 0, 2), kTop, 1.3)) << "x outside";
  EXPECT_FALSE(connectPointLight(glm::dvec3(0, 0, -1), glm::dvec3(0, 0, -2), kTop, 1.3)) << "light inside";
  EXPECT_FALSE(connectDirectionalLight(glm::dvec3(0, 0, -1), glm::dvec3(0, 0, 1), kTop, 1.3)) << "lit from inside";
}

// The light's rays simulated forwards: directions from the light uniformly within a
// small cone around the connection, refracted at the plane; the fraction that passes
// within r of x, times the cone's solid angle over π r², estimates the irradiance across
// the ray per unit intensity. 2·10^6 rays give a standard error of about 0.5 %; the disc
// is small enough that the tube's curvature over it is below that.
TEST(RefractedConnection, GeometryMatchesAForwardSimulationOfTheRays) {
  struct Case {
    glm::dvec3 x, light;
    double eta;
  };
  for (const Case& k : {Case{{2.0, 1.0, -1.5}, {0.0, 0.0, 3.0}, 1.4}, Case{{0.1, 0.0, -0.5}, {0.0, 0.0, 4.0}, 1.3},
                        Case{{4.0, -2.0, -0.3}, {-1.0, 0.5, 1.0}, 1.5}, Case{{1.0, 1.0, -2.0}, {0.0, 0.0, 2.0}, 0.8}}) {
    const auto c = connectPointLight(k.x, k.light, kTop, k.eta);
    ASSERT_TRUE(c);
    const glm::dvec3 axis = -c->toLightOutside;  // from the light towards y
    const double radius = 2e-3 * c->insideDistance;
    // Half-angle: the disc seen from the light, widened by the largest tube compression.
    const double halfAngle = 4.0 * radius / (c->insideDistance + c->outsideDistance);
    const double cosHalf = std::cos(halfAngle);
    const double solidAngle = 2.0 * 3.141592653589793 * (1.0 - cosHalf);
    const glm::dvec3 e1 = glm::normalize(glm::cross(axis, std::abs(axis.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
    const glm::dvec3 e2 = glm::cross(axis, e1);
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    const int rays = 2000000;
    int hits = 0;
    for (int i = 0; i < rays; ++i) {
      const double cosTheta = 1.0 - uniform(rng) * (1.0 - cosHalf);
      const double sinTheta = std::sqrt(1.0 - cosTheta * cosTheta), phi = 6.283185307179586 * uniform(rng);
      const glm::dvec3 dir = cosTheta * axis + sinTheta * (std::cos(phi) * e1 + std::sin(phi) * e2);
      const double t = (kTop.offset - glm::dot(kTop.normal, k.light)) / glm::dot(kTop.normal, dir);
      const glm::dvec3 y = k.light + t * dir;
      const glm::dvec3 inside = refractInto(dir, kTop.normal, k.eta);
      const glm::dvec3 toX = k.x - y;
      const double along = glm::dot(toX, inside);
      if (glm::length(toX - along * inside) < radius) ++hits;
    }
    const double fraction = double(hits) / rays;
    const double simulated = fraction * solidAngle / (3.141592653589793 * radius * radius);
    const double standardError = simulated / std::sqrt(double(hits));
    std::cout << "[ measured ] eta " << k.eta << ": geometry " << c->geometry << ", forward simulation "
              << simulated << " +- " << standardError << " (" << hits << " rays through the disc)\n";
    ASSERT_GT(hits, 20000) << "the cone must cover the disc";
    EXPECT_NEAR(c->geometry, simulated, 4.0 * standardError);
  }
}

TEST(RefractedConnection, MeshPlanesOfABoxAndOfASphere) {
  std::vector<int> planeOf;
  const auto box = meshPlanes(makeBoxMesh(glm::vec3(-1, -2, -3), glm::vec3(1, 2, 3)), 64, &planeOf);
  ASSERT_TRUE(box);
  EXPECT_EQ(box->size(), 6u);
  for (int p : planeOf) EXPECT_GE(p, 0);
  for (const BoundaryPlane& plane : *box) EXPECT_NEAR(glm::length(plane.normal), 1.0, 1e-12);
  EXPECT_FALSE(meshPlanes(makeIcosphere(glm::vec3(0.0f), 1.0f, 3), 64)) << "a curved surface has too many";
}

}  // namespace
}  // namespace sslpv::test
