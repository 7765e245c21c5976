// The editor's brush panel state (editor/brush_controls.h): whatever keys an artist
// presses, the brush handed to the engine stays usable, and each key does what the help
// overlay says.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "editor/brush_controls.h"
#include "volume/material/artist_params.h"
#include "volume/scene/material.h"

namespace sslpv {
namespace {

MaterialSample base() {
  MaterialSample m;
  m.sigmaT = {1.0f, 2.0f, 4.0f};
  m.sigmaS = {0.5f, 1.0f, 3.0f};
  return m;
}

/// Controls on the σt channel (the second; the first is the artist's colour).
BrushControls sigmaTControls() {
  BrushControls controls(base(), 10.0, "mm");
  controls.cycleChannel(+1);
  return controls;
}

TEST(BrushControls, DefaultsComeFromTheScene) {
  const BrushControls controls = sigmaTControls();
  const Brush b = controls.brush();
  EXPECT_EQ(b.channel, BrushChannel::SigmaT);
  EXPECT_EQ(b.mode, BrushMode::Set);
  EXPECT_EQ(b.rgb, glm::dvec3(2.0, 4.0, 8.0));  // twice the base σt: a first stroke shows
  EXPECT_DOUBLE_EQ(b.radius, 0.8);              // 8 % of the object's extent
  EXPECT_EQ(brushProblem(b), "");
}

TEST(BrushControls, RandomKeySequencesAlwaysGiveAUsableBrush) {
  // 20000 random presses of every control: brushProblem() must stay empty (the engine
  // would reject the stroke otherwise), e.g. albedo+mfp never gets a mode other than set.
  BrushControls controls(base(), 10.0, "mm");
  std::mt19937 rng(7);
  for (int i = 0; i < 20000; ++i) {
    const int dir = (rng() & 1) ? 1 : -1;
    switch (rng() % 14) {
      case 0: controls.cycleChannel(dir); break;
      case 1: controls.cycleMode(dir); break;
      case 2: controls.cycleFalloff(); break;
      case 3: controls.scaleRadius(dir > 0 ? 1.2 : 1 / 1.2); break;
      case 4: controls.adjustStrength(0.05 * dir); break;
      case 5: controls.adjustValue(dir); break;
      case 6: controls.adjustAlbedo(dir); break;
      case 7: controls.cycleComponent(); break;
      case 8: controls.negateValue(); break;
      case 9: controls.cycleMirror(); break;
      case 10: controls.adjustDepth(dir); break;
      case 11: controls.adjustArtistG(dir); break;
      case 12: controls.cycleSwatch(dir); break;
      case 13: {
        // Typed entries, good and bad: a refused one must leave the brush as it was.
        const std::string texts[] = {"0.5", "1.2", "0.1, 0.2 0.3", "x", "-1", "1e-40", "3e38", "0.99", ""};
        const Brush before = controls.brush();
        const std::string& text = texts[rng() % 9];  // drawn before the field, as GCC did (seeded_draws.h)
        const std::string problem = controls.enterArtistField(int(rng() % 3), text);
        const Brush after = controls.brush();
        if (!problem.empty()) {
          ASSERT_TRUE(after.artist.colour == before.artist.colour &&
                      after.artist.scatterDistance == before.artist.scatterDistance && after.artist.g == before.artist.g)
              << problem;
        }
        break;
      }
    }
    const Brush b = controls.brush();
    ASSERT_EQ(brushProblem(b), "") << "after " << i << " presses: " << controls.describe();
  }
}

TEST(BrushControls, ValuesAreRememberedPerChannelAndMode) {
  // A set target and a multiply factor are different numbers: switching mode and back
  // restores the first, and the value keys change only the current one.
  BrushControls controls = sigmaTControls();
  controls.adjustValue(+1);  // set target x1.25
  EXPECT_EQ(controls.brush().rgb, glm::dvec3(2.5, 5.0, 10.0));
  controls.cycleMode(+1);  // add
  controls.cycleMode(+1);  // multiply
  EXPECT_EQ(controls.brush().mode, BrushMode::Multiply);
  EXPECT_EQ(controls.brush().rgb, glm::dvec3(1.5));
  controls.cycleMode(-1);
  controls.cycleMode(-1);
  EXPECT_EQ(controls.brush().rgb, glm::dvec3(2.5, 5.0, 10.0));
}

TEST(BrushControls, ComponentSelectionEditsOneChannel) {
  BrushControls controls = sigmaTControls();
  controls.cycleComponent();  // r
  controls.adjustValue(-1);
  EXPECT_EQ(controls.brush().rgb, glm::dvec3(2.0 / 1.25, 4.0, 8.0));
  controls.cycleComponent();  // g
  controls.cycleComponent();  // b
  controls.cycleComponent();  // all again
  controls.adjustValue(+1);
  EXPECT_NEAR(controls.brush().rgb.x, 2.0, 1e-12);
  EXPECT_NEAR(controls.brush().rgb.y, 5.0, 1e-12);
}

TEST(BrushControls, AlbedoMfpStartsAtTheBaseAndPresetsCycleTheJensenTable) {
  BrushControls controls = sigmaTControls();
  controls.cycleChannel(+1);
  controls.cycleChannel(+1);
  controls.cycleChannel(+1);
  Brush b = controls.brush();
  ASSERT_EQ(b.channel, BrushChannel::AlbedoMfp);
  EXPECT_EQ(b.mode, BrushMode::Set);
  EXPECT_NEAR(b.albedo.z, 0.75, 1e-6);        // σs/σt of the base
  EXPECT_NEAR(b.meanFreePath.y, 0.5, 1e-6);   // 1/σt
  controls.cycleChannel(+1);
  const std::size_t n = measuredMaterials().size();
  const std::string first = controls.brush().preset;
  for (std::size_t i = 0; i < n; ++i) controls.adjustValue(+1);
  EXPECT_EQ(controls.brush().preset, first) << "a full cycle returns to the first preset";
  controls.adjustValue(-1);
  EXPECT_EQ(controls.brush().preset, std::string(measuredMaterials()[n - 1].name));
}

TEST(BrushControls, GStaysInsideTheBrushLimit) {
  BrushControls controls = sigmaTControls();
  controls.cycleChannel(+1);
  controls.cycleChannel(+1);
  ASSERT_EQ(controls.brush().channel, BrushChannel::G);
  for (int i = 0; i < 100; ++i) controls.adjustValue(+1);
  EXPECT_DOUBLE_EQ(controls.brush().scalar, double(kBrushMaxG));
  for (int i = 0; i < 100; ++i) controls.adjustValue(-1);
  EXPECT_DOUBLE_EQ(controls.brush().scalar, -double(kBrushMaxG));
}

TEST(BrushControls, DescribeNamesWhatThePaintWillDo) {
  BrushControls controls = sigmaTControls();
  controls.cycleMirror();
  const std::string text = controls.describe();
  EXPECT_NE(text.find("sigma_t set [2 4 8] /mm"), std::string::npos) << text;
  EXPECT_NE(text.find("radius 0.8 mm"), std::string::npos) << text;
  EXPECT_NE(text.find("mirror x"), std::string::npos) << text;
}

TEST(BrushControls, ColourIsThePrimaryChannelAndStartsFromTheBaseSeenAsAColour) {
  const double ior = 1.4;
  BrushControls controls(base(), 10.0, "mm", ior);
  const Brush b = controls.brush();
  EXPECT_EQ(b.channel, BrushChannel::Colour);
  EXPECT_EQ(b.mode, BrushMode::Set);
  const ArtistParams seen = physicalToArtist(base(), ior);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(b.artist.colour[c], 0.5 * seen.colour[c], 1e-12);  // darker: a first stroke shows
    EXPECT_NEAR(b.artist.scatterDistance[c], seen.scatterDistance[c], 1e-12);
  }
  EXPECT_EQ(brushProblem(b), "");
  // Keys: ; / ' the colour (all components, then one), , / . the distance, g / G the phase g.
  controls.adjustAlbedo(+1);
  EXPECT_NEAR(controls.brush().artist.colour.x, std::round((0.5 * seen.colour.x + 0.02) * 1000) / 1000, 1e-12);
  for (int i = 0; i < 100; ++i) controls.adjustAlbedo(+1);
  EXPECT_EQ(controls.brush().artist.colour, glm::dvec3(maxSurfaceColour(ior))) << "clamped to the ior's brightest";
  controls.cycleComponent();
  controls.cycleComponent();  // green
  for (int i = 0; i < 100; ++i) controls.adjustAlbedo(-1);
  EXPECT_EQ(controls.brush().artist.colour, glm::dvec3(maxSurfaceColour(ior), 0.0, maxSurfaceColour(ior)));
  EXPECT_NE(controls.describe().find("(editing green)"), std::string::npos) << controls.describe();
  const double d = controls.brush().artist.scatterDistance.y;
  controls.adjustValue(+1);
  EXPECT_NEAR(controls.brush().artist.scatterDistance.y, 1.25 * d, 1e-12);
  for (int i = 0; i < 100; ++i) controls.adjustArtistG(+1);
  EXPECT_DOUBLE_EQ(controls.brush().artist.g, 0.99);
}

TEST(BrushControls, SwatchesAreTheJensenMaterialsAndTypedEntryIsChecked) {
  const double ior = 1.3;
  BrushControls controls(base(), 10.0, "mm", ior);
  ASSERT_EQ(controls.swatches().size(), measuredMaterials().size());
  ASSERT_TRUE(controls.pickSwatch(2));
  EXPECT_EQ(controls.swatchName(2), std::string(measuredMaterials()[2].name));
  // The swatch paints exactly its Jensen material.
  const MaterialSample painted = artistToPhysical(controls.brush().artist, ior);
  const MaterialSample preset = *presetMaterial(measuredMaterials()[2].name, 0.0f, 1.0);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(painted.sigmaT[c], preset.sigmaT[c], 1e-4 * preset.sigmaT[c]);
    EXPECT_NEAR(painted.sigmaS[c], preset.sigmaS[c], 1e-4 * preset.sigmaS[c]);
  }
  EXPECT_FALSE(controls.pickSwatch(controls.swatches().size()));

