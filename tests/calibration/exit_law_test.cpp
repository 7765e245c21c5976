// The calibrated exit law (volume/calibration/exit_law.h): the medium's exit angular shape h(μo; α', η)
// replaces the Lambertian-inside law T(μo)/η² of the shading while keeping its power.
// Expectations:
// - power: 2 ∫0^1 T(μo)/η² h(μo) μo dμo = diffuseBoundaryTransmittance(η) (the old law's
//   power) to 1e-4, for tabulated and untabulated shapes, on and off the table's nodes,
//   for η below, at and above 1 (the shading's exit gain is calibrated on that power);
// - η = 1: the exact exitant radiance of an isotropically scattering half-space under
//   normal incidence is ∝ H(μ; α')/(1 + μ) (Chandrasekhar, Radiative Transfer, 1950,
//   eq. for the diffuse reflection of a semi-infinite atmosphere, I(0, μ; μ0) =
//   (α'/4) F μ0 H(μ)H(μ0)/(μ + μ0) at μ0 = 1), for every α': the adding-doubling shape
//   follows it to 1e-3 and the table to 3e-3 (measured 9e-6 and 5e-4);
// - the table is the adding-doubling shape at off-node α' and μo within the bilinear
//   interpolation error (measured below);
// - the shape converges with the adding-doubling nodes;
// - it is what it is meant to correct: at low α' the exit is far from Lambertian (less
//   radiance near the normal), at α' = 1 and η = 1 nearly so.
#include "volume/calibration/exit_law.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "volume/calibration/adding_doubling.h"
#include "volume/core/fresnel.h"
#include "device_shared/lpv_constants.h"
#include "volume/reference/slab_reflectance.h"

namespace {
using namespace sslpv;

/// 2 ∫0^1 f(μ) μ dμ by the midpoint rule on 40,000 panels (independent of the table's
/// own quadrature; error ~1e-7 even across the η < 1 kink).
template <class F>
double outsidePower(const F& f) {
  constexpr int n = 40000;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const double mu = (i + 0.5) / n;
    sum += 2.0 * f(mu) * mu / n;
  }
  return sum;
}

TEST(ExitLaw, KeepsTheLambertianLawsPowerForEveryAlbedoAndIndex) {
  for (double eta : {0.8, 1.0, 1.3, 1.4, 1.5}) {
    const ExitLawTable& table = exitLawTable(eta);
    const double target = diffuseBoundaryTransmittance(eta);
    const double old = outsidePower([&](double mu) { return (1.0 - fresnelReflectance(mu, eta)) / (eta * eta); });
    ASSERT_NEAR(old / target, 1.0, 1e-5) << "the old law's power, eta " << eta;
    std::cout << "eta " << eta << ": table built in " << table.buildMs << " ms\n";
    for (double albedo : {0.0, 0.005, 0.02, 0.07, 0.37, 0.8, 0.93, 0.99, 0.9993, 1.0}) {
      const double tabulated = outsidePower([&](double mu) { return exitRadianceFactor(table, albedo, mu); });
      EXPECT_NEAR(tabulated / target, 1.0, 1e-4) << "table, eta " << eta << " albedo " << albedo;
      if (albedo == 0.37 || albedo == 0.9993) {
        const ExactExitShape shape(albedo, eta);
        const double exact =
            outsidePower([&](double mu) { return (1.0 - fresnelReflectance(mu, eta)) / (eta * eta) * shape(mu); });
        EXPECT_NEAR(exact / target, 1.0, 1e-4) << "untabulated, eta " << eta << " albedo " << albedo;
      }
    }
  }
}

