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
//     With isotropic injection no cell ever holds a linear band, so both backends run
//     the steps after the first as a stencil on c0 (keepsCellsIsotropic).
//  2. Picks the DC survival s per step so that the walk decays with depth exactly as
//     transport in the medium does far from sources and boundaries, exp(-κ z): κ is the
//     asymptotic decay constant of radiative transport, α' atanh(κ/σt') / (κ/σt') = 1
//     for the reduced albedo α' = σs' / σt', σs' = σs(1 - g), σt' = σa + σs' (similarity
//     relation). Diffusion's σtr = sqrt(3 σa σt') is its α' -> 1 limit; at α' = 0.8 it
//     is 9 % too large, which over a 4 mean-free-path slab darkens transmission by 25 %.
//     The walk's steady state decays as r^n per layer with r + 1/r = 6/s - 4, so
//     s = 3 / (2 + cosh(κ Δx)). This holds for any cell size relative to the mean free
//     path.
//  3. Gives the lattice the medium's boundary, so that light crossing a thin object
//     comes out as it should at every grid resolution, not only light reflected near
//     where it entered. A diffuse field meets a boundary as if it vanished an
//     extrapolation length z_b = 2 A / (3 σt') outside it (A from the Fresnel moments,
//     diffusionBoundaryCoefficient), and light entering as a beam starts diffusing about
//     z0 = 1 / σt' deep. The bare lattice has z_b = Δx / 2 (light sent to an outside cell
//     is lost) and injects Δx / 2 deep; both shrink with the cells, so thin slabs went
//     darker as the grid was refined (jade: x0.88 at 32³, x0.59 at 64³). So a boundary
//     cell returns to itself the share ρ of the light it sends toward each outside
//     neighbour: with a linear profile that puts the zero z_b beyond the face for
//     ρ = (k - 1) / (k + 1), k = 2 z_b / Δx (negative when z_b < Δx / 2, within
//     [kMinRetention, kMaxRetention]), and light is injected isotropically where the refracted beam
//     first scatters, max(z0 cos θt, Δx / 2) deep (θt: the beam's angle to the normal).
//     A face tilted against the grid is a staircase of cells; computeStepFactors gives
//     each of a boundary cell's outside faces its own ρ from the surface plane through
//     the cell (so the profile's zero is z_b beyond the true surface along every axis),
//     and corrects its exit gain for light read back before it propagates, which the
//     staircase dilutes (staircaseExitCorrection). Where the grid falls against a face
//     (the boundary cells' coverage) is corrected from the same lattice's Green's function
//     (gridPhaseFreshGain, alignedPhaseObliqueFactors, tiltedPhaseObliqueFactors).
//  4. Scales the exitant radiance by a coupling gain G so that a thick slab's diffuse
//     reflectance is exact. For a semi-infinite layer stack under normal illumination
//     the lattice's shaded reflectance is, in closed form (derivation in
//     lpv_calibration.cpp), with the injection depth max(z0, Δx / 2) at layer
//     m* = depth / Δx + 1/2 split linearly between layers m = floor(m*) and m + 1
//     (fraction f):
//        R_lpv = 3 ((1 - f) r^m + f r^(m+1)) / (s (1 - ρ r)),  r = exp(-κ Δx).
//     G makes the power the lattice reflects equal the medium's total diffuse reflectance
//     Rd(α', η) under collimated normal incidence: exact transport in an isotropically
//     scattering half-space (reduced albedo α', similarity relation) behind a smooth
//     boundary of relative index η, from the adding-doubling method (adding_doubling.h).
//     At η = 1 that is 1 - H(1; α')·sqrt(1 - α') (Chandrasekhar's H-function). With a
//     boundary, the injection's entry transmittance 1 - F(0) and the shading's exit
//     transmittance of an isotropic cell (diffuseBoundaryTransmittance) are divided out:
//        G = Rd(α', η) / ((1 - F(0)) · T_exit(η) · R_lpv).
//     So the reflected power is exact for a thick slab.
//     (The η-dependence used to come from the dipole's ratio Rd(α', η) / Rd(α', 1): at
//     η = 1.3 it put the reflected power per entering power 1 % low at α' ≈ 1 and up to
//     85 % high at α' = 0.02, Jensen's ketchup blue.)
//  5. Makes that hold for light entering at any angle, not only along the normal. The
//     medium sends back more of an oblique beam (it scatters nearer the surface); the
//     lattice, injecting at z0 cos θt, sends back R_lpv at that depth, and the two differ
//     (ketchup red at 80° incidence: the lattice 13 % too bright). So the injected power is
//     multiplied by the oblique-entry gain
//        c(θi) = [Rd(α', η, θi) / (1 - F(θi))] / [Rd(α', η, 0) / (1 - F(0))]
//                · R_lpv(z0) / R_lpv(z0 cos θt),
//     Rd(α', η, θi) by adding-doubling for a beam at that angle. c = 1 at normal
//     incidence; it is stored at SSLPV_OBLIQUE_INTERVALS values of y = cos² θi and is
//     piecewise linear in y (obliqueEntryGain).
//  6. Gives that power the medium's angular distribution instead of the lattice's
//     (Lambertian inside, Fresnel-weighted outside): the shading weights each cell's
//     exitant radiance by the half-space's exit shape for its α' and η, normalised to
//     the same total power (volume/exit_law.h).
//  7. Gives a heterogeneous medium its own diffusion coefficient per cell. Points 1-6 fix
//     the walk's decay κ per cell, but every cell passes light on at the same rate, so
//     the lattice solves ∇·(D_L ∇φ) − D_L σtr² φ with one D_L: where σt' varies, the
//     flux through an interface is wrong (a marble slab with a 2 mm vein of half the
//     σs' and 100x the σa: diffusion theory puts the lattice's transmission at x1.48 of
//     the medium's; a sheet of marble's σs' and the vein's σa at x0.91). With D = 1/(3σt')
//     and w = D / D_ref, each face passes √(w_i w_j) of what it passed and the cell keeps
//     the rest, which gives ∇·(w D_L ∇φ). In a homogeneous region this is the same
//     lattice run slower: with the survival 1/s_w − 1 = w (1/s − 1), the accumulated
//     light is exactly λ = 1 + s (1/w − 1) times the w = 1 lattice's (boundary and fresh
//     light included), so the exit gain is divided by λ and the fresh gain F becomes
//     1 + λ (F − 1). D_ref is the largest D of the grid's cells, but at most
//     kMaxDiffusivityContrast times the smallest: steps grow as 1 / w.
//  8. Leaves the light that scatters once to the shading (volume/single_scattering.h),
//     which integrates it per pixel: at low α' nearly all returned light is once
//     scattered and leaves within a mean free path of where it entered, which a lattice
//     of diffusing cells spreads too far (round an edge, ketchup green and blue read 1.5-2x
//     the path tracer's a millimetre below it, and 1.0 with the term). The lattice then
//     carries the rest: the gain of point 4 targets Rd − Rd₁ (singleScatteringPerEntering),
//     the oblique-entry gain of point 5 the same difference at each angle, and the exit
//     shape of point 6 that of the radiance less the once-scattered 1/(1 + μ) part. Its
//     light has scattered at least twice, so it is injected where the second scattering
//     happens on average, secondScatteringDepth(η) / σt' (1.21-1.29 / σt'), instead of
//     at 1/σt'. That also keeps what the lattice sends deep into the object: for
//     α' ≥ 0.75 (jade, ketchup red, skin, marble) the depth at which a source reflecting
//     Rd − Rd₁ sends as much light deep as one at 1/σt' reflecting Rd lies at 1.19-1.34 / σt'
//     (lattice Green's function with the boundary's retention); injected at 1/σt' with
//     the smaller gain, a backlit 4 mm jade slab came out 14 % darker (mean ratio 0.86).
//
// Keeping the seed scheme selectable lets the benchmark show both.
#include <array>
#include <string>
#include <string_view>