  controls.cycleChannel(+1);  // to sigma_t: a typed colour comes back to the colour channel
  EXPECT_EQ(controls.enterArtistField(0, "0.8, 0.4 0.1"), "");
  EXPECT_EQ(controls.enterArtistField(1, "2"), "");
  EXPECT_EQ(controls.enterArtistField(2, "0.25"), "");
  const Brush b = controls.brush();
  EXPECT_EQ(b.channel, BrushChannel::Colour);
  EXPECT_EQ(b.artist.colour, glm::dvec3(0.8, 0.4, 0.1));
  EXPECT_EQ(b.artist.scatterDistance, glm::dvec3(2.0));
  EXPECT_EQ(b.artist.g, 0.25);
  EXPECT_EQ(controls.artistFieldText(0), "0.8, 0.4, 0.1");
  const std::string text = controls.describe();
  EXPECT_NE(text.find("colour set [0.8 0.4 0.1] dist 2 mm g 0.25"), std::string::npos) << text;
  const MaterialSample stored = artistToPhysical(b.artist, ior);
  char expected[160];
  std::snprintf(expected, sizeof expected, "stores sigma_t [%.3g %.3g %.3g] sigma_s [%.3g %.3g %.3g] /mm, g 0.25",
                stored.sigmaT.x, stored.sigmaT.y, stored.sigmaT.z, stored.sigmaS.x, stored.sigmaS.y, stored.sigmaS.z);
  EXPECT_EQ(controls.describeStored(), expected);
  controls.cycleChannel(+1);
  EXPECT_EQ(controls.describeStored(), "") << "sigma_t's value is already what is stored";

