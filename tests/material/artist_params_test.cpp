// Artist parameters (volume/material/artist_params.h): surface colour and scatter distance map to
// σt, σs, g and back. The round trips are judged against adding-doubling itself, not the
// table the mapping inverts, so an inaccurate table or a wrong inversion fails them.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "volume/calibration/adding_doubling.h"
#include "volume/material/artist_params.h"
#include "volume/core/error.h"
#include "volume/core/fresnel.h"
#include "volume/calibration/lpv_calibration.h"
#include "volume/reference/slab_reflectance.h"

namespace sslpv::test {
namespace {

/// α' of a stored material channel, from the float values the grids would hold.
double reducedAlbedo(const MaterialSample& m, int c) {
  const double sigmaT = m.sigmaT[c], sigmaS = m.sigmaS[c], g = m.g;
  return sigmaS * (1.0 - g) / (sigmaT - sigmaS * g);
}

std::string problemOf(const ArtistParams& p, double ior) { return artistParamsProblem(p, ior); }

TEST(ArtistParams, MaxColourIsOneMinusNormalFresnel) {
  EXPECT_DOUBLE_EQ(maxSurfaceColour(1.0), 1.0);
  EXPECT_NEAR(maxSurfaceColour(1.5), 0.96, 1e-12);
  // The table's brightest entry is the same limit, so the largest accepted colour maps to α' = 1.
  for (double ior : {1.0, 1.3, 1.5}) EXPECT_DOUBLE_EQ(boundaryReflectance(1.0, ior), maxSurfaceColour(ior));
}

// colour -> σt, σs, g (stored as floats) -> α' -> exact Rd within 0.1 %, across the range
// and for several g: the distance is the reduced one, so Rd depends on α' only.
TEST(ArtistParams, ColourRoundTripsThroughAddingDoublingWithinPointOnePercent) {
  for (double ior : {1.0, 1.3, 1.5}) {
    const double cmax = maxSurfaceColour(ior);
    for (double fraction : {0.001, 0.01, 0.1, 0.3, 0.5, 0.7, 0.9, 0.97, 0.995}) {
      for (double g : {0.0, 0.6, -0.4}) {
        const double colour = fraction * cmax;
        SCOPED_TRACE("ior " + std::to_string(ior) + " colour " + std::to_string(colour) + " g " + std::to_string(g));
        ArtistParams p;
        p.colour = glm::dvec3(colour, 0.5 * colour, 0.25 * colour);
        p.scatterDistance = glm::dvec3(0.5, 2.0, 7.0);
        p.g = g;
        const MaterialSample m = artistToPhysical(p, ior);
        for (int c = 0; c < 3; ++c) {
          const double exact = addingDoublingHalfSpace(reducedAlbedo(m, c), ior).rd;
          EXPECT_NEAR(exact, p.colour[c], 1e-3 * p.colour[c]) << "channel " << c;
          // The distance is the transport mean free path.
          const double reducedSigmaT = double(m.sigmaT[c]) - double(m.sigmaS[c]) * g;
          EXPECT_NEAR(1.0 / reducedSigmaT, p.scatterDistance[c], 1e-5 * p.scatterDistance[c]);
        }
        EXPECT_FLOAT_EQ(m.g, float(g));
      }
    }
  }
}

TEST(ArtistParams, ReverseViewRecoversColourAndDistance) {
  ArtistParams p;
  p.colour = {0.8, 0.45, 0.1};
  p.scatterDistance = {3.0, 1.0, 0.25};
  p.g = 0.3;
  const ArtistParams back = physicalToArtist(artistToPhysical(p, 1.4), 1.4);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(back.colour[c], p.colour[c], 1e-4 * p.colour[c]);
    EXPECT_NEAR(back.scatterDistance[c], p.scatterDistance[c], 1e-5 * p.scatterDistance[c]);
  }
  EXPECT_NEAR(back.g, 0.3, 1e-7);
  // σ -> artist -> σ: a Jensen material comes back as itself.
  const MaterialSample skin = *presetMaterial("skin1", 0.0f, 1.0);
  const MaterialSample again = artistToPhysical(physicalToArtist(skin, 1.3), 1.3);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(again.sigmaT[c], skin.sigmaT[c], 1e-4 * skin.sigmaT[c]);
    EXPECT_NEAR(again.sigmaS[c], skin.sigmaS[c], 1e-4 * skin.sigmaS[c]);
  }
}

