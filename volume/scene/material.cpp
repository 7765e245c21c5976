#include "volume/scene/material.h"

#include <array>
#include <utility>

namespace sslpv {

const std::vector<MeasuredMaterial>& measuredMaterials() {
  // Jensen, Marschner, Levoy, Hanrahan 2001, "A Practical Model for Subsurface Light
  // Transport", Figure 5: reduced scattering sigma_s' and absorption sigma_a in mm^-1 (RGB),
  // relative index of refraction 1.3 for all but marble (1.5).
  static const std::vector<MeasuredMaterial> table = {
      {"apple", {2.29f, 2.39f, 1.97f}, {0.0030f, 0.0034f, 0.046f}, 1.3f},
      {"chicken1", {0.15f, 0.21f, 0.38f}, {0.015f, 0.077f, 0.19f}, 1.3f},
      {"chicken2", {0.19f, 0.25f, 0.32f}, {0.018f, 0.088f, 0.20f}, 1.3f},
      {"cream", {7.38f, 5.47f, 3.15f}, {0.0002f, 0.0028f, 0.0163f}, 1.3f},
      {"ketchup", {0.18f, 0.07f, 0.03f}, {0.061f, 0.97f, 1.45f}, 1.3f},
      {"marble", {2.19f, 2.62f, 3.00f}, {0.0021f, 0.0041f, 0.0071f}, 1.5f},
      {"potato", {0.68f, 0.70f, 0.55f}, {0.0024f, 0.0090f, 0.12f}, 1.3f},
      {"skimmilk", {0.70f, 1.22f, 1.90f}, {0.0014f, 0.0025f, 0.0142f}, 1.3f},
      {"skin1", {0.74f, 0.88f, 1.01f}, {0.032f, 0.17f, 0.48f}, 1.3f},
      {"skin2", {1.09f, 1.59f, 1.79f}, {0.013f, 0.070f, 0.145f}, 1.3f},
      {"wholemilk", {2.55f, 3.21f, 3.77f}, {0.0011f, 0.0024f, 0.014f}, 1.3f},
  };
  return table;
}

const MeasuredMaterial* findMeasuredMaterial(std::string_view name) {
  for (const MeasuredMaterial& m : measuredMaterials())
    if (m.name == name) return &m;
  return nullptr;
}

std::optional<MaterialSample> presetMaterial(std::string_view name, float g,
                                             double sceneUnitInMm) {
  const MeasuredMaterial* m = findMeasuredMaterial(name);
  if (m == nullptr) return std::nullopt;
  // The measurement only fixes the reduced coefficient sigma_s' = sigma_s (1 - g): for a
  // chosen g, the similarity relation gives the sigma_s with the same diffusion behaviour.
  // Computed in double so that a g close to 1 does not lose the small sigma_a.
  MaterialSample sample;
  sample.g = g;
  for (int c = 0; c < 3; ++c) {
    double sigmaS = double(m->sigmaSPrime[c]) / (1.0 - double(g)) * sceneUnitInMm;
    double sigmaA = double(m->sigmaA[c]) * sceneUnitInMm;
    sample.sigmaS[c] = float(sigmaS);
    sample.sigmaT[c] = float(sigmaS + sigmaA);
  }
  return sample;
}

std::string presetNames() {
  std::string names;
  for (const MeasuredMaterial& m : measuredMaterials()) {
    if (!names.empty()) names += ", ";
    names += m.name;
  }
  return names;
}

std::optional<double> unitInMm(std::string_view units) {
  static const std::array<std::pair<std::string_view, double>, 4> kUnits = {{
      {"mm", 1.0},
      {"cm", 10.0},
      {"m", 1000.0},
      {"in", 25.4},
  }};
  for (const auto& [unitName, millimetres] : kUnits)
    if (unitName == units) return millimetres;
  return std::nullopt;
}

}  // namespace sslpv
