// The measured-material table (Jensen et al. 2001, as listed in docs/design.md §6.11) and the preset
// conversion sigma_s = sigma_s' / (1 - g), sigma_t = sigma_s + sigma_a, per scene unit.
#include <gtest/gtest.h>

#include <string>

#include "volume/scene/material.h"

namespace sslpv {
namespace {

const MeasuredMaterial& find(std::string_view name) {
  for (const auto& m : measuredMaterials())
    if (m.name == name) return m;
  throw std::runtime_error("no material " + std::string(name));
}

TEST(Material, TableHasTheElevenJensenMaterialsInOrder) {
  const char* expected[] = {"apple", "chicken1", "chicken2", "cream", "ketchup", "marble",
                            "potato", "skimmilk", "skin1", "skin2", "wholemilk"};
  ASSERT_EQ(measuredMaterials().size(), 11u);
  for (std::size_t i = 0; i < 11; ++i) EXPECT_EQ(measuredMaterials()[i].name, expected[i]);
}

TEST(Material, TableValuesMatchDesignDocument) {
  // Spot checks copied from docs/design.md §6.11 "Measured materials".
  const auto& skin1 = find("skin1");
  EXPECT_FLOAT_EQ(skin1.sigmaSPrime.r, 0.74f);
  EXPECT_FLOAT_EQ(skin1.sigmaSPrime.g, 0.88f);
  EXPECT_FLOAT_EQ(skin1.sigmaSPrime.b, 1.01f);
  EXPECT_FLOAT_EQ(skin1.sigmaA.r, 0.032f);
  EXPECT_FLOAT_EQ(skin1.sigmaA.g, 0.17f);
  EXPECT_FLOAT_EQ(skin1.sigmaA.b, 0.48f);

  const auto& ketchup = find("ketchup");
  EXPECT_FLOAT_EQ(ketchup.sigmaSPrime.g, 0.07f);
  EXPECT_FLOAT_EQ(ketchup.sigmaA.b, 1.45f);

  const auto& cream = find("cream");
  EXPECT_FLOAT_EQ(cream.sigmaSPrime.r, 7.38f);
  EXPECT_FLOAT_EQ(cream.sigmaA.r, 0.0002f);

  const auto& wholemilk = find("wholemilk");
  EXPECT_FLOAT_EQ(wholemilk.sigmaSPrime.b, 3.77f);
  EXPECT_FLOAT_EQ(wholemilk.sigmaA.g, 0.0024f);

  const auto& potato = find("potato");
  EXPECT_FLOAT_EQ(potato.sigmaA.b, 0.12f);
}

TEST(Material, MarbleIsTheOnlyMaterialWithEta15) {
  for (const auto& m : measuredMaterials()) {
    if (m.name == "marble")
      EXPECT_FLOAT_EQ(m.eta, 1.5f);
    else
      EXPECT_FLOAT_EQ(m.eta, 1.3f) << m.name;
  }
}

TEST(Material, EveryPresetHasPhysicalCoefficients) {
  for (const auto& m : measuredMaterials()) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_GT(m.sigmaSPrime[c], 0.0f) << m.name;
      EXPECT_GT(m.sigmaA[c], 0.0f) << m.name;
    }
  }
}

TEST(Material, PresetWithZeroGUsesReducedScatteringDirectly) {
  auto marble = presetMaterial("marble", 0.0f, 1.0);
  ASSERT_TRUE(marble.has_value());
  EXPECT_FLOAT_EQ(marble->g, 0.0f);
  EXPECT_FLOAT_EQ(marble->sigmaS.r, 2.19f);
  EXPECT_FLOAT_EQ(marble->sigmaS.g, 2.62f);
  EXPECT_FLOAT_EQ(marble->sigmaS.b, 3.00f);
  EXPECT_FLOAT_EQ(marble->sigmaT.r, 2.19f + 0.0021f);
  EXPECT_FLOAT_EQ(marble->sigmaT.g, 2.62f + 0.0041f);
  EXPECT_FLOAT_EQ(marble->sigmaT.b, 3.00f + 0.0071f);
}

