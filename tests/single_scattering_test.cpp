// The calibrated shading's single-scattering term (volume/single_scattering.h) against
// closed forms: a homogeneous half-space lit along its normal, seen along and off it,
// and the once-scattered share of the thick slab's reflectance the lattice leaves to it.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <glm/geometric.hpp>

#include "test_meshes.h"
#include "volume/fresnel.h"
#include "volume/lpv_calibration.h"
#include "volume/lpv_constants.h"
#include "volume/single_scattering.h"
#include "volume/voxelize.h"

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

/// A homogeneous slab 20 x 10 x 20 (top face y = 0) on a 32³ grid, σt = 1, σs = 0.5, and
/// an orthographic "shadow map" of a light straight above: every texel enters the top face
/// at normal incidence with irradiance `irradiance` inside.
struct LitSlab {
  MaterialGrid material;
  std::vector<EntryMap> maps;
};

LitSlab litSlab(float irradiance) {
  LitSlab slab;
  const TriangleMesh mesh = makeBoxMesh(glm::vec3(-10.0f, -10.0f, -10.0f), glm::vec3(10.0f, 0.0f, 10.0f));
  MaterialGrid& m = slab.material;
  m.frame = makeGridFrame(mesh.bounds(), 32);
  m.coverage = voxelizeCoverage(mesh, m.frame);
  m.sigmaT.assign(m.frame.cellCount(), glm::vec3(1.0f));
  m.sigmaS.assign(m.frame.cellCount(), glm::vec3(0.5f));
  m.g.assign(m.frame.cellCount(), 0.0f);
  EntryMap map;
  ShadowView& view = map.view;
  view.projection = ShadowView::Projection::Orthographic;
  view.size = 64;
  view.halfSize = 20.0;
  view.forward = glm::dvec3(0.0, -1.0, 0.0);
  view.right = glm::dvec3(1.0, 0.0, 0.0);
  view.up = glm::cross(view.right, view.forward);
  view.origin = glm::dvec3(0.0, 10.0, 0.0);
  map.texels.resize(std::size_t(view.size) * view.size);
  for (int y = 0; y < view.size; ++y)
    for (int x = 0; x < view.size; ++x) {
      const TexelRay ray = view.texelRay(x, y);
      EntryTexel& t = map.texels[std::size_t(y) * view.size + x];
      t.position = glm::vec3(ray.origin + 10.0 * ray.dir);
      t.distance = 10.0f;
      t.pathScale = 1.0f;
      t.irradiance = glm::vec3(irradiance, 2.0f * irradiance, 0.5f * irradiance);
      t.direction = glm::vec3(0.0f, -1.0f, 0.0f);
    }
  slab.maps.push_back(map);
  return slab;
}

TEST(SingleScatteredRadiance, HalfSpaceLitAlongItsNormal) {
  // Seen along inside cosine μ: L = σs E / (4π σt (1 + μ)), per channel in proportion to E.
  const LitSlab slab = litSlab(3.0f);
  const glm::dvec3 p(0.3, 0.0, -0.2), inward(0.0, -1.0, 0.0);
  for (double mu : {1.0, 0.6, 0.3}) {
    const glm::dvec3 into(std::sqrt(1.0 - mu * mu), -mu, 0.0);
    const glm::vec3 radiance = singleScatteredRadiance(slab.material, slab.maps, p, inward, into);
    for (int ch = 0; ch < 3; ++ch) {
      const double e = 3.0 * (ch == 0 ? 1.0 : ch == 1 ? 2.0 : 0.5);
      const double exact = 0.5 * e / (4.0 * SSLPV_PI * (1.0 + mu));
      // The view leg is exact (midpoints in u = 1 − e^{−σt s}); the light leg's e^{−σt s μ}
      // is (1 − u)^μ there, which 8 midpoints integrate within 0.3 % at μ = 0.6 and
      // 1 % at μ = 0.3 (exact at μ = 1).
      const double tolerance = mu == 1.0 ? 1e-4 : mu == 0.6 ? 4e-3 : 1.2e-2;
      EXPECT_NEAR(radiance[ch], exact, tolerance * exact) << "mu " << mu << " channel " << ch;
    }
  }
}

TEST(SingleScatteringGroups, ChannelsWithCloseExtinctionShareSamples) {
  int group[3];
  double reference[3];
  // Jensen's ketchup: red alone, green and blue (1.48 / 1.04 = 1.42) together.
  ASSERT_EQ(singleScatteringGroups(glm::dvec3(0.241, 1.04, 1.48), group, reference), 2);
  EXPECT_EQ(group[0], 0);
  EXPECT_EQ(group[1], 1);
  EXPECT_EQ(group[2], 1);
  EXPECT_DOUBLE_EQ(reference[0], 0.241);
  EXPECT_DOUBLE_EQ(reference[1], std::sqrt(1.04 * 1.48));
  // Unsorted, one channel without medium: it gets no group.
  ASSERT_EQ(singleScatteringGroups(glm::dvec3(3.0, 0.0, 1.0), group, reference), 2);
  EXPECT_EQ(group[0], 1);
  EXPECT_EQ(group[1], -1);
  EXPECT_EQ(group[2], 0);
  ASSERT_EQ(singleScatteringGroups(glm::dvec3(1.0, 1.0, 1.0), group, reference), 1);
  EXPECT_DOUBLE_EQ(reference[0], 1.0);
}