TEST(ArtistParams, ReverseViewOfEmptyOrClampedChannels) {
  MaterialSample m;
  m.sigmaT = {0.0f, 2.0f, 1.0f};
  m.sigmaS = {0.0f, 3.0f, 0.0f};  // σs > σt reads as σt, as the brush clamps it
  const ArtistParams p = physicalToArtist(m, 1.3);
  EXPECT_EQ(p.colour[0], 0.0);
  EXPECT_TRUE(std::isinf(p.scatterDistance[0]));
  EXPECT_DOUBLE_EQ(p.colour[1], maxSurfaceColour(1.3));
  EXPECT_DOUBLE_EQ(p.scatterDistance[1], 0.5);
  EXPECT_EQ(p.colour[2], 0.0);  // a pure absorber
}

TEST(ArtistParams, ColourZeroIsAPureAbsorberAndColourMaxAbsorbsNothing) {
  ArtistParams p;
  p.colour = {0.0, maxSurfaceColour(1.3), 0.5};
  p.scatterDistance = glm::dvec3(2.0);
  p.g = 0.5;
  const MaterialSample m = artistToPhysical(p, 1.3);
  EXPECT_EQ(m.sigmaS[0], 0.0f);
  EXPECT_FLOAT_EQ(m.sigmaT[0], 0.5f);
  EXPECT_EQ(m.sigmaS[1], m.sigmaT[1]);
  EXPECT_FLOAT_EQ(m.sigmaS[1], 1.0f);  // σs' = 1 / d, σs = σs' / (1 - g)
  // Index-matched, a colour of exactly 1 is reachable (α' = 1).
  EXPECT_EQ(reducedAlbedoForColour(1.0, 1.0), 1.0);
}

TEST(ArtistParams, OutOfRangeValuesAreRefusedNamingTheValue) {
  ArtistParams p;
  p.scatterDistance = glm::dvec3(1.0);
  p.colour = {0.5, 1.0, 0.5};
  const std::string bright = problemOf(p, 1.5);
  EXPECT_NE(bright.find("colour[1]"), std::string::npos) << bright;
  EXPECT_NE(bright.find("got 1"), std::string::npos) << bright;
  EXPECT_NE(bright.find("0.96"), std::string::npos) << bright;
  EXPECT_THROW(artistToPhysical(p, 1.5), InputError);
  EXPECT_EQ(problemOf(p, 1.0), "");

  p.colour = {-0.01, 0.5, 0.5};
  EXPECT_NE(problemOf(p, 1.0).find("colour[0]: must be in [0, 1], got -0.01"), std::string::npos) << problemOf(p, 1.0);
  p.colour = {0.5, 0.5, NAN};
  EXPECT_NE(problemOf(p, 1.0).find("colour[2]"), std::string::npos);
  p.colour = glm::dvec3(0.5);
  p.scatterDistance = {1.0, 0.0, 1.0};
  EXPECT_NE(problemOf(p, 1.0).find("scatter_distance[1]: must be positive and finite, got 0"), std::string::npos);
  p.scatterDistance = {1.0, 1.0, INFINITY};
  EXPECT_NE(problemOf(p, 1.0).find("scatter_distance[2]"), std::string::npos);
  p.scatterDistance = {1e-40, 1.0, 1.0};
  EXPECT_NE(problemOf(p, 1.0).find("scatter_distance[0]: must be at least"), std::string::npos);
  p.scatterDistance = glm::dvec3(1.0);
  p.g = 0.995;
  EXPECT_EQ(problemOf(p, 1.0), "g: must be in [-0.99, 0.99], got 0.995");
  EXPECT_THROW(reducedAlbedoForColour(1.2, 1.0), InputError);
}

// Independent of both the table and adding-doubling: the reference path tracer's slab
// reflectance of the mapped material (g = 0, where the colour's definition needs no
// similarity relation). 4 standard errors, and the error must be small against the value.
TEST(ArtistParams, PathTracedSlabShowsThePickedColour) {
  ArtistParams p;
  p.colour = {0.7, 0.4, 0.1};
  p.scatterDistance = {1.0, 0.5, 0.25};
  const double ior = 1.3;
  SlabReflectanceOptions options;
  options.samples = 1 << 14;
  options.seed = 7;
  const SlabReflectance measured = estimateSlabReflectance(artistToPhysical(p, ior), ior, options);
  for (int c = 0; c < 3; ++c) {
    SCOPED_TRACE(c);
    EXPECT_LT(measured.standardError[c], 0.03 * p.colour[c]);
    EXPECT_NEAR(measured.rd[c], p.colour[c], 4.0 * measured.standardError[c]);
  }
}

}  // namespace
}  // namespace sslpv::test