TEST(Material, PresetWithForwardScatteringKeepsReducedScatteringFixed) {
  // sigma_s (1 - g) must reproduce the measured sigma_s'; absorption is unchanged.
  const float g = 0.8f;
  auto skin = presetMaterial("skin1", g, 1.0);
  ASSERT_TRUE(skin.has_value());
  EXPECT_FLOAT_EQ(skin->g, g);
  EXPECT_NEAR(skin->sigmaS.r, 0.74 / 0.2, 1e-5);
  EXPECT_NEAR(skin->sigmaS.b, 1.01 / 0.2, 1e-5);
  EXPECT_NEAR(skin->sigmaS.g * (1.0f - g), 0.88f, 1e-5);
  EXPECT_NEAR(skin->sigmaT.r - skin->sigmaS.r, 0.032f, 1e-5);
  EXPECT_NEAR(skin->sigmaT.b - skin->sigmaS.b, 0.48f, 1e-5);
}

TEST(Material, PresetWithBackwardScatteringShrinksSigmaS) {
  auto apple = presetMaterial("apple", -0.5f, 1.0);
  ASSERT_TRUE(apple.has_value());
  EXPECT_NEAR(apple->sigmaS.g, 2.39 / 1.5, 1e-5);
}

TEST(Material, PresetScalesWithSceneUnit) {
  // 1 cm holds 10 mean free paths where 1 mm holds one: coefficients per cm are 10x.
  auto perMm = presetMaterial("ketchup", 0.0f, 1.0);
  auto perCm = presetMaterial("ketchup", 0.0f, 10.0);
  auto perInch = presetMaterial("ketchup", 0.3f, 25.4);
  ASSERT_TRUE(perMm && perCm && perInch);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(perCm->sigmaT[c], 10.0f * perMm->sigmaT[c], 1e-5f * perCm->sigmaT[c]);
    EXPECT_NEAR(perCm->sigmaS[c], 10.0f * perMm->sigmaS[c], 1e-5f * perCm->sigmaS[c]);
  }
  EXPECT_NEAR(perInch->sigmaS.r, 0.18 / 0.7 * 25.4, 1e-4);
  EXPECT_NEAR(perInch->sigmaT.g - perInch->sigmaS.g, 0.97 * 25.4, 1e-4);
}

TEST(Material, AlbedoOfPresetsStaysBelowOne) {
  for (float g : {-0.9f, 0.0f, 0.5f, 0.99f}) {
    for (const auto& m : measuredMaterials()) {
      auto sample = presetMaterial(m.name, g, 1.0);
      ASSERT_TRUE(sample);
      for (int c = 0; c < 3; ++c) {
        EXPECT_LE(sample->sigmaS[c], sample->sigmaT[c]) << m.name << " g=" << g;
        EXPECT_GT(sample->sigmaT[c] - sample->sigmaS[c], 0.0f) << m.name << " g=" << g;
      }
    }
  }
}

TEST(Material, UnknownPresetIsNullopt) {
  EXPECT_FALSE(presetMaterial("jade", 0.0f, 1.0).has_value());
  EXPECT_FALSE(presetMaterial("", 0.0f, 1.0).has_value());
  EXPECT_FALSE(presetMaterial("Marble", 0.0f, 1.0).has_value());  // names are case-sensitive
}

TEST(Material, PresetNamesListsEveryMaterial) {
  std::string names = presetNames();
  EXPECT_EQ(names.rfind("apple, chicken1, ", 0), 0u) << names;
  for (const auto& m : measuredMaterials())
    EXPECT_NE(names.find(std::string(m.name)), std::string::npos) << m.name;
  EXPECT_EQ(names.substr(names.size() - 9), "wholemilk");
}

TEST(Material, UnitsConvertToMillimetres) {
  EXPECT_EQ(unitInMm("mm"), 1.0);
  EXPECT_EQ(unitInMm("cm"), 10.0);
  EXPECT_EQ(unitInMm("m"), 1000.0);
  EXPECT_EQ(unitInMm("in"), 25.4);
  EXPECT_FALSE(unitInMm("ft").has_value());
  EXPECT_FALSE(unitInMm("MM").has_value());
  EXPECT_FALSE(unitInMm("").has_value());
}

}  // namespace
}  // namespace sslpv