#include "volume/lpv_constants.h"

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
  /// ρ: share of the light sent toward an outside neighbour that a boundary cell of this
  /// material keeps (calibrated scheme; 0 in the seed's).
  float retention = 0.0f;
  /// z_b = 2 A / (3 σt'): how far beyond the surface a diffuse field's linear profile
  /// vanishes (calibrated scheme; infinite for an empty cell, 0 in the seed's). Tilted
  /// surfaces derive their own ρ from it (computeStepFactors).
  float extrapolationLength = 0.0f;
  /// Depth below the surface at which light entering this material is injected, in
  /// scene units, before the Δx / 2 floor (calibrated scheme: 1 / σt'; 0 in the seed's,
  /// whose lobes go half a cell deep).
  float injectionDepth = 0.0f;
  /// Oblique-entry gain at y = cos² θi = 1 - k / SSLPV_OBLIQUE_INTERVALS, k = 1, 2, ...
  /// (calibrated scheme; all 1 in the seed's). The grazing node (y = 0) holds the value
  /// at cos θi = 0.03, where the entering power is already negligible.
  std::array<float, SSLPV_OBLIQUE_INTERVALS> obliqueGain{};
  /// Of the light an aligned half-space's boundary cells hold under normal incidence, the
  /// share that was injected there and has not propagated yet (calibrated scheme; 0 in the
  /// seed's). A staircase face reads that share out diluted (staircaseExitCorrection).
  float freshShare = 0.0f;
};

