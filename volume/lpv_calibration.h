#pragma once
// Calibrated SSLPV transport (issue 4): per-step coefficients derived so that the LPV's
// lattice walk has the medium's diffusion length, plus a surface coupling gain so that
// a thick slab's diffuse reflectance matches radiative transport.
//
// Why: with the seed's per-step factors (extinction e = exp(-σt Δx), then HG scattering),
// one LPV step redirects light about as much as one scattering event whatever the cell
// size, so how far light spreads is fixed by the grid, not the medium (DESIGN.md
// "Measured: why SSLPV needs calibration"). The calibrated scheme instead:
//
//  1. Resets the linear band every step (light in a cell is re-emitted isotropically),
//     which makes propagation an exact lattice random walk: from a laterally uniform
//     layer, 1/6 of a step's power moves up, 1/6 down and 4/6 stays in the layer.
//  2. Picks the DC survival s per step so that the walk decays with depth exactly as
//     diffusion in the medium does, exp(-σtr z), σtr = sqrt(3 σa σt') with the reduced
//     σt' = σa + σs(1 - g): the walk's steady state decays as r^n per layer with
//     r + 1/r = 6/s - 4, so s = 3 / (2 + cosh(σtr Δx)). This holds for any cell size
//     relative to the mean free path; g enters through σt' (similarity relation).
//  3. Scales the exitant radiance by a coupling gain G: the walk has the right diffusion
//     length but couples to the boundary over a cell instead of over a transport mean
//     free path. For a semi-infinite layer under normal illumination the lattice's shaded
//     reflectance is, in closed form (derivation in lpv_calibration.cpp),
//        R_lpv = 3 r (f_lat + r f_down),  r = exp(-σtr Δx),
//     where f_lat and f_down are the fractions of an injected cosine lobe that the first
//     step keeps in its layer and sends one layer deeper. G makes the power the lattice
//     reflects equal the medium's total diffuse reflectance Rd(α', η) under collimated
//     normal incidence: exact transport in an isotropically scattering half-space (reduced
//     albedo α', similarity relation) behind a smooth boundary of relative index η, from
//     the adding-doubling method (adding_doubling.h). At η = 1 that is
//     1 - H(1; α')·sqrt(1 - α') (Chandrasekhar's H-function). With a boundary, the
//     injection's entry transmittance 1 - F(0) and the shading's exit transmittance of an
//     isotropic cell (diffuseBoundaryTransmittance) are divided out:
//        G = Rd(α', η) / ((1 - F(0)) · T_exit(η) · R_lpv).
//     So the reflected power is exact for a thick slab.
//  4. Gives that power the medium's angular distribution instead of the lattice's
//     (Lambertian inside, Fresnel-weighted outside): the shading weights each cell's
//     exitant radiance by the half-space's exit shape for its α' and η, normalised to
//     the same total power (volume/exit_law.h).
//     (The η-dependence used to come from the dipole's ratio Rd(α', η) / Rd(α', 1): at
//     η = 1.3 it put the reflected power per entering power 1 % low at α' ≈ 1 and up to
//     85 % high at α' = 0.02, Jensen's ketchup blue.)
//
// Keeping the seed scheme selectable lets the benchmark show both.
#include <array>
#include <string>
#include <string_view>

namespace sslpv {

enum class LpvScheme { Seed, Calibrated };

/// "seed" / "calibrated"; std::nullopt-like false when unknown.
bool parseLpvScheme(std::string_view name, LpvScheme& scheme);
std::string lpvSchemeName(LpvScheme scheme);

/// Coefficients of one cell and channel for one propagation step and for shading.
struct CellTransport {
  float dc = 1.0f;        ///< DC band factor per step
  float linear = 1.0f;    ///< linear band factor per step
  float exitGain = 1.0f;  ///< multiplies the exitant radiance read from this cell
  /// α' = σs(1-g) / (σa + σs(1-g)): picks the cell's exit angular shape (exit_law.h;
  /// calibrated scheme only).
  float reducedAlbedo = 1.0f;
};

/// The seed's factors (e = exp(-σt Δx), α = σs/σt: dc = e + α(1-e), linear = e + α(1-e)g).
CellTransport seedTransport(double sigmaT, double sigmaS, double g, double cellSize);

/// The calibrated factors for a cell of the given material, cell size and boundary index.
CellTransport calibratedTransport(double sigmaT, double sigmaS, double g, double cellSize, double ior);

/// Total diffuse reflectance of a semi-infinite isotropically scattering medium of the
/// given albedo with a smooth boundary of relative index `ior`, under a collimated beam at
/// normal incidence: diffusely reflected power per incident power (addingDoublingHalfSpace,
/// specular reflection excluded). Every cell of every grid needs it, so it is tabulated
/// on the first call for each ior (129 albedos over sqrt(1 - albedo), about 30 ms) and
/// interpolated (cubic); the table holds Rd / albedo, so low albedos keep their relative
/// accuracy.
/// Throws std::invalid_argument unless ior is positive and finite.
double boundaryReflectance(double albedo, double ior);

/// Builds the per-ior tables the calibrated scheme uses (boundaryReflectance and the exit
/// law, ~50 ms together) now, so renderers pay it while loading the object rather than
/// inside their first frame's stage timings. Throws like boundaryReflectance.
void prepareCalibrationTables(double ior);

/// The index-matched case boundaryReflectance(albedo, 1): 1 - H(1)·sqrt(1 - albedo), as
/// exactIsotropicRd (volume/slab_reflectance.h) computes it from the H-function.
double halfSpaceReflectance(double albedo);

/// Fractions of an injected cosine lobe's power that the first propagation step sends
/// (back out of the layer, within the layer, one layer deeper), from the same clamped
/// face evaluation the propagation uses.
std::array<double, 3> injectedLobeSplit();

}  // namespace sslpv
