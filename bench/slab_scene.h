#pragma once
// Shared by the slab benchmarks: a box of one measured material with nothing else in the
// scene yet, the calibrated settings they render with, and their command-line flags.
#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "volume/material.h"
#include "volume/scene.h"

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
