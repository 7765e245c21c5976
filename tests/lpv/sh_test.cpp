// L1 SH conventions and the LPV geometric constants, checked by numerical integration.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>

#include "volume/lpv/sh.h"

namespace {
using namespace sslpv;

constexpr double kPi = 3.14159265358979323846;

/// Integrates f over the unit sphere with a fine latitude-longitude midpoint rule.
template <class F>
double sphereIntegral(F f, int n = 800) {
  double total = 0.0;
  for (int i = 0; i < n; ++i) {
    const double theta = (i + 0.5) * kPi / n;
    for (int j = 0; j < 2 * n; ++j) {
      const double phi = (j + 0.5) * kPi / n;
      const glm::vec3 w(float(std::sin(theta) * std::cos(phi)), float(std::sin(theta) * std::sin(phi)),
                        float(std::cos(theta)));
      total += f(w) * std::sin(theta) * (kPi / n) * (kPi / n);
    }
  }
  return total;
}

TEST(ShBasis, BasisFunctionsAreOrthonormal) {
  const sh::Coeffs y00(1, 0, 0, 0), y1x(0, 1, 0, 0), y1z(0, 0, 0, 1);
  EXPECT_NEAR(sphereIntegral([&](glm::vec3 w) { return std::pow(sh::evaluate(y00, w), 2); }), 1.0, 1e-4);
  EXPECT_NEAR(sphereIntegral([&](glm::vec3 w) { return std::pow(sh::evaluate(y1x, w), 2); }), 1.0, 1e-4);
  EXPECT_NEAR(sphereIntegral([&](glm::vec3 w) { return sh::evaluate(y1x, w) * sh::evaluate(y1z, w); }), 0.0,
              1e-5);
}

TEST(ShBasis, ClampedCosineLobeProjectsToTheStatedCoefficients) {
  const glm::vec3 n = glm::normalize(glm::vec3(0.3f, -0.5f, 0.8f));
  auto lobe = [&](glm::vec3 w) { return std::max(0.0f, glm::dot(n, w)); };
  const sh::Coeffs expected = sh::cosineLobe(n, 1.0f);
  EXPECT_NEAR(sphereIntegral([&](glm::vec3 w) { return lobe(w) * sh::kY00; }), expected.x, 1e-4);
  EXPECT_NEAR(sphereIntegral([&](glm::vec3 w) { return lobe(w) * sh::kY1 * w.x; }), expected.y, 1e-4);
  EXPECT_NEAR(sphereIntegral([&](glm::vec3 w) { return lobe(w) * sh::kY1 * w.y; }), expected.z, 1e-4);
  EXPECT_NEAR(sphereIntegral([&](glm::vec3 w) { return lobe(w) * sh::kY1 * w.z; }), expected.w, 1e-4);
}

TEST(ShBasis, FluxOfACellIsTheSphereIntegralOfItsIntensity) {
  const sh::Coeffs c(2.0f, 0.7f, -0.4f, 0.2f);
  EXPECT_NEAR(sphereIntegral([&](glm::vec3 w) { return sh::evaluate(c, w); }), sh::flux(c), 1e-3);
  // A cosine lobe of power Φ (intensity (Φ/π) max(0, cos)) holds exactly Φ.
  EXPECT_NEAR(sh::flux(sh::cosineLobe(glm::vec3(0, 0, 1), 5.0f / sh::kPi)), 5.0f, 1e-5);
}

TEST(ShBasis, HemisphereIntegralsMatchQuadrature) {
  const glm::vec3 n = glm::normalize(glm::vec3(-0.2f, 0.9f, 0.4f));
  const sh::Coeffs c(1.0f, 0.3f, 0.6f, -0.5f);
  const double numeric =
      sphereIntegral([&](glm::vec3 w) { return glm::dot(w, n) > 0.0f ? sh::evaluate(c, w) : 0.0f; }, 1200);
  EXPECT_NEAR(numeric, sh::hemisphereIntegral(c, n), 2e-3);
  // The documented values: ∫_H Y00 = sqrt(pi), ∫_H Y1m = (sqrt(3 pi)/2) n_m.
  EXPECT_NEAR(SSLPV_HEMI_Y00, std::sqrt(kPi), 1e-12);
  EXPECT_NEAR(SSLPV_HEMI_Y1, std::sqrt(3.0 * kPi) / 2.0, 1e-12);
}

/// Solid angle of the rectangle [u0,u1]x[v0,v1] on the plane at distance d, by quadrature.
double rectangleSolidAngle(double d, double u0, double u1, double v0, double v1, int n = 1000) {
  double total = 0.0;
  const double du = (u1 - u0) / n, dv = (v1 - v0) / n;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double u = u0 + (i + 0.5) * du, v = v0 + (j + 0.5) * dv;
      const double r2 = u * u + v * v + d * d;
      total += d / (r2 * std::sqrt(r2)) * du * dv;
    }
  return total;
}

TEST(LpvGeometry, FaceSolidAnglesMatchTheCellGeometry) {
  // Source centre at the origin, destination centred at (0,0,1): its far face lies on
  // z = 1.5, and one side face on x = 0.5 spanning z in [0.5, 1.5].
  EXPECT_NEAR(rectangleSolidAngle(1.5, -0.5, 0.5, -0.5, 0.5), SSLPV_FRONT_FACE_SOLID_ANGLE, 1e-6);
  EXPECT_NEAR(rectangleSolidAngle(0.5, 0.5, 1.5, -0.5, 0.5), SSLPV_SIDE_FACE_SOLID_ANGLE, 1e-6);
  EXPECT_NEAR(4.0 * SSLPV_SIDE_FACE_SOLID_ANGLE + SSLPV_FRONT_FACE_SOLID_ANGLE, 2.0 * kPi / 3.0, 1e-12);
}

}  // namespace
