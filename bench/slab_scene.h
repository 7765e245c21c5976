#pragma once
// Shared by the slab benchmarks: a box of one measured material with nothing else in the
// scene yet, the calibrated settings they render with, and their command-line flags.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "volume/calibration/adding_doubling.h"
#include "volume/scene/material.h"
#include "volume/scene/scene.h"

namespace sslpv::bench {

/// A box (mm) of `material` as the similarity relation's isotropic medium (σt = σs' + σa,
/// σs = σs', g = 0), relative index `ior`; lights and camera are the caller's.
inline Scene materialBox(const MeasuredMaterial& material, double ior, const glm::dvec3& boxMin,
                         const glm::dvec3& boxMax) {
  Scene scene;
  scene.units = "mm";
  scene.mesh.kind = MeshSource::Kind::Box;
  scene.mesh.boxMin = boxMin;
  scene.mesh.boxMax = boxMax;
  scene.material.base.sigmaT = material.sigmaSPrime + material.sigmaA;
  scene.material.base.sigmaS = material.sigmaSPrime;
  scene.material.base.g = 0.0f;
  scene.material.ior = ior;
  return scene;
}

/// The calibrated scheme at `grid` cells along the longest axis, propagated to convergence.
inline LpvSettings calibratedAuto(int grid) {
  LpvSettings settings;
  settings.resolution = grid;
  settings.autoSteps = true;
  settings.scheme = LpvScheme::Calibrated;
  return settings;
}

/// "a,b,c" -> {"a", "b", "c"}.
inline std::vector<std::string> splitNames(const char* list) {
  std::vector<std::string> names;
  std::stringstream in(list);
  for (std::string name; std::getline(in, name, ',');) names.push_back(name);
  return names;
}

/// Half the width of backlitSlab's slab, mm.
inline constexpr double kBacklitHalfWidth = 30.0;

/// A slab 60 x 60 mm wide and `thickness` mm thick, lit from above by a directional light
/// of unit irradiance along its normal and seen from below: a 3-degree, 32 x 32 view of
/// its unlit face's middle along the normal (bench/slab_transmission).
inline Scene backlitSlab(const MeasuredMaterial& material, double thickness) {
  Scene scene = materialBox(material, material.eta, glm::dvec3(-kBacklitHalfWidth, -thickness, -kBacklitHalfWidth),
                            glm::dvec3(kBacklitHalfWidth, 0.0, kBacklitHalfWidth));
  Light light;
  light.type = Light::Type::Directional;
  light.direction = glm::dvec3(0.0, -1.0, 0.0);
  light.irradiance = glm::vec3(1.0f);
  scene.lights = {light};
  scene.camera.position = glm::dvec3(0.0, -thickness - 200.0, 0.0);
  scene.camera.target = glm::dvec3(0.0, -thickness, 0.0);
  scene.camera.up = glm::dvec3(0.0, 0.0, 1.0);
  scene.camera.fovYDeg = 3.0;
  scene.camera.width = scene.camera.height = 32;
  return scene;
}

/// π L / E of the light a laterally infinite slab of `material`, `thickness` mm thick,
/// transmits in one channel, outside, along the normal, exactly (adding-doubling on the
/// similarity relation's medium, as materialBox): the solution's node nearest the normal
/// (its cosine is above 0.99 with 16 nodes; the exit shape is flat there).
inline double exactNormalTransmission(const MeasuredMaterial& material, int channel, double thickness) {
  const double reducedT = material.sigmaSPrime[channel] + material.sigmaA[channel];
  const double eta = material.eta;
  const SlabTransport slab = addingDoublingSlab(material.sigmaSPrime[channel] / reducedT, eta, reducedT * thickness);
  const std::size_t i = std::size_t(std::max_element(slab.mu.begin(), slab.mu.end()) - slab.mu.begin());
  return slab.transmittedFlux[i] / (2.0 * slab.weight[i] * slab.mu[i] * eta * eta);
}

/// The materials of `available` that `names` asks for, in `available`'s order. A name
/// none of them has prints a one-line reason naming it and makes `ok` false.
inline std::vector<MeasuredMaterial> pickMaterials(const std::vector<MeasuredMaterial>& available,
                                                   const std::vector<std::string>& names, const char* program,
                                                   bool& ok) {
  ok = true;
  for (const std::string& name : names)
    if (std::none_of(available.begin(), available.end(),
                     [&](const MeasuredMaterial& m) { return name == std::string(m.name); })) {
      std::string known;
      for (const MeasuredMaterial& m : available) known += (known.empty() ? "" : ",") + std::string(m.name);
      std::fprintf(stderr, "%s: unknown material '%s' (known: %s)\n", program, name.c_str(), known.c_str());
      ok = false;
    }
  std::vector<MeasuredMaterial> picked;
  for (const MeasuredMaterial& m : available)
    if (std::find(names.begin(), names.end(), std::string(m.name)) != names.end()) picked.push_back(m);
  return picked;
}

/// "--name value" pairs, each flag taking one value; anything else, or a flag the program
/// does not know, prints `usage` and makes ok() false.
class Flags {
 public:
  Flags(int argc, char** argv, std::vector<std::string> known, const char* usage) {
    for (int i = 1; i < argc; ++i) {
      const std::string flag = argv[i];
      bool isKnown = false;
      for (const std::string& k : known) isKnown = isKnown || flag == "--" + k;
      if (!isKnown || i + 1 >= argc) {
        std::fprintf(stderr, "usage: %s\n", usage);
        ok_ = false;
        return;
      }
      values_[flag.substr(2)] = argv[++i];
    }
  }
  bool ok() const { return ok_; }
  int integer(const std::string& name, int fallback) const {
    const auto it = values_.find(name);
    return it == values_.end() ? fallback : std::atoi(it->second.c_str());
  }
  std::vector<std::string> names(const std::string& name, std::vector<std::string> fallback) const {
    const auto it = values_.find(name);
    return it == values_.end() ? fallback : splitNames(it->second.c_str());
  }
  std::string text(const std::string& name, const std::string& fallback) const {
    const auto it = values_.find(name);
    return it == values_.end() ? fallback : it->second;
  }

 private:
  std::map<std::string, std::string> values_;
  bool ok_ = true;
};

}  // namespace sslpv::bench
