// Thick-slab diffuse reflectance from the reference tracer (volume/reference/slab_reflectance.h)
// against exact transport and the dipole (docs/design.md §7). Statistical checks allow 4 standard
// errors of the Monte Carlo mean (about one false failure in 16,000 seeds; seeds are
// fixed) and require the standard error to be small against the value, so that noise
// cannot make a check pass.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <stdexcept>

#include "half_space_walk.h"
#include "volume/core/fresnel.h"
#include "volume/reference/reference_tracer.h"
#include "volume/reference/slab_reflectance.h"

namespace sslpv::test {
namespace {

/// σt = 1, σs = α per channel, g = 0: the albedos the checks use.
MaterialSample albedoMaterial(const glm::dvec3& albedo) {
  MaterialSample m;
  m.sigmaT = glm::vec3(1.0f);
  m.sigmaS = glm::vec3(albedo);
  m.g = 0.0f;
  return m;
}

// H for isotropic scattering against what is known about it independently of the
// iteration: Chandrasekhar's table value H(1) = 2.9078 in the conservative case, the
// zeroth moment ∫0^1 H dμ = (2/ω)(1 - sqrt(1 - ω)), and the other form of the integral
// equation, H(μ) = 1 / (1 - (ω/2) μ ∫0^1 H(μ')/(μ + μ') dμ').
TEST(SlabReflectance, ChandrasekharHMatchesTableMomentAndIntegralEquation) {
  EXPECT_NEAR(chandrasekharH(1.0, 1.0), 2.9078, 1e-4);
  EXPECT_DOUBLE_EQ(chandrasekharH(0.7, 0.0), 1.0);
  constexpr int kPoints = 400;  // midpoint rule: H has a μ log μ term at 0, error ~1e-6
  for (double albedo : {0.5, 0.9, 0.99, 1.0}) {
    SCOPED_TRACE(albedo);
    double moment = 0.0, integral = 0.0;
    for (int i = 0; i < kPoints; ++i) {
      const double mu = (i + 0.5) / kPoints;
      const double h = chandrasekharH(mu, albedo);
      moment += h / kPoints;
      integral += h / (1.0 + mu) / kPoints;
    }
    EXPECT_NEAR(moment, 2.0 / albedo * (1.0 - std::sqrt(1.0 - albedo)), 1e-5);
    EXPECT_NEAR(chandrasekharH(1.0, albedo), 1.0 / (1.0 - 0.5 * albedo * integral), 2e-5);
  }
  // The plane albedo at normal incidence: no light back without scattering, all of it
  // without absorption.
  EXPECT_DOUBLE_EQ(exactIsotropicRd(0.0), 0.0);
  EXPECT_NEAR(exactIsotropicRd(1.0), 1.0, 1e-12);
}

// Index-matched, isotropic (g = 0), collimated normal incidence on a slab 12 diffusion
// lengths deep and 24 wide: the tracer's Rd equals the exact half-space value
// 1 - H(1)·sqrt(1 - α) within 4 standard errors plus the finite-slab bias. That bias is
// the light that would have come back from beyond the slab, below exp(-12)·13 ≈ 1e-4 of Rd
// (the diffusion fall-off of flux with depth and of Rd(r) with radius); allowed as 1e-4·Rd.
// The dipole (η = 1, A ≈ 1) is only as good as diffusion theory: against exact
// transport it under-predicts by 0.8 %, 7.1 % and 16.8 % at α' = 0.99, 0.9 and 0.7, so it
// is held to 3 %, 10 % and 20 %, and must come out low where the gap is many standard
// errors wide.
TEST(SlabReflectance, IndexMatchedSlabMatchesExactHalfSpaceAndDipole) {
  const glm::dvec3 albedo(double(0.99f), double(0.9f), double(0.7f));  // as the float material stores them
  SlabReflectanceOptions options;
  options.samples = 1 << 16;
  options.seed = 1;
  const SlabReflectance r = estimateSlabReflectance(albedoMaterial(albedo), 1.0, options);
  const glm::dvec3 dipoleTolerance(0.03, 0.10, 0.20);
  for (int c = 0; c < 3; ++c) {
    SCOPED_TRACE(albedo[c]);
    const double exact = exactIsotropicRd(albedo[c]), dipole = dipoleRd(albedo[c], 1.0);
    std::cout << "alpha " << albedo[c] << ": Rd " << r.rd[c] << " +- " << r.standardError[c] << ", exact "
              << exact << ", dipole " << dipole << " (slab " << r.slabSize[c] << " mfp)\n";
    EXPECT_LE(std::abs(r.rd[c] - exact), 4.0 * r.standardError[c] + 1e-4 * exact);
    EXPECT_LE(r.standardError[c], 0.006 * exact) << "too noisy to check anything";
    EXPECT_LE(std::abs(r.rd[c] - dipole), dipoleTolerance[c] * dipole);
    if (c > 0) {
      EXPECT_GT(r.rd[c] - dipole, 4.0 * r.standardError[c]) << "the dipole under-predicts";
    }
  }
  std::cout << r.seconds << " s\n";
}

// With η = 1.3 the tracer's light connection is exact for this slab (a straight line:
// the light arrives along the normal of a flat face; see slab_reflectance.h), and camera
// paths refract and reflect at the boundary exactly. So its Rd must equal an independent
// 1D walk within 4 combined standard errors. The dipole with its boundary term A(1.3) is
// printed for reference, not checked: it is not an exact result.
TEST(SlabReflectance, DielectricSlabMatchesIndependentRandomWalk) {
  EXPECT_NEAR(fresnelReflectance(1.0, 1.3), (0.3 / 2.3) * (0.3 / 2.3), 1e-12);
  const double eta = 1.3;
  const glm::dvec3 albedo(double(0.99f), double(0.9f), double(0.7f));
  SlabReflectanceOptions options;
  options.samples = 1 << 16;
  options.seed = 2;
  const SlabReflectance r = estimateSlabReflectance(albedoMaterial(albedo), eta, options);
  for (int c = 0; c < 3; ++c) {
    SCOPED_TRACE(albedo[c]);
    double walkError = 0.0;
    const double walk = halfSpaceWalk(albedo[c], eta, 1000000, 30 + std::uint64_t(c), walkError);
    std::cout << "eta 1.3 alpha " << albedo[c] << ": Rd " << r.rd[c] << " +- " << r.standardError[c] << ", 1D walk "
              << walk << " +- " << walkError << ", dipole " << dipoleRd(albedo[c], eta) << "\n";
    EXPECT_LE(std::abs(r.rd[c] - walk), 4.0 * std::hypot(r.standardError[c], walkError));
    EXPECT_LE(r.standardError[c], 0.01 * walk) << "too noisy to check anything";
  }
}

// A semi-infinite medium's Rd cannot depend on how far away the slab's other faces are.
// With one seed, a 12- and a 3000-diffusion-length slab see the same camera paths (only
// translated), so the two estimates must agree far inside their standard error. This
// catches paths that skip a boundary closer than the tracer's ray epsilon (which grows
// with the scene size) at ior != 1: they escape instead of being internally reflected,
// and Rd came out 4 % low (6 standard errors) at 3000 before scattering vertices stopped
// using the epsilon.
TEST(SlabReflectance, DielectricSlabRdDoesNotDependOnSlabSize) {
  MaterialSample m = albedoMaterial(glm::dvec3(0.99, 0.0, 0.0));
  m.sigmaT.y = m.sigmaT.z = 0.0f;  // one channel is enough
  SlabReflectanceOptions options;
  options.samples = 1 << 16;
  options.seed = 6;
  const SlabReflectance near = estimateSlabReflectance(m, 1.3, options);
  options.size = 3000.0;
  const SlabReflectance far = estimateSlabReflectance(m, 1.3, options);
  std::cout << "slab " << near.slabSize.x << ": Rd " << near.rd.x << " +- " << near.standardError.x << "; slab "
            << far.slabSize.x << ": Rd " << far.rd.x << " +- " << far.standardError.x << "\n";
  EXPECT_LE(std::abs(far.rd.x - near.rd.x), 0.25 * near.standardError.x);
  EXPECT_LE(near.standardError.x, 0.01 * near.rd.x);
}

// One random stream per sample, summed in index order: the thread count cannot change a
// bit, a different seed must.
TEST(SlabReflectance, DeterministicForASeedRegardlessOfThreads) {
  const MaterialSample m = albedoMaterial(glm::dvec3(0.95, 0.8, 0.5));
  SlabReflectanceOptions options;
  options.samples = 2048;
  options.seed = 4;
  options.threads = 1;
  const SlabReflectance one = estimateSlabReflectance(m, 1.3, options);
  options.threads = 2;
  const SlabReflectance two = estimateSlabReflectance(m, 1.3, options);
  options.seed = 5;
  const SlabReflectance other = estimateSlabReflectance(m, 1.3, options);
  EXPECT_EQ(one.rd, two.rd);
  EXPECT_EQ(one.standardError, two.standardError);
  EXPECT_NE(one.rd, other.rd);
}

TEST(SlabReflectance, RejectsBadArguments) {
  const MaterialSample m = albedoMaterial(glm::dvec3(0.9));
  SlabReflectanceOptions options;
  options.samples = 1;
  EXPECT_THROW(estimateSlabReflectance(m, 1.0, options), std::invalid_argument);
  options.samples = 16;
  EXPECT_THROW(estimateSlabReflectance(m, 0.0, options), std::invalid_argument);
  options.size = 0.0;
  EXPECT_THROW(estimateSlabReflectance(m, 1.0, options), std::invalid_argument);
  EXPECT_THROW(chandrasekharH(1.0, 1.5), std::invalid_argument);
  // A channel without extinction reflects nothing (and costs nothing).
  MaterialSample empty = m;
  empty.sigmaT.y = empty.sigmaS.y = 0.0f;
  options.size = 12.0;
  EXPECT_EQ(estimateSlabReflectance(empty, 1.0, options).rd.y, 0.0);
}

}  // namespace
}  // namespace sslpv::test
