#pragma once
// L1 spherical harmonics on the CPU, with the constants shared with the shaders.
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "device_shared/lpv_constants.h"

namespace sslpv::sh {

inline constexpr float kY00 = float(SSLPV_SH_Y00);
inline constexpr float kY1 = float(SSLPV_SH_Y1);
inline constexpr float kLobeC0 = float(SSLPV_COSINE_LOBE_C0);
inline constexpr float kLobeC1 = float(SSLPV_COSINE_LOBE_C1);
inline constexpr float kPi = float(SSLPV_PI);
inline constexpr float kFluxPerC0 = float(SSLPV_FLUX_PER_C0);

/// Coefficients (c0, c1x, c1y, c1z) of one colour channel.
using Coeffs = glm::vec4;

/// The L1 reconstruction at unit direction w (may be negative: L1 rings).
inline float evaluate(const Coeffs& c, const glm::vec3& w) {
  return c.x * kY00 + kY1 * (c.y * w.x + c.z * w.y + c.w * w.z);
}

/// Projection of the clamped cosine lobe max(0, n.w), scaled by `scale`.
inline Coeffs cosineLobe(const glm::vec3& n, float scale) {
  return Coeffs(kLobeC0, kLobeC1 * n.x, kLobeC1 * n.y, kLobeC1 * n.z) * scale;
}

/// Projection of a direction delta scaled by `scale` (for the test of projection).
inline Coeffs directionDelta(const glm::vec3& w, float scale) {
  return Coeffs(kY00, kY1 * w.x, kY1 * w.y, kY1 * w.z) * scale;
}

/// Total power of a cell holding intensity c: the integral of c over the sphere.
inline float flux(const Coeffs& c) { return c.x * kFluxPerC0; }

/// Integral of the reconstruction over the hemisphere around unit n (no clamping).
inline float hemisphereIntegral(const Coeffs& c, const glm::vec3& n) {
  return float(SSLPV_HEMI_Y00) * c.x + float(SSLPV_HEMI_Y1) * (c.y * n.x + c.z * n.y + c.w * n.z);
}

}  // namespace sslpv::sh