/// Exit-gain factor of a boundary cell whose surface has the unit normal n. Light injected
/// half a cell inside a face tilted against the grid is spread over the cells of a
/// staircase, |nx| + |ny| + |nz| of them per cell-area of surface instead of one, and the
/// shading reads those same cells with the same trilinear weights: light that has not
/// propagated yet comes back diluted about 1 / |n|_1 (light that has is spread smoothly
/// and comes back whole). Measured on the thick slab tilted 30° / 45° / along (1,1,1):
/// ketchup blue (freshShare 0.6) read 0.83 / 0.85 / 0.75 of the path tracer, as
/// 1 - f + f / |n|_1 predicts (0.84 / 0.83 / 0.75). So the cell's gain is divided by that.
double staircaseExitCorrection(double freshShare, double normalL1);

/// Upper bound of gridPhaseFreshGain, where the light not yet propagated is a small part
/// of what the face shows and the exact factor would be large.
inline constexpr double kMaxFreshGain = 4.0;

/// Gain on the injected light (not yet propagated) as the boundary layers of an
/// axis-aligned face hold it for shading, where the face covers only `coverage` of its
/// boundary cells (the face lies inside the cells, not on their outer sides). R_lpv above
/// assumes the face on a cell boundary; with it inside, the boundary cell's centre sits
/// (coverage - 1/2) Δx deep, its retention follows that depth, the injection's and the
/// shading's coverage-weighted trilinear weights split differently between layers 1 and
/// 2, and the shaded reflectance changed with where the grid happened to fall: ketchup's
/// top face, green, Δx = 1 mm, with the face at coverage 1, 0.9, 0.8, 0.7, 0.6 read 1.00 /
/// 0.89 / 0.84 / 0.85 / 0.93 of the path tracer; the same Green's function with the
/// boundary cell's ρ and those weights predicts 1.000 / 0.888 / 0.836 / 0.852 / 0.929.
/// The difference is put on the light read before it propagates, not on the exit gain:
/// light arriving from deep inside (through a thin backlit object) reads the same at any
/// coverage (within 1 % for jade), and a gain on the exit would have darkened it.
/// `survival`, `extrapolationLength` and `injectionDepth` are the cell's CellTransport
/// dc, extrapolationLength and injectionDepth (scene units, as `cellSize`). Clamped to
/// [0, kMaxFreshGain].
double gridPhaseFreshGain(double survival, double extrapolationLength, double injectionDepth, double cellSize,
                          double coverage);

inline constexpr int kObliqueIntervals = SSLPV_OBLIQUE_INTERVALS;

/// Per oblique-entry node (CellTransport::obliqueGain), the factor that carries the grid
/// phase corrections to light entering obliquely, which is injected shallower
/// (z0 cos θt). The oblique gain is derived for a face on a cell boundary, and the phase
/// matters more the shallower the light sits: a 30° staircase of ketchup at Δx = 1 mm
/// read, in green, 1.00 of the aligned slab at normal incidence but 0.89 at 60° and 0.86
/// at 80°, as the phase-averaged Green's function predicts (0.90, 0.86). Both forms are 1
/// at normal incidence.
/// An aligned face inside its cells (coverage < 1, with its gridPhaseFreshGain): the exact
/// factor at that coverage, reflectance on a cell boundary over that of the injection
/// there plus the fresh gain's share.
std::array<double, kObliqueIntervals> alignedPhaseObliqueFactors(double survival, double extrapolationLength,
                                                                 double injectionDepth, double cellSize, double ior,
                                                                 double coverage, double freshGain);
/// A tilted face, whose cells take every phase along it: the phase-averaged reflectance
/// (8 coverages) at normal depth over that at the node's depth, both relative to a face
/// on a cell boundary. Depends on the medium only.
std::array<double, kObliqueIntervals> tiltedPhaseObliqueFactors(double survival, double extrapolationLength,
                                                                double injectionDepth, double cellSize, double ior);

