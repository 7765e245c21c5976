#pragma once
// The homogeneous material model and the table of measured presets (Jensen et al. 2001).
#include <glm/vec3.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace sslpv {

/// Optical properties at one point. sigmaT and sigmaS are per scene unit, per RGB channel.
struct MaterialSample {
  glm::vec3 sigmaT{0.0f};
  glm::vec3 sigmaS{0.0f};
  float g = 0.0f;  ///< Henyey-Greenstein asymmetry, |g| < 1
};

/// One measured material: reduced scattering and absorption in mm^-1, RGB, and its
/// relative index of refraction.
struct MeasuredMaterial {
  std::string_view name;
  glm::vec3 sigmaSPrime;
  glm::vec3 sigmaA;
  float eta;
};

/// Jensen 2001's eleven measured materials, in table order.
const std::vector<MeasuredMaterial>& measuredMaterials();

/// The measured material of that name, nullptr when there is none.
const MeasuredMaterial* findMeasuredMaterial(std::string_view name);

/// The preset's MaterialSample for asymmetry g (sigma_s = sigma_s' / (1 - g)), converted
/// from mm^-1 to per scene unit (`sceneUnitInMm` millimetres per scene unit).
/// std::nullopt when the name is unknown.
std::optional<MaterialSample> presetMaterial(std::string_view name, float g, double sceneUnitInMm);

/// "apple, chicken1, ..." for error messages.
std::string presetNames();

/// Millimetres per unit for the scene's "units" key (mm, cm, m, in); nullopt if unknown.
std::optional<double> unitInMm(std::string_view units);

}  // namespace sslpv
