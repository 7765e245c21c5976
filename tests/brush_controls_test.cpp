// The editor's brush panel state (editor/brush_controls.h): whatever keys an artist
// presses, the brush handed to the engine stays usable, and each key does what the help
// overlay says.
#include <gtest/gtest.h>

#include <random>

#include "editor/brush_controls.h"
#include "volume/material.h"

namespace sslpv {
namespace {

MaterialSample base() {
  MaterialSample m;
  m.sigmaT = {1.0f, 2.0f, 4.0f};
  m.sigmaS = {0.5f, 1.0f, 3.0f};
  return m;
}

TEST(BrushControls, DefaultsComeFromTheScene) {
  const BrushControls controls(base(), 10.0, "mm");
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
    switch (rng() % 11) {
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
    }
    const Brush b = controls.brush();
    ASSERT_EQ(brushProblem(b), "") << "after " << i << " presses: " << controls.describe();
  }
}

TEST(BrushControls, ValuesAreRememberedPerChannelAndMode) {
  // A set target and a multiply factor are different numbers: switching mode and back
  // restores the first, and the value keys change only the current one.
  BrushControls controls(base(), 10.0, "mm");
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
  BrushControls controls(base(), 10.0, "mm");
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
  BrushControls controls(base(), 10.0, "mm");
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
  BrushControls controls(base(), 10.0, "mm");
  controls.cycleChannel(+1);
  controls.cycleChannel(+1);
  ASSERT_EQ(controls.brush().channel, BrushChannel::G);
  for (int i = 0; i < 100; ++i) controls.adjustValue(+1);
  EXPECT_DOUBLE_EQ(controls.brush().scalar, double(kBrushMaxG));
  for (int i = 0; i < 100; ++i) controls.adjustValue(-1);
  EXPECT_DOUBLE_EQ(controls.brush().scalar, -double(kBrushMaxG));
}

TEST(BrushControls, DescribeNamesWhatThePaintWillDo) {
  BrushControls controls(base(), 10.0, "mm");
  controls.cycleMirror();
  const std::string text = controls.describe();
  EXPECT_NE(text.find("sigma_t set [2 4 8] /mm"), std::string::npos) << text;
  EXPECT_NE(text.find("radius 0.8 mm"), std::string::npos) << text;
  EXPECT_NE(text.find("mirror x"), std::string::npos) << text;
}

}  // namespace
}  // namespace sslpv