  EXPECT_NE(controls.enterArtistField(0, "0.5, 0.99, 0.5").find("colour[1]: must be in [0, 0.98"), std::string::npos);
  EXPECT_EQ(controls.enterArtistField(0, "0.5, 0.5"), "colour: expected one number or three, got \"0.5, 0.5\"");
  EXPECT_EQ(controls.enterArtistField(2, "0.1 0.2 0.3"), "g: expected one number, got \"0.1 0.2 0.3\"");
  EXPECT_NE(controls.enterArtistField(1, "0").find("scatter_distance[0]: must be positive"), std::string::npos);
  EXPECT_EQ(controls.brush().artist.colour, glm::dvec3(0.8, 0.4, 0.1)) << "a refused entry changes nothing";
}

TEST(BrushControls, PanelSettersValidateLikeTheKeys) {
  // The brush panel sets values directly; junk (NaN, 0, a mode the channel refuses, an
  // out-of-range colour) leaves the brush as it was and usable.
  BrushControls controls(base(), 10.0, "mm", 1.3);
  const Brush before = controls.brush();
  EXPECT_FALSE(controls.setRadius(std::nan("")));
  EXPECT_FALSE(controls.setRadius(0.0));
  EXPECT_DOUBLE_EQ(controls.brush().radius, before.radius);
  EXPECT_TRUE(controls.setRadius(2.5));
  EXPECT_DOUBLE_EQ(controls.brush().radius, 2.5);
  controls.setStrength(7.0);
  EXPECT_DOUBLE_EQ(controls.brush().strength, 1.0);
  controls.setDepth(-1.0);
  EXPECT_DOUBLE_EQ(controls.brush().depth, 0.0);
  EXPECT_FALSE(controls.setMode(BrushMode::Add)) << "the colour channel only sets";
  controls.setChannel(BrushChannel::All);
  EXPECT_EQ(controls.brush().mode, BrushMode::Smooth) << "a channel change picks an accepted mode";
  ArtistParams bad = controls.artist();
  bad.colour = glm::dvec3(1.5);
  EXPECT_NE(controls.setArtist(bad), "");
  EXPECT_EQ(controls.brush().channel, BrushChannel::All) << "a refused colour changes nothing";
  ArtistParams good = controls.artist();
  good.colour = glm::dvec3(0.5, 0.3, 0.1);
  EXPECT_EQ(controls.setArtist(good), "");
  EXPECT_EQ(controls.brush().channel, BrushChannel::Colour);
  EXPECT_EQ(controls.brush().artist.colour, good.colour);
  EXPECT_EQ(brushProblem(controls.brush()), "");
}

}  // namespace
}  // namespace sslpv
