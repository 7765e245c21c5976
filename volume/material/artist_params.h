#pragma once
// Artist parameters: a material described as what it looks like rather than by its
// coefficients. Per channel:
//
//   surface colour C  the total diffuse reflectance Rd a thick slab of the material shows
//                     under light along its normal (specular reflection excluded), behind
//                     the scene's smooth boundary of relative index η; linear, not sRGB;
//   scatter distance d the transport mean free path 1 / σt' = 1 / (σa + σs (1 - g)), in
//                     scene units;
//   g                 the Henyey-Greenstein asymmetry (one for all channels, as the grids
//                     store it).
//
// Rd depends on the medium only through the reduced albedo α' = σs (1 - g) / σt' (the
// similarity relation the calibrated scheme and the boundary table already rely on), so
// C fixes α' by inverting boundaryReflectance(α', η) (volume/calibration/lpv_calibration.h: the
// adding-doubling Rd table), and d fixes the scale. The reduced distance, not 1 / σt, is
// what makes g an independent "advanced" control: changing g at fixed C and d keeps a
// thick object's colour and how far light bleeds (both set by α' and σt'), and only
// reshapes the single scattering. Then
//
//   σt' = 1 / d,  σa = (1 - α') / d,  σs = α' / (d (1 - g)),  σt = σa + σs.
//
// C can be any value in [0, Cmax(η)], Cmax = Rd(α' = 1) = 1 - F(0) (a medium that does not
// absorb returns all that enters it): 1 at η = 1, 0.980 at η = 1.33, 0.960 at η = 1.5.
// C = 0 is a pure absorber (σs = 0). A brighter colour would need light created inside,
// so it is refused, as are negative or non-finite colours, a distance that is not positive
// and finite and |g| > 0.99.
#include <glm/vec3.hpp>
#include <string>

#include "volume/scene/material.h"

namespace sslpv {

struct ArtistParams {
  glm::dvec3 colour{0.5};           ///< surface colour per channel (linear diffuse reflectance)
  glm::dvec3 scatterDistance{1.0};  ///< transport mean free path per channel, scene units
  double g = 0.0;                   ///< phase asymmetry
};

/// Largest |g| the artist mapping accepts (the brush's limit too).
inline constexpr double kArtistMaxG = 0.99;

/// Smallest scatter distance accepted: σs = α' / (d (1 - g)) then fits a float at |g| = 0.99.
inline constexpr double kMinScatterDistance = 1e-36;

/// Cmax(η) = 1 - F(0): the brightest surface colour a medium behind a smooth boundary of
/// relative index `ior` shows. Throws std::invalid_argument unless ior is positive and finite.
double maxSurfaceColour(double ior);

/// The reduced albedo α' in [0, 1] whose boundaryReflectance(α', ior) is `colour`, by
/// bisection (Rd grows with α'); 0 for colour 0 and 1 for Cmax exactly. Throws InputError
/// for a colour outside [0, Cmax(ior)] (message names the value and the bound).
double reducedAlbedoForColour(double colour, double ior);

/// What is wrong with `params` at this ior ("colour[1]: ...", "scatter_distance[0]: ...",
/// "g: ..."), each naming the value; "" when the mapping accepts them.
std::string artistParamsProblem(const ArtistParams& params, double ior);

/// σt, σs (per scene unit) and g for the artist parameters. Throws InputError with
/// artistParamsProblem's message when they are not accepted.
MaterialSample artistToPhysical(const ArtistParams& params, double ior);

/// The reverse view, for display: per channel C = boundaryReflectance(α', ior) and
/// d = 1 / σt' (infinite where σt' = 0, where C is 0). σs above σt counts as σt (the
/// brush's clamp). g is copied.
ArtistParams physicalToArtist(const MaterialSample& material, double ior);

}  // namespace sslpv
