// The L1 SH face-flux transfer of one LPV step, the GLSL twin of volume/cpu/propagate.cpp: the
// renormalized clamp of a source cell and the light it sends through the 5 faces of each
// of its 6 neighbours, re-emitted there as cosine lobes. One vec4 holds one channel's
// coefficients (c0, c1x, c1y, c1z).
//
// The CPU normalizes a source (scale = power / clamped face flux, never negative) and then
// evaluates the clamped faces again from the scaled coefficients for each neighbour. As
// max(0, s u) = s max(0, u) for s >= 0, the GPU evaluates the 30 clamped faces once, sums
// them for the scale, and forms all 6 outgoing lobes from the same values: the same light
// (up to float rounding) for about half the arithmetic.
#ifndef SSLPV_LPV_TRANSFER_GLSL
#define SSLPV_LPV_TRANSFER_GLSL

const float kY00 = float(SSLPV_SH_Y00);
const float kY1 = float(SSLPV_SH_Y1);
const float kFront = float(SSLPV_FRONT_FACE_SOLID_ANGLE);
const float kSide = float(SSLPV_SIDE_FACE_SOLID_ANGLE);
const float kFluxPerC0 = float(SSLPV_FLUX_PER_C0);
// Side faces are evaluated in the direction of their centres, (e_a ± 0.5 e_b)/sqrt(1.25).
const float kSideNorm = 0.89442719099991588;  // 1/sqrt(1.25)
const float kHalfY1SideNorm = 0.5 * float(SSLPV_SH_Y1) * kSideNorm;
// Re-emission as a cosine lobe of power Φ: (Φ/π)(C0, C1 n).
const float kEmitDC = float(SSLPV_COSINE_LOBE_C0) / float(SSLPV_PI);
const float kEmitLinear = float(SSLPV_COSINE_LOBE_C1) / float(SSLPV_PI);

/// Directions of travel, the index of Lobes::toward.
const int PLUS_X = 0, MINUS_X = 1, PLUS_Y = 2, MINUS_Y = 3, PLUS_Z = 4, MINUS_Z = 5;

/// What one channel of a source cell sends to each neighbour (toward[d] goes to the
/// neighbour in direction d), in that neighbour's (c0, c1x, c1y, c1z).
struct Lobes {
  vec4 toward[6];
};

/// Normalizes one channel `c` of a source cell (normalizeEmission on the CPU) and returns
/// the lobes it sends, times the cell's `conductance` (StepFactors::conductance; 1 where
/// D is uniform). Adds the power it holds and the excess the clamp would have created.
Lobes emitChannel(vec4 c, float conductance, inout float emitted, inout float clampRemoved) {
  const float base = c.x * kY00;
  float total = 0.0;
  vec4 axisFrame[6];  // (dc, along the axis, along b1, along b2), unscaled
  for (int a = 0; a < 3; ++a) {
    const float ca = c[1 + a];
    const float h1 = kHalfY1SideNorm * c[1 + (a + 1) % 3];
    const float h2 = kHalfY1SideNorm * c[1 + (a + 2) % 3];
    for (int k = 0; k < 2; ++k) {
      const float sd = k == 0 ? -1.0 : 1.0;  // the CPU's order: -e_a, then +e_a
      const float along = sd * kY1 * ca;
      const float front = max(0.0, base + along);
      const float alongSide = base + along * kSideNorm;
      const float s1p = max(0.0, alongSide + h1), s1m = max(0.0, alongSide - h1);
      const float s2p = max(0.0, alongSide + h2), s2m = max(0.0, alongSide - h2);
      const float sides = s1p + s1m + s2p + s2m;
      total += kFront * front;
      total += kSide * sides;
      axisFrame[2 * a + 1 - k] = vec4(kEmitDC * (kFront * front + kSide * sides), sd * (kEmitLinear * kFront) * front,
                                      (kEmitLinear * kSide) * (s1p - s1m), (kEmitLinear * kSide) * (s2p - s2m));
    }
  }
  // A cell driven below zero (a boundary whose retention is negative drains it) emits
  // nothing, and what its lobe would have sent counts as removed, as on the CPU.
  const float power = max(0.0, c.x * kFluxPerC0);
  const float raw = total;
  const float scale = (raw > 0.0 ? power / raw : 0.0) * conductance;
  emitted += power;
  clampRemoved += max(0.0, raw - power);
  // Back to (c0, x, y, z): along x, b1 = y and b2 = z; along y, b1 = z and b2 = x; along
  // z, b1 = x and b2 = y.
  Lobes lobes;
  for (int k = 0; k < 2; ++k) {
    const vec4 tx = axisFrame[k], ty = axisFrame[2 + k], tz = axisFrame[4 + k];
    lobes.toward[k] = scale * tx;
    lobes.toward[2 + k] = scale * vec4(ty.x, ty.w, ty.y, ty.z);
    lobes.toward[4 + k] = scale * vec4(tz.x, tz.z, tz.w, tz.y);
  }
  return lobes;
}

/// emitChannel for a cell without linear band under a scheme whose steps keep it so (the
/// calibrated one, after its first step): every lobe is the same and no face clamps, so
/// each neighbour gets kIsotropicShare of the cell's c0 (a cell driven below zero sends
/// nothing, unless `linear`: the Chebyshev iterates, chebyshevSlice on the CPU).
/// gatherSliceIsotropic on the CPU. The clamp removes nothing.
const float kIsotropicShare = float(SSLPV_ISOTROPIC_NEIGHBOUR_SHARE);
Lobes emitIsotropicChannel(vec4 c, float conductance, bool linear, inout float emitted) {
  const float light = linear ? c.x : max(0.0, c.x);
  emitted += light * kFluxPerC0;
  const vec4 lobe = vec4(kIsotropicShare * conductance * light, 0.0, 0.0, 0.0);
  Lobes lobes;
  for (int d = 0; d < 6; ++d) lobes.toward[d] = lobe;
  return lobes;
}

#endif
