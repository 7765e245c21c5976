// The L1 SH face-flux transfer of one LPV step, the GLSL twin of volume/propagate.cpp:
// the renormalized clamp of a source cell and the light it sends through the 5 faces of
// one neighbour, re-emitted as cosine lobes. One vec4 holds one channel's coefficients
// (c0, c1x, c1y, c1z).
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

/// Sum of Δω_f · max(0, I(ω_f)) over the 30 faces a cell sends light through.
float clampedFaceFlux(vec4 c) {
  const float base = c.x * kY00;
  float total = 0.0;
  for (int a = 0; a < 3; ++a) {
    const float ca = c[1 + a];
    const float h1 = kHalfY1SideNorm * c[1 + (a + 1) % 3];
    const float h2 = kHalfY1SideNorm * c[1 + (a + 2) % 3];
    for (int sd = -1; sd <= 1; sd += 2) {
      const float along = float(sd) * kY1 * ca;
      total += kFront * max(0.0, base + along);
      const float alongSide = along * kSideNorm;
      total += kSide * (max(0.0, base + alongSide + h1) + max(0.0, base + alongSide - h1) +
                        max(0.0, base + alongSide + h2) + max(0.0, base + alongSide - h2));
    }
  }
  return total;
}

/// Rescales one channel so its clamped face fluxes add up to exactly the power it holds
/// (without it the clamp creates energy). Adds the held power and the removed excess.
vec4 normalizeEmission(vec4 c, inout float emitted, inout float clampRemoved) {
  const float power = c.x * kFluxPerC0;
  const float raw = power > 0.0 ? clampedFaceFlux(c) : 0.0;
  const float scale = raw > 0.0 ? power / raw : 0.0;
  emitted += max(0.0, power);
  clampRemoved += max(0.0, raw - power);
  return c * scale;
}

/// Light a source channel (c0, c along the axis a, along b1, along b2) sends along sd*e_a
/// into its neighbour, re-emitted there as cosine lobes; returned in the same axis frame
/// (dc, along a, along b1, along b2), with b1 = (a+1)%3 and b2 = (a+2)%3.
vec4 faceTransfer(float c0, float ca, float cb1, float cb2, float sd) {
  const float base = c0 * kY00;
  const float along = sd * kY1 * ca;
  const float front = max(0.0, base + along);
  const float alongSide = base + along * kSideNorm;
  const float h1 = kHalfY1SideNorm * cb1;
  const float h2 = kHalfY1SideNorm * cb2;
  const float s1p = max(0.0, alongSide + h1), s1m = max(0.0, alongSide - h1);
  const float s2p = max(0.0, alongSide + h2), s2m = max(0.0, alongSide - h2);
  return vec4(kEmitDC * (kFront * front + kSide * (s1p + s1m + s2p + s2m)),
              sd * kEmitLinear * kFront * front,
              kEmitLinear * kSide * (s1p - s1m),
              kEmitLinear * kSide * (s2p - s2m));
}

/// Transfer from a source along ±x (axis frame x, y, z).
vec4 transferX(vec4 s, float sd) { return faceTransfer(s.x, s.y, s.z, s.w, sd); }
/// Along ±y: b1 = z, b2 = x.
vec4 transferY(vec4 s, float sd) {
  const vec4 t = faceTransfer(s.x, s.z, s.w, s.y, sd);
  return vec4(t.x, t.w, t.y, t.z);
}
/// Along ±z: b1 = x, b2 = y.
vec4 transferZ(vec4 s, float sd) {
  const vec4 t = faceTransfer(s.x, s.w, s.y, s.z, sd);
  return vec4(t.x, t.z, t.w, t.y);
}

#endif