TEST(SingleScatteredRadiance, ChannelsSharingSamplesKeepTheirOwnExtinction) {
  // σt = 1, 1.3 and 3 (σs = σt / 2): the first two share samples spaced for √1.3, so
  // each view leg is integrated off its own exponential; the closed form per channel is
  // still σs E / (4π σt (1 + μ)) along the normal.
  LitSlab slab = litSlab(1.0f);
  for (glm::vec3& t : slab.material.sigmaT) t = glm::vec3(1.0f, 1.3f, 3.0f);
  for (glm::vec3& s : slab.material.sigmaS) s = glm::vec3(0.5f, 0.65f, 1.5f);
  const glm::dvec3 p(0.3, 0.0, -0.2), inward(0.0, -1.0, 0.0);
  const glm::vec3 radiance = singleScatteredRadiance(slab.material, slab.maps, p, inward, inward);
  for (int ch = 0; ch < 3; ++ch) {
    const double e = ch == 0 ? 1.0 : ch == 1 ? 2.0 : 0.5;
    const double exact = 0.5 * e / (4.0 * SSLPV_PI * 2.0);
    EXPECT_NEAR(radiance[ch], exact, 1.5e-2 * exact) << "channel " << ch;
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
  // Integrated from 3 below the top face (seen from inside), every sample lies more than
  // 1.5 cells and half its depth below the entry point. With texels that enter straight
  // down the planar estimate's entry is on the face, and the light arrives through the
  // 3 + s above the sample: L = σs E e^{-3} / (4π σt · 2). With texels that claim a grazing
  // entry (cos θi / cos θt = 0.05, refracted almost along the face) while the map sees the
  // face straight above, the estimate would bring light through 1/20 of that depth; that
  // is a curved surface's terminator, not a plane, and (almost) no light is counted.
  LitSlab slab = litSlab(1.0f);
  const glm::dvec3 deep(0.0, -3.0, 0.0), down(0.0, -1.0, 0.0);
  const glm::vec3 planar = singleScatteredRadiance(slab.material, slab.maps, deep, down, down);
  const double exact = 0.5 * std::exp(-3.0) / (4.0 * SSLPV_PI * 2.0);
  EXPECT_NEAR(planar.r, exact, 1e-4 * exact);
  for (EntryTexel& t : slab.maps[0].texels) {
    t.pathScale = 0.05f;
    t.direction = glm::vec3(glm::normalize(glm::dvec3(1.0, -0.05, 0.0)));
  }
  // The cut ramps out between one and two times its tolerance (half the depth below the
  // entry here), which the shallowest samples' entries just reach: under 2 % of the light.
  const glm::vec3 grazing = singleScatteredRadiance(slab.material, slab.maps, deep, down, down);
  for (int ch = 0; ch < 3; ++ch) EXPECT_LT(grazing[ch], 0.02 * planar[ch]) << "channel " << ch;
}

TEST(SingleScatteringReads, EveryTermThatChangesWithAnEditedCellIsFlagged) {
  // The renderer re-integrates after a material edit only the pixels whose term reads an
  // edited cell. Over random view points and directions on the lit top face, with a
  // block of cells darkened 2 below it: every term that changed must be flagged, some
  // terms must change and some must be left alone (or the check would prove nothing).
  const LitSlab before = litSlab(1.0f);
  LitSlab after = before;
  const GridFrame& frame = after.material.frame;
  const glm::ivec3 centre = glm::ivec3(frame.toGrid(glm::dvec3(1.0, -2.0, 0.5)));
  CellRange edited;
  edited.lo = centre - 1;
  edited.hi = centre + 1;
  for (int z = edited.lo.z; z <= edited.hi.z; ++z)
    for (int y = edited.lo.y; y <= edited.hi.y; ++y)
      for (int x = edited.lo.x; x <= edited.hi.x; ++x) after.material.sigmaT[frame.index(x, y, z)] *= 3.0f;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> across(-6.0, 6.0), unit(0.0, 1.0);
  const glm::dvec3 inward(0.0, -1.0, 0.0);
  int changed = 0, flagged = 0, unflagged = 0;
  for (int i = 0; i < 4000; ++i) {
    const glm::dvec3 p(across(rng), 0.0, across(rng));
    const double mu = 0.2 + 0.8 * unit(rng), phi = 2.0 * SSLPV_PI * unit(rng), sine = std::sqrt(1.0 - mu * mu);
    const glm::dvec3 into(sine * std::cos(phi), -mu, sine * std::sin(phi));
    double reach = 0.0;
    const glm::vec3 old = singleScatteredRadiance(before.material, before.maps, p, inward, into, &reach);
    const glm::vec3 now = singleScatteredRadiance(after.material, after.maps, p, inward, into);
    const bool reads = singleScatteringReads(frame, p, inward, into, reach, edited);
    (reads ? flagged : unflagged) += 1;
    if (now != old) {
      ++changed;
      EXPECT_TRUE(reads) << "an unflagged term changed at p " << p.x << " " << p.z << ", mu " << mu;
    }
  }
  EXPECT_GT(changed, 20);
  EXPECT_GT(unflagged, 2000) << "most terms read none of a 3-cell block";
  EXPECT_GE(flagged, changed);
  EXPECT_FALSE(singleScatteringReads(frame, glm::dvec3(0.0), inward, inward, 10.0, CellRange{}))
      << "an empty range is read by nothing";
}

}  // namespace
}  // namespace sslpv
