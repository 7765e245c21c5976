// The calibrated shading's single-scattering term (volume/cpu/single_scattering.h) against
// closed forms: a homogeneous half-space lit along its normal, seen along and off it,
// and the once-scattered share of the thick slab's reflectance the lattice leaves to it.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <glm/geometric.hpp>

#include "test_meshes.h"
#include "volume/core/fresnel.h"
#include "volume/calibration/lpv_calibration.h"
#include "device_shared/lpv_constants.h"
#include "volume/cpu/single_scattering.h"
#include "volume/lpv/voxelize.h"

namespace sslpv {
namespace {

using test::makeBoxMesh;

TEST(SingleScatteringShare, IndexMatchedMatchesTheClosedForm) {
  // η = 1: (α'/2) ∫0^1 μ / (μ + μt) dμ = (α'/2) (1 − μt ln((1 + μt) / μt)).
  for (double beam : {1.0, 0.7, 0.3})
    for (double albedo : {0.05, 0.5, 1.0}) {
      const double exact = 0.5 * albedo * (1.0 - beam * std::log((1.0 + beam) / beam));
      EXPECT_NEAR(singleScatteringPerEntering(albedo, 1.0, beam), exact, 1e-7 * exact) << beam << " " << albedo;
    }
}

TEST(SingleScatteringShare, WithABoundaryMatchesAFineQuadrature) {
  // Behind η = 1.3 only directions above the critical cosine leave, each through 1 − F.
  const double ior = 1.3, muC = std::sqrt(1.0 - 1.0 / (ior * ior));
  for (double beam : {1.0, 0.8}) {
    constexpr int kSteps = 200000;
    double sum = 0.0;
    for (int i = 0; i < kSteps; ++i) {
      const double mu = muC + (1.0 - muC) * (i + 0.5) / kSteps;
      sum += (1.0 - fresnelReflectanceFromInside(mu, ior)) * mu / (mu + beam);
    }
    const double exact = 0.5 * 0.6 * sum * (1.0 - muC) / kSteps;
    EXPECT_NEAR(singleScatteringPerEntering(0.6, ior, beam), exact, 1e-6 * exact) << beam;
    // Below the index-matched share: the boundary keeps some of the light in.
    EXPECT_LT(exact, singleScatteringPerEntering(0.6, 1.0, beam));
  }
}

TEST(SecondScatteringDepth, MatchesARandomWalk) {
  // An analog walk of the first two scatterings below a smooth boundary: first at
  // z ~ e^-z, then a flight of length e^-l at a uniform cosine; flights that reach the
  // boundary leave with 1 − R (single scattering) or are mirrored back in with R.
  std::mt19937_64 rng(7);
  std::exponential_distribution<double> flight(1.0);
  std::uniform_real_distribution<double> cosine(-1.0, 1.0), unit(0.0, 1.0);
  for (double ior : {1.0, 1.3, 1.5}) {
    constexpr int kWalks = 400000;
    double sum = 0.0, sumSquares = 0.0;
    int second = 0;
    for (int i = 0; i < kWalks; ++i) {
      const double z = flight(rng), mu = cosine(rng), l = flight(rng);
      double depth = z + mu * l;
      if (depth < 0.0) {
        if (unit(rng) >= fresnelReflectanceFromInside(-mu, ior)) continue;  // left: scattered once
        depth = -depth;
      }
      sum += depth;
      sumSquares += depth * depth;
      ++second;
    }
    const double mean = sum / second;
    const double standardError = std::sqrt((sumSquares / second - mean * mean) / second);
    EXPECT_NEAR(secondScatteringDepth(ior), mean, 4.0 * standardError) << "ior " << ior;
  }
  EXPECT_THROW(secondScatteringDepth(0.0), std::invalid_argument);
}

/// The definition of singleScatteringIntegral, by a fine midpoint rule.
double integralByQuadrature(double sigma, double p0, double k, double end = 1e300) {
  if (end == 1e300 && k < 0.0 && p0 >= 0.0) end = p0 / -k;  // no exit found: the light's entry
  end = std::min(end, 60.0 / sigma);
  constexpr int kSteps = 400000;
  double sum = 0.0;
  for (int i = 0; i < kSteps; ++i) {
    const double s = end * (i + 0.5) / kSteps;
    sum += std::exp(-sigma * s - sigma * std::max(0.0, p0 + k * s));
  }
  return sum * end / kSteps;
}

TEST(SingleScatteringIntegral, MatchesItsDefinition) {
  // Front-lit (k ≥ 0), lit from behind (k < 0: the ray ends where the light entered,
  // k = −1 is a slab seen against its light), points just in front of the entry, and rays
  // that leave the object after 0.2 or 1.5.
  for (double end : {std::numeric_limits<double>::infinity(), 1.5, 0.2})
    for (double sigma : {0.05, 1.0, 7.0})
      for (double p0 : {-0.3, 0.0, 0.4, 3.0})
        for (double k : {-4.0, -1.0, -0.999, -0.5, 0.0, 0.35, 1.0, 6.0}) {
          const double exact = integralByQuadrature(sigma, p0, k, std::isinf(end) ? 1e300 : end);
          const double value = singleScatteringIntegral(sigma, p0, k, end);
          EXPECT_NEAR(value, exact, 1e-5 * exact + 1e-12)
              << "sigma " << sigma << " p0 " << p0 << " k " << k << " end " << end;
        }
  EXPECT_EQ(singleScatteringIntegral(0.0, 1.0, 1.0), 0.0) << "no medium, nothing scatters";
  EXPECT_TRUE(std::isfinite(singleScatteringIntegral(1e6, 1e3, -1e-3))) << "extreme exponents stay finite";
}

/// A homogeneous slab 20 x 10 x 20 (top face y = 0, bottom y = -10) on a 32³ grid, σt = 1,
/// σs = 0.5, and an orthographic "shadow map" of a light straight above (or below, `fromBelow`):
/// every texel enters its face at normal incidence with irradiance `irradiance` inside.
struct LitSlab {
  MaterialGrid material;
  std::vector<EntryMap> maps;
};

/// The medium of a slab 20 wide from y = `bottom` to its top face y = 0, σt = 1, σs = 0.5.
MaterialGrid slabMedium(float bottom, int resolution) {
  const TriangleMesh mesh = makeBoxMesh(glm::vec3(-10.0f, bottom, -10.0f), glm::vec3(10.0f, 0.0f, 10.0f));
  MaterialGrid m;
  m.frame = makeGridFrame(mesh.bounds(), resolution);
  m.coverage = voxelizeCoverage(mesh, m.frame);
  m.sigmaT.assign(m.frame.cellCount(), glm::vec3(1.0f));
  m.sigmaS.assign(m.frame.cellCount(), glm::vec3(0.5f));
  m.g.assign(m.frame.cellCount(), 0.0f);
  return m;
}

LitSlab litSlab(float irradiance, bool fromBelow = false) {
  LitSlab slab;
  slab.material = slabMedium(-10.0f, 32);
  EntryMap map;
  ShadowView& view = map.view;
  const double down = fromBelow ? -1.0 : 1.0;
  view.projection = ShadowView::Projection::Orthographic;
  view.size = 64;
  view.halfSize = 20.0;
  view.forward = glm::dvec3(0.0, -down, 0.0);
  view.right = glm::dvec3(1.0, 0.0, 0.0);
  view.up = glm::cross(view.right, view.forward);
  view.origin = glm::dvec3(0.0, fromBelow ? -20.0 : 10.0, 0.0);
  map.texels.resize(std::size_t(view.size) * view.size);
  for (int y = 0; y < view.size; ++y)
    for (int x = 0; x < view.size; ++x) {
      const TexelRay ray = view.texelRay(x, y);
      EntryTexel& t = map.texels[std::size_t(y) * view.size + x];
      t.position = glm::vec3(ray.origin + 10.0 * ray.dir);
      t.distance = 10.0f;
      t.pathScale = 1.0f;
      t.irradiance = glm::vec3(irradiance, 2.0f * irradiance, 0.5f * irradiance);
      t.direction = glm::vec3(view.forward);
      t.pathGradient = glm::vec3(view.forward);  // −n / cos θt, n = −forward, θt = 0
    }
  slab.maps.push_back(map);
  return slab;
}

TEST(SingleScatteredRadiance, HalfSpaceLitAlongItsNormal) {
  // Seen along inside cosine μ: L = σs E / (4π σt (1 + μ)), per channel in proportion to E.
  // The light's path below the face is linear, so P and its gradient from the entry texel
  // are exact.
  const LitSlab slab = litSlab(3.0f);
  const glm::dvec3 inward(0.0, -1.0, 0.0);
  for (const glm::dvec3& p : {glm::dvec3(0.3, 0.0, -0.2), glm::dvec3(-4.1, 0.0, 6.7)})
    for (double mu : {1.0, 0.6, 0.3}) {
      const glm::dvec3 into(std::sqrt(1.0 - mu * mu), -mu, 0.0);
      const glm::vec3 radiance = singleScatteredRadiance(slab.material, slab.maps, p, inward, into);
      for (int ch = 0; ch < 3; ++ch) {
        const double e = 3.0 * (ch == 0 ? 1.0 : ch == 1 ? 2.0 : 0.5);
        const double exact = 0.5 * e / (4.0 * SSLPV_PI * (1.0 + mu));
        EXPECT_NEAR(radiance[ch], exact, 1e-4 * exact) << "mu " << mu << " channel " << ch;
      }
    }
}

TEST(SingleScatteredRadiance, EachChannelWithItsOwnExtinction) {
  // σt = 1, 1.3 and 3 (σs = σt / 2): along the normal each channel is σs E / (4π σt · 2).
  LitSlab slab = litSlab(1.0f);
  for (glm::vec3& t : slab.material.sigmaT) t = glm::vec3(1.0f, 1.3f, 3.0f);
  for (glm::vec3& s : slab.material.sigmaS) s = glm::vec3(0.5f, 0.65f, 1.5f);
  const glm::dvec3 p(0.3, 0.0, -0.2), inward(0.0, -1.0, 0.0);
  const glm::vec3 radiance = singleScatteredRadiance(slab.material, slab.maps, p, inward, inward);
  for (int ch = 0; ch < 3; ++ch) {
    const double e = ch == 0 ? 1.0 : ch == 1 ? 2.0 : 0.5;
    const double exact = 0.5 * e / (4.0 * SSLPV_PI * 2.0);
    EXPECT_NEAR(radiance[ch], exact, 1e-4 * exact) << "channel " << ch;
  }
}

TEST(SingleScatteredRadiance, SlabSeenAgainstItsLight) {
  // Lit from below, seen from above along the normal: every depth of the 10-thick slab
  // sends e^{-σt s} e^{-σt (10 - s)}, so L = σs E · 10 e^{-10} / (4π), the k = -1 branch.
  const LitSlab slab = litSlab(1.0f, true);
  const glm::vec3 radiance = singleScatteredRadiance(slab.material, slab.maps, glm::dvec3(0.3, 0.0, -0.2),
                                                     glm::dvec3(0.0, -1.0, 0.0), glm::dvec3(0.0, -1.0, 0.0));
  for (int ch = 0; ch < 3; ++ch) {
    const double e = ch == 0 ? 1.0 : ch == 1 ? 2.0 : 0.5;
    const double exact = 0.5 * e * 10.0 * std::exp(-10.0) / (4.0 * SSLPV_PI);
    EXPECT_NEAR(radiance[ch], exact, 1e-3 * exact) << "channel " << ch;
  }
}

TEST(SingleScatteredRadiance, DarkWhereNoLightEnters) {
  // Texels that carry no light, and points the light would reach from in front of the
  // surface (the entry point more than a cell below them), add nothing.
  LitSlab slab = litSlab(0.0f);
  const glm::dvec3 p(0.0, 0.0, 0.0), inward(0.0, -1.0, 0.0);
  EXPECT_EQ(singleScatteredRadiance(slab.material, slab.maps, p, inward, inward), glm::vec3(0.0f));
  slab = litSlab(1.0f);
  for (EntryTexel& t : slab.maps[0].texels) t.distance = 25.0f;  // entry 15 below the top face
  EXPECT_EQ(singleScatteredRadiance(slab.material, slab.maps, p, inward, inward), glm::vec3(0.0f));
  // Outside every view: no light either.
  slab = litSlab(1.0f);
  slab.maps[0].view.halfSize = 1e-3;
  EXPECT_EQ(singleScatteredRadiance(slab.material, slab.maps, glm::dvec3(5.0, 0.0, 5.0), inward, inward),
            glm::vec3(0.0f));
}

TEST(SingleScatteredRadiance, NoLightWhereThePlanarEntryIsNotOnTheSurface) {
  // Seen from 3 below the top face, the light arrives through the 3 above (P = 3):
  // L = σs E e^{-3} / (4π σt · 2). With texels that claim a grazing entry (cos θi / cos θt
  // = 0.05, refracted almost along the face) while the map sees the face straight above,
  // the planar estimate would bring light through 1/20 of that depth; that is a curved
  // surface's terminator, not a plane, and (almost) no light is counted.
  LitSlab slab = litSlab(1.0f);
  const glm::dvec3 deep(0.0, -3.0, 0.0), down(0.0, -1.0, 0.0);
  const glm::vec3 planar = singleScatteredRadiance(slab.material, slab.maps, deep, down, down);
  const double exact = 0.5 * std::exp(-3.0) / (4.0 * SSLPV_PI * 2.0);
  EXPECT_NEAR(planar.r, exact, 1e-4 * exact);
  for (EntryTexel& t : slab.maps[0].texels) {
    t.pathScale = 0.05f;
    t.direction = glm::vec3(glm::normalize(glm::dvec3(1.0, -0.05, 0.0)));
    t.pathGradient = glm::vec3(0.0f, -0.05f, 0.0f);
  }
  const glm::vec3 grazing = singleScatteredRadiance(slab.material, slab.maps, deep, down, down);
  for (int ch = 0; ch < 3; ++ch) EXPECT_LT(grazing[ch], 0.02 * planar[ch]) << "channel " << ch;
}

TEST(SingleScatteredRadiance, ThinSlabEndsWhereTheViewRayLeaves) {
  // A slab 1 thick (σt = 1, σs = 0.5) lit along its normal from above and seen along it:
  // the view ray leaves at the bottom face, L = σs E (1 − e^{-2}) / (4π σt · 2). The exit is
  // found to within half a cell (64³ here: 1/3 unit).
  LitSlab slab = litSlab(1.0f);
  slab.material = slabMedium(-1.0f, 64);
  const MaterialGrid& m = slab.material;
  const glm::dvec3 down(0.0, -1.0, 0.0);
  const glm::vec3 radiance = singleScatteredRadiance(m, slab.maps, glm::dvec3(0.3, 0.0, -0.2), down, down);
  const double thick = 0.5 / (4.0 * SSLPV_PI * 2.0);
  const double exact = thick * (1.0 - std::exp(-2.0));
  EXPECT_NEAR(radiance.r, exact, 0.06 * exact);
  EXPECT_LT(radiance.r, 0.95 * thick) << "a half-space's light would be 16 % more";
  EXPECT_EQ(viewRayExit(m, glm::dvec3(0.3, 0.0, -0.2), glm::dvec3(1.0, 0.0, 0.0), 1.0),
            std::numeric_limits<double>::infinity())
      << "along the slab the ray stays inside for the 6 optical depths searched";
}

}  // namespace
}  // namespace sslpv
