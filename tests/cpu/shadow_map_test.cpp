// Shadow maps: the power they deliver to the surface against closed-form solid angles.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/trigonometric.hpp>

#include "test_meshes.h"
#include "volume/core/fresnel.h"
#include "volume/lpv/lpv_stages.h"
#include "volume/scene/ray_scene.h"
#include "volume/cpu/shadow_map.h"

namespace {
using namespace sslpv;
using namespace sslpv::test;

constexpr double kPi = 3.14159265358979323846;

glm::dvec3 totalFlux(const std::vector<SurfaceFluxSample>& samples) {
  glm::dvec3 sum(0.0);
  for (const auto& s : samples) sum += glm::dvec3(s.flux);
  return sum;
}

Light pointLight(glm::dvec3 position, float intensity) {
  Light l;
  l.type = Light::Type::Point;
  l.position = position;
  l.intensity = glm::vec3(intensity);
  return l;
}

TEST(ShadowMap, DirectionalLightDeliversIrradianceTimesProjectedArea) {
  // A 2x2 top face under irradiance E along -z receives 4E; the map's texel grid can
  // misplace at most half a texel along the face's perimeter.
  const TriangleMesh box = makeBoxMesh(glm::vec3(-1, -1, -0.5f), glm::vec3(1, 1, 0.5f));
  RayScene rays(box);
  Light sun;
  sun.type = Light::Type::Directional;
  sun.direction = glm::dvec3(0, 0, -1);
  sun.irradiance = glm::vec3(3.0f, 2.0f, 1.0f);
  const int size = 256;
  ShadowMapStats stats;
  const auto samples = castShadowMap(sun, rays, box.bounds(), size, 1.0, &stats);
  const double texel = 2.0 * 1.01 * 0.5 * glm::length(box.bounds().extent()) / size;
  const double perimeterSlack = 8.0 * texel * 0.5;
  EXPECT_NEAR(stats.incidentFlux.x, 3.0 * 4.0, 3.0 * perimeterSlack);
  EXPECT_NEAR(stats.incidentFlux.z / stats.incidentFlux.x, 1.0 / 3.0, 1e-6);
  // Index-matched: everything enters, straight on.
  EXPECT_NEAR(totalFlux(samples).x, stats.incidentFlux.x, 1e-6 * stats.incidentFlux.x);
  for (const auto& s : samples) {
    EXPECT_NEAR(s.direction.z, -1.0f, 1e-6f);
    EXPECT_NEAR(s.normal.z, 1.0f, 1e-6f);
  }
}

TEST(ShadowMap, FresnelTransmittanceAtNormalIncidence) {
  // At normal incidence into glass (η = 1.5), R = ((η-1)/(η+1))² = 0.04.
  const TriangleMesh box = makeBoxMesh(glm::vec3(-1, -1, -0.5f), glm::vec3(1, 1, 0.5f));
  RayScene rays(box);
  Light sun;
  sun.type = Light::Type::Directional;
  sun.direction = glm::dvec3(0, 0, -1);
  sun.irradiance = glm::vec3(1.0f);
  ShadowMapStats stats;
  castShadowMap(sun, rays, box.bounds(), 128, 1.5, &stats);
  EXPECT_NEAR(stats.transmittedFlux.x / stats.incidentFlux.x, 0.96, 1e-6);
}

TEST(ShadowMap, ObliqueIncidenceRefractsBySnellsLaw) {
  const TriangleMesh box = makeBoxMesh(glm::vec3(-1, -1, -0.5f), glm::vec3(1, 1, 0.5f));
  RayScene rays(box);
  Light sun;
  sun.type = Light::Type::Directional;
  sun.direction = glm::normalize(glm::dvec3(std::sin(0.6), 0, -std::cos(0.6)));
  sun.irradiance = glm::vec3(1.0f);
  const double eta = 1.4;
  const int size = 64;
  const auto samples = castShadowMap(sun, rays, box.bounds(), size, eta, nullptr);
  const double texel = 2.0 * 1.01 * 0.5 * glm::length(box.bounds().extent()) / size;
  const double transmittance = 1.0 - fresnelReflectance(std::cos(0.6), eta);
  int onTop = 0;
  for (const auto& s : samples) {
    if (s.normal.z < 0.99f) continue;
    ++onTop;
    const double sinT = std::sqrt(1.0 - double(s.direction.z) * s.direction.z);
    EXPECT_NEAR(sinT, std::sin(0.6) / eta, 1e-5);
    // Each texel carries E times its area across the beam, times T(θ).
    EXPECT_NEAR(s.flux.x, texel * texel * transmittance, 1e-5 * texel * texel);
  }
  EXPECT_GT(onTop, 100);
}

TEST(ShadowMap, PointLightDeliversIntensityTimesSubtendedSolidAngle) {
  // A sphere of radius r seen from distance d subtends 2π(1 - cos α), sin α = r/d.
  const TriangleMesh sphere = makeIcosphere(glm::vec3(0.0f), 1.0f, 6);
  RayScene rays(sphere);
  const double d = 4.0;
  ShadowMapStats stats;
  castShadowMap(pointLight({0, 0, d}, 2.0f), rays, sphere.bounds(), 512, 1.0, &stats);
  const double expected = 2.0 * 2.0 * kPi * (1.0 - std::cos(std::asin(1.0 / d)));
  EXPECT_NEAR(stats.incidentFlux.x, expected, 0.005 * expected);
}

TEST(ShadowMap, PointLightInsideTheBoundingSphereUsesACubeMap) {
  // 0.2 above the centre of a 2x2 face: Ω = 4 atan(a² / (h sqrt(2a² + h²))), a = 1.
  const TriangleMesh box = makeBoxMesh(glm::vec3(-1, -1, -0.5f), glm::vec3(1, 1, 0.5f));
  RayScene rays(box);
  const double h = 0.2;
  ShadowMapStats stats;
  castShadowMap(pointLight({0, 0, 0.5 + h}, 1.0f), rays, box.bounds(), 256, 1.0, &stats);
  const double expected = 4.0 * std::atan(1.0 / (h * std::sqrt(2.0 + h * h)));
  EXPECT_EQ(stats.texels, 6u * 256u * 256u);
  EXPECT_NEAR(stats.incidentFlux.x, expected, 0.005 * expected);
}

TEST(ShadowMap, SpotLightConeIsAHardEdgedSolidAngle) {
  // A narrow cone entirely on the sphere delivers I * 2π(1 - cos(fov/2)).
  const TriangleMesh sphere = makeIcosphere(glm::vec3(0.0f), 1.0f, 6);
  RayScene rays(sphere);
  Light spot = pointLight({0, 0, 5}, 1.0f);
  spot.type = Light::Type::Spot;
  spot.direction = glm::dvec3(0, 0, -1);
  spot.fovDeg = 10.0;
  ShadowMapStats stats;
  castShadowMap(spot, rays, sphere.bounds(), 512, 1.0, &stats);
  const double expected = 2.0 * kPi * (1.0 - std::cos(glm::radians(5.0)));
  EXPECT_NEAR(stats.incidentFlux.x, expected, 0.01 * expected);
}

TEST(ShadowMap, SpotLightPointingAwayIsCulled) {
  const TriangleMesh sphere = makeIcosphere(glm::vec3(0.0f), 1.0f, 3);
  RayScene rays(sphere);
  Light spot = pointLight({0, 0, 5}, 1.0f);
  spot.type = Light::Type::Spot;
  spot.direction = glm::dvec3(0, 0, 1);
  spot.fovDeg = 30.0;
  ShadowMapStats stats;
  EXPECT_TRUE(castShadowMap(spot, rays, sphere.bounds(), 64, 1.0, &stats).empty());
  EXPECT_TRUE(stats.culled);
  EXPECT_EQ(stats.texels, 0u) << "a culled light casts no rays";
}

}  // namespace
