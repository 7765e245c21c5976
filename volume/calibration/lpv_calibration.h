#pragma once
// Calibrated SSLPV transport: the per-cell, per-channel factors that make the LPV's
// lattice walk decay with depth as the medium does (survival s = 3 / (2 + cosh(κ Δx))),
// give it the medium's boundary (retention ρ) and source depth, and scale what the
// shading reads (exit gain G, oblique-entry gain, exit shape) so that a thick slab
// reflects exactly what radiative transport says, less the once-scattered light the
// shading adds itself. Lengths are scene units, σ per scene unit; every table is built
// once per ior (prepareCalibrationTables). Derivations, constants and the measurements
// behind each choice: docs/design.md §6.6 "Why SSLPV needs calibration" and §6.7
// "Calibrated scheme" (6.7.1 lattice walk, 6.7.2 survival, 6.7.3 boundary, staircase and
// grid phase, 6.7.4 coupling gain, 6.7.5 oblique entry, 6.7.6 exit shape, 6.7.7 per-cell
// diffusion coefficient, 6.7.8 single scattering). The seed scheme stays selectable so
// benchmarks can show both.
#include <array>
#include <string>
#include <string_view>

#include "device_shared/lpv_constants.h"
#include "volume/calibration/lpv_scheme.h"

namespace sslpv {

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

/// Exit-gain factor 1 - f + f / |n|_1 of a boundary cell on a face of unit normal n
/// (normalL1 = |nx| + |ny| + |nz|), f = freshShare: on a staircase the light read back
/// before it propagates comes back diluted about 1 / |n|_1, so the cell's gain is divided
/// by this (docs/design.md §6.7.3, "Staircases").
double staircaseExitCorrection(double freshShare, double normalL1);

/// Upper bound of gridPhaseFreshGain, where the light not yet propagated is a small part
/// of what the face shows and the exact factor would be large.
inline constexpr double kMaxFreshGain = 4.0;

/// Gain on the injected light (not yet propagated) as the boundary layers of an
/// axis-aligned face hold it for shading, where the face covers only `coverage` of its
/// boundary cells (it lies inside them, not on their outer sides): the reflectance of a
/// face on a cell boundary over the lattice Green's function's at that coverage. It is put
/// on the fresh light, not on the exit gain, so light arriving from deep inside is not
/// changed (docs/design.md §6.7.3, "Grid phase").
/// `survival`, `extrapolationLength` and `injectionDepth` are the cell's CellTransport
/// dc, extrapolationLength and injectionDepth (scene units, as `cellSize`). Clamped to
/// [0, kMaxFreshGain].
double gridPhaseFreshGain(double survival, double extrapolationLength, double injectionDepth, double cellSize,
                          double coverage);

inline constexpr int kObliqueIntervals = SSLPV_OBLIQUE_INTERVALS;

/// Per oblique-entry node (CellTransport::obliqueGain), the factor that carries the grid
/// phase corrections to light entering obliquely, which is injected shallower
/// (z0 cos θt), where the phase matters more (docs/design.md §6.7.3, "Grid phase"). Both
/// forms are 1 at normal incidence.
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

/// Lower bound of ρ: k = 0, the profile's zero on the face itself. Where z_b is under half
/// a cell the zero lies inside the boundary cell and ρ must be negative; with |ρ| ≤ 1 per
/// outside face a row of the step operator still sums to at most s < 1 in absolute value,
/// so propagation converges (docs/design.md §6.7.3).
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
/// exactIsotropicRd (volume/reference/slab_reflectance.h) computes it from the H-function.
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