TEST(ExitLaw, IndexMatchedShapeIsChandrasekharsHOverOnePlusMu) {
  // The reflected radiance at η = 1 under normal incidence is ∝ H(1) H(μ) / (1 + μ), its
  // once-scattered part ∝ 1 / (1 + μ) (H = 1); the lattice carries the rest, whose shape
  // this is: h ∝ (H(1) H(μ) − 1) / (1 + μ).
  const ExitLawTable& table = exitLawTable(1.0);
  double worstExact = 0.0, worstTable = 0.0;
  for (double albedo : {1.0, 0.999, 0.99, 0.9, 0.5, 0.1, 0.02}) {
    // h is normalised to 2 ∫ h μ dμ = 1 at η = 1. The integral follows from the same
    // solution's flux, Rd = (α'/2) H(1) ∫ H(μ) μ/(1 + μ) dμ with Rd = 1 - H(1) sqrt(1 - α'),
    // and ∫ μ/(1 + μ) dμ = 1 − ln 2: the norm is in closed form.
    const double h1 = chandrasekharH(1.0, albedo);
    const double rd = 1.0 - h1 * std::sqrt(1.0 - albedo);
    const double norm = 4.0 * rd / albedo - 2.0 * (1.0 - std::log(2.0));
    const ExactExitShape shape(albedo, 1.0);
    for (double mu = 0.02; mu <= 1.0; mu += 0.0613) {
      const double expected = (h1 * chandrasekharH(mu, albedo) - 1.0) / (1.0 + mu) / norm;
      const double exact = shape(mu);
      const double tabulated = exitLawShape(table, float(albedo), float(mu));
      worstExact = std::max(worstExact, std::abs(exact / expected - 1.0));
      worstTable = std::max(worstTable, std::abs(tabulated / expected - 1.0));
      EXPECT_NEAR(exact / expected, 1.0, 1e-3) << "albedo " << albedo << " mu " << mu;
      EXPECT_NEAR(tabulated / expected, 1.0, 3e-3) << "albedo " << albedo << " mu " << mu;
    }
  }
  std::cout << "eta 1 against H(mu)/(1 + mu): adding-doubling shape within " << worstExact << ", table within "
            << worstTable << "\n";
}

TEST(ExitLaw, TableMatchesAddingDoublingBetweenItsNodes) {
  constexpr int kA = SSLPV_EXIT_LAW_ALBEDO_INTERVALS, kM = SSLPV_EXIT_LAW_MU_INTERVALS;
  for (double eta : {1.3, 1.5, 0.8}) {
    const ExitLawTable& table = exitLawTable(eta);
    double worst = 0.0;
    // Midpoints in t = sqrt(1 - α') and in μo: where bilinear interpolation is worst.
    for (int k : {0, 3, 10, 20, 31}) {
      const double t = (k + 0.5) / kA, albedo = 1.0 - t * t;
      const ExactExitShape shape(albedo, eta);
      for (int j = 1; j < kM; j += 7) {
        const double mu = (j + 0.5) / kM;
        if (eta < 1.0 && mu < std::sqrt(1.0 - eta * eta)) continue;  // nothing leaves there
        const double exact = shape(mu);
        const double tabulated = exitLawShape(table, float(albedo), float(mu));
        worst = std::max(worst, std::abs(tabulated / exact - 1.0));
        EXPECT_NEAR(tabulated / exact, 1.0, 2e-3) << "eta " << eta << " albedo " << albedo << " mu " << mu;
      }
    }
    std::cout << "eta " << eta << ": table against adding-doubling between nodes within " << worst << "\n";
  }
}

TEST(ExitLaw, ShapeConvergesWithTheAddingDoublingNodes) {
  for (double eta : {1.0, 1.3}) {
    for (double albedo : {0.05, 0.9, 0.999}) {
      const ExactExitShape coarse(albedo, eta, 32), fine(albedo, eta, 48);
      for (double mu : {0.1, 0.5, 0.985}) {
        EXPECT_NEAR(coarse(mu) / fine(mu), 1.0, 2e-4) << "eta " << eta << " albedo " << albedo << " mu " << mu;
      }
    }
  }
}

TEST(ExitLaw, LowAlbedoMediaAreDarkerNearTheNormalThanLambertian) {
  // Without its once-scattered light (which the shading adds itself), a low-albedo
  // medium's light is twice scattered: still below Lambertian at the normal, but flatter
  // than single scattering's h ∝ 1/(1 + μ), whose h(1) = 1 / (4 (1 - ln 2)) = 0.8147.
  const ExitLawTable& matched = exitLawTable(1.0);
  EXPECT_GT(exitLawShape(matched, 0.0f, 1.0f), 1.0 / (4.0 * (1.0 - std::log(2.0))) + 0.05);
  EXPECT_LT(exitLawShape(matched, 0.0f, 1.0f), 0.95f);
  // Conservative scattering sends more light towards the normal than single scattering.
  EXPECT_GT(exitLawShape(matched, 1.0f, 1.0f), 1.0f);
  const ExitLawTable& jensen = exitLawTable(1.3);
  EXPECT_LT(exitLawShape(jensen, 0.07f, 0.985f), 0.95f);
  EXPECT_GT(exitLawShape(jensen, 0.07f, 0.985f), 0.7f);
}

TEST(ExitLaw, RejectsABadIndex) {
  EXPECT_THROW(buildExitLawTable(0.0), std::invalid_argument);
  EXPECT_THROW(exitLawTable(std::nan("")), std::invalid_argument);
}

}  // namespace
