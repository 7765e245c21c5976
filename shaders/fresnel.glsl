// GLSL twin of volume/core/fresnel.h (smooth dielectric boundary), line for line in float.
// tests/gpu/gpu_shadow_map_test.cpp compares both over incidence angles and indices through
// shaders/fresnel_probe.comp.
#ifndef SSLPV_FRESNEL_GLSL
#define SSLPV_FRESNEL_GLSL

/// Unpolarized Fresnel reflectance for light arriving at cosThetaI (> 0) from the side
/// of index 1 onto a medium of relative index eta (= n_inside / n_outside); equal, by
/// reciprocity, to that of the refracted pair travelling the other way.
float fresnelReflectance(float cosThetaI, float eta) {
  if (eta == 1.0) return 0.0;
  cosThetaI = clamp(cosThetaI, 0.0, 1.0);
  const float sin2T = (1.0 - cosThetaI * cosThetaI) / (eta * eta);
  if (sin2T >= 1.0) return 1.0;
  const float cosT = sqrt(1.0 - sin2T);
  const float rs = (cosThetaI - eta * cosT) / (cosThetaI + eta * cosT);
  const float rp = (eta * cosThetaI - cosT) / (eta * cosThetaI + cosT);
  return 0.5 * (rs * rs + rp * rp);
}

/// Direction of the ray refracted into a medium of relative index eta: `incident` is the
/// unit travel direction, `normal` the unit outward normal (dot(incident, normal) < 0).
vec3 refractInto(vec3 incident, vec3 normal, float eta) {
  const float cosI = -dot(incident, normal);
  const float sin2T = (1.0 - cosI * cosI) / (eta * eta);
  const float cosT = sqrt(max(0.0, 1.0 - sin2T));
  return normalize(incident / eta + (cosI / eta - cosT) * normal);
}

#endif
