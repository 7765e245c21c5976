#pragma once
// Smooth dielectric boundary: unpolarized Fresnel reflectance and Snell refraction.
#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace sslpv {

/// Fresnel reflectance for light arriving at cosThetaI (> 0) from the side of index 1
/// onto a medium of relative index eta (= n_inside / n_outside). Equal, by reciprocity,
/// to the reflectance of the refracted pair travelling the other way.
inline double fresnelReflectance(double cosThetaI, double eta) {
  if (eta == 1.0) return 0.0;
  cosThetaI = std::clamp(cosThetaI, 0.0, 1.0);
  const double sin2T = (1.0 - cosThetaI * cosThetaI) / (eta * eta);
  if (sin2T >= 1.0) return 1.0;
  const double cosT = std::sqrt(1.0 - sin2T);
  const double rs = (cosThetaI - eta * cosT) / (cosThetaI + eta * cosT);
  const double rp = (eta * cosThetaI - cosT) / (eta * cosThetaI + cosT);
  return 0.5 * (rs * rs + rp * rp);
}

/// Fresnel reflectance for light inside (index eta) arriving at cosInside (> 0) onto the
/// boundary: 1 beyond the critical angle, else the reflectance of its refracted pair.
inline double fresnelReflectanceFromInside(double cosInside, double eta) {
  const double sin2T = eta * eta * (1.0 - cosInside * cosInside);
  return sin2T >= 1.0 ? 1.0 : fresnelReflectance(std::sqrt(1.0 - sin2T), eta);
}

/// Direction of the ray refracted into a medium of relative index eta. `incident` is the
/// unit travel direction, `normal` the unit outward normal (incident . normal < 0).
inline glm::dvec3 refractInto(const glm::dvec3& incident, const glm::dvec3& normal, double eta) {
  const double cosI = -glm::dot(incident, normal);
  const double sin2T = (1.0 - cosI * cosI) / (eta * eta);
  const double cosT = std::sqrt(std::max(0.0, 1.0 - sin2T));
  return glm::normalize(incident / eta + (cosI / eta - cosT) * normal);
}

}  // namespace sslpv
