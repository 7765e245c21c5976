#pragma once
// Shared by the slab benchmarks: a box of one measured material with nothing else in the
// scene yet, the calibrated settings they render with, and their --materials lists.
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

}  // namespace sslpv::bench
