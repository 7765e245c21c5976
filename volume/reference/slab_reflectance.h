#pragma once
// Total diffuse reflectance Rd of a thick homogeneous slab under broad normal
// illumination, measured with the reference path tracer, and the closed forms it is
// judged against (docs/design.md §7): the check that the path tracer agrees with exact
// transport (adding-doubling, which the calibrated scheme targets) and with the dipole.
#include <cstdint>
#include <glm/vec3.hpp>

#include "volume/scene/material.h"

namespace sslpv {

struct SlabReflectanceOptions {
  int samples = 1 << 16;  ///< camera paths per channel
  /// Random streams are (seed, channel, sample): two calls with one seed reuse the same
  /// numbers, so their errors are correlated (good for differences between similar
  /// materials, bad when independent errors are wanted: then give each call its own seed).
  std::uint64_t seed = 0;
  int threads = 0;  ///< 0: TBB's default
  /// Slab depth and half-width in units of max(1/σtr, 1/σt'), σtr = sqrt(3 σa σt') the
  /// diffusion attenuation. Reflectance lost through the bottom and the sides falls
  /// off about as exp(-size): 12 leaves ~1e-5 of Rd, below any standard error reached.
  double size = 12.0;
  /// Scattering events after which a path ends (ReferenceOptions::maxScatterEvents).
  int maxScatterEvents = 0;
};

struct SlabReflectance {
  glm::dvec3 rd{0.0};             ///< diffuse reflectance per channel (specular surface reflection excluded)
  glm::dvec3 standardError{0.0};  ///< of rd
  glm::dvec3 slabSize{0.0};       ///< depth = half-width used per channel, in the material's units
  double seconds = 0.0;
};

/// Rd per channel of a slab of `material` (σ per unit length; one unit = one length unit
/// of the result) with relative index `ior`, lit by a directional light along the slab
/// normal. Rd = π E[L] / E with exitant radiance L sampled by the reference tracer
/// along cosine-distributed directions from a point just above the centre of the top
/// face (a cosine-weighted estimate of the exitant flux). Channels with σt = 0 give 0.
/// Deterministic for a seed whatever the thread count.
///
/// Exact for any ior here: the light arrives along the normal of a flat face, so the
/// tracer's light connection through the flat face (reference_tracer.h) is a straight
/// line, with transmittance 1 - F(0), and the only light it misses is the unscattered
/// beam reflected at the bottom face, attenuated by exp(-σt·depth) ~ exp(-12) or less.
/// Camera paths handle refraction and internal reflection exactly.
SlabReflectance estimateSlabReflectance(const MaterialSample& material, double ior,
                                        const SlabReflectanceOptions& options = {});

/// Jensen et al. 2001 dipole total diffuse reflectance Rd(α') with A = (1+Fdr)/(1-Fdr),
/// Fdr = -1.440/η² + 0.710/η + 0.668 + 0.0636η (Egan and Hilgeman's fit, as Jensen et al. use it).
double dipoleRd(double albedoPrime, double eta);

/// Chandrasekhar's H-function for isotropic scattering with single-scattering albedo
/// `albedo` in [0, 1], at direction cosine mu in [0, 1].
double chandrasekharH(double mu, double albedo);

/// Exact diffuse reflectance of a semi-infinite, index-matched, isotropically scattering
/// half-space under collimated normal incidence: 1 - H(1; α)·sqrt(1 - α) (Chandrasekhar,
/// Radiative Transfer, 1950: the plane albedo of a semi-infinite atmosphere).
double exactIsotropicRd(double albedo);

}  // namespace sslpv