/// y = cos² θi of light outside that refracted into a medium of relative index `ior` at
/// `cosRefracted` to the normal inside, clamped to [0, 1]. The injection reads this from
/// the refracted direction it has.
double incidentCosineSquared(double cosRefracted, double ior);

/// The oblique-entry gain at y = cos² θi from a cell's nodes (CellTransport::obliqueGain):
/// piecewise linear, 1 at y = 1. shaders/lpv_inject.comp interpolates the same way.
double obliqueEntryGain(const float* nodes, double y);

/// Upper bound of ρ. Where z_b spans many cells (optically thin cells) diffusion does not
/// describe the object anyway, and ρ -> 1 would hold light for thousands of steps.
inline constexpr double kMaxRetention = 0.95;

/// Lower bound of ρ. Where z_b is under half a cell (dense media at coarse cells, or a
/// partly covered cell whose centre is near the surface) the profile's zero lies between
/// the boundary cell's centre and its outer face, and the ghost value ρ w(1) must be
/// negative: the face drains more than it would open. Clamping at 0 held that light in,
/// and it crossed the object (marble_pebble at 32³ under its spot alone: the far side
/// ×2 bright, 41 % → 24 % without the clamp). -1 is k = 0, the zero on the face itself;
/// with |ρ| ≤ 1 per outside face a cell's row of the step operator still sums to at most
/// its survival s < 1 in absolute value, so the propagation converges.
inline constexpr double kMinRetention = -1.0;

/// The seed's factors (e = exp(-σt Δx), α = σs/σt: dc = e + α(1-e), linear = e + α(1-e)g).
CellTransport seedTransport(double sigmaT, double sigmaS, double g, double cellSize);

/// The calibrated factors for a cell of the given material, cell size and boundary index.
CellTransport calibratedTransport(double sigmaT, double sigmaS, double g, double cellSize, double ior);

/// κ / σt' of radiative transport with isotropic scattering at albedo `albedo` (use α'):
/// the root in (0, 1] of albedo · atanh(k) / k = 1 (1 at albedo 0, 0 at albedo 1).
/// Tabulated once over sqrt(1 - albedo) (129 nodes, cubic; within 1e-6 of the root).
double asymptoticDecay(double albedo);

/// The lattice boundary retention ρ = (k - 1) / (k + 1), k = 2 z_b / Δx, clamped to
/// [kMinRetention, kMaxRetention], for an extrapolation length z_b and cell size Δx.
double boundaryRetention(double extrapolationLength, double cellSize);

/// Total diffuse reflectance of a semi-infinite isotropically scattering medium of the
/// given albedo with a smooth boundary of relative index `ior`, under a collimated beam at
/// normal incidence: diffusely reflected power per incident power (addingDoublingHalfSpace,
/// specular reflection excluded). Every cell of every grid needs it, so it is tabulated
/// on the first call for each ior (129 albedos over sqrt(1 - albedo), about 30 ms) and
/// interpolated (cubic); the table holds Rd / albedo, so low albedos keep their relative
/// accuracy.
/// Throws std::invalid_argument unless ior is positive and finite.
double boundaryReflectance(double albedo, double ior);

/// Builds the per-ior tables the calibrated scheme uses (boundaryReflectance, the exit law
/// and the oblique-entry ratios, ~60 ms together) now, so renderers pay it while loading
/// the object rather than inside their first frame's stage timings. Throws like boundaryReflectance.
void prepareCalibrationTables(double ior);

/// The index-matched case boundaryReflectance(albedo, 1): 1 - H(1)·sqrt(1 - albedo), as
/// exactIsotropicRd (volume/slab_reflectance.h) computes it from the H-function.
double halfSpaceReflectance(double albedo);

/// Light that scatters exactly once in an isotropically scattering half-space (albedo α')
/// and leaves through its smooth boundary (relative index `ior`), per power entering as a
/// beam at cosine `beamCosine` inside: (α'/2) ∫ T(μ) μ / (μ + μt) dμ.
double singleScatteringPerEntering(double albedo, double ior, double beamCosine);

/// Mean depth, in mean free paths below a smooth boundary of relative index `ior`, at
/// which light entering along the normal of an isotropically scattering half-space
/// scatters for the second time (the light that leaves after one scattering excluded, the
/// part the boundary reflects back in included): 1.294 at η = 1, 1.222 at 1.3, 1.210 at
/// 1.5. The calibrated scheme injects there, since its lattice carries only light that
/// has scattered more than once. Throws std::invalid_argument unless ior is positive.
double secondScatteringDepth(double ior);


}  // namespace sslpv
