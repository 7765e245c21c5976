#pragma once
// The data of one SSLPV frame's stages (Børlum et al. 2011) that both backends share:
// shadow-map samples, injection and propagation options and results, the per-cell step
// factors. The CPU stages themselves are volume/cpu/{shadow_map,inject,propagate,shade}.h;
// the GPU's are gpu/passes/.
#include <array>
#include <glm/vec3.hpp>
#include <vector>

#include "volume/calibration/lpv_calibration.h"
#include "volume/lpv/lpv_grid.h"
#include "volume/scene/mesh.h"
#include "volume/scene/scene.h"

namespace sslpv {

class RayScene;
struct Image;
struct EntryMap;

/// Light that crossed the surface at one shadow-map texel.
struct SurfaceFluxSample {
  glm::vec3 position;   ///< hit point on the surface (world)
  glm::vec3 normal;     ///< outward unit normal
  glm::vec3 direction;  ///< unit direction of the refracted light inside the medium
  glm::vec3 flux;       ///< transmitted power T * I * dω (or T * E * texel area), per channel
};

struct ShadowMapStats {
  std::size_t texels = 0;        ///< texels cast
  std::size_t hits = 0;          ///< texels whose ray hit the object
  glm::dvec3 incidentFlux{0.0};  ///< power arriving on the surface
  glm::dvec3 transmittedFlux{0.0};
  bool culled = false;           ///< the light cannot reach the object
};

struct StepFactors;

struct InjectionStats {
  /// Total flux of the samples written into the grid (before the calibrated scheme's
  /// oblique-entry gain, which like the exit gain is a coupling factor, not light lost).
  glm::dvec3 injectedFlux{0.0};
  glm::dvec3 droppedFlux{0.0};   ///< flux of samples with no active cell nearby
};

/// Per-step power bookkeeping. Every quantity is total flux (W), per channel.
struct StepEnergy {
  glm::dvec3 inGrid{0.0};     ///< power held by the propagating grid after the step
  glm::dvec3 left{0.0};       ///< power that left through the object's boundary this step
  glm::dvec3 absorbed{0.0};   ///< power absorbed this step
  glm::dvec3 clampRemoved{0.0};  ///< power the clamp would have created, removed this step
};

/// The converged light of a previous Chebyshev run (PropagationOptions::chebyshev), kept
/// by a renderer between frames so that the next run starts from it instead of from the
/// new source: after a stroke or a light nudge only what changed, and the light it moves,
/// has to re-converge. Any start converges to the same x = (I - T)^-1 y (the iteration's
/// error is a polynomial in T applied to the start's error, whatever T and y now are), and
/// the stop rule bounds the light still to come relative to the whole light, so a warm
/// result meets the same tolerance as a cold one.
struct PropagationWarmStart {
  GridFrame frame;                       ///< the grid `light` belongs to (dims, origin, cell)
  std::array<std::vector<float>, 3> light;  ///< per channel, x (c0) over the frame's cells
  /// Per channel, the spectral radius the run that produced `light` estimated. A warm run
  /// reuses it instead of probing: an estimate off the new T's radius only converges more
  /// slowly, and the stop rule then follows the shrink it observes.
  glm::dvec3 rho{0.0};
  /// Per cell of `frame`: an active cell within two cells of an inactive one, where the
  /// shading reads the light (half a cell, at most one cell, inside the surface, trilinear).
  /// Filled by the first warm run on the frame.
  std::vector<unsigned char> shell;
  /// `light` is a coarser grid's prolonged (volume/cpu/coarse_start.h): the run rescales it
  /// and probes the radius itself (`rho` is the coarser grid's, below this one's).
  bool fromCoarserGrid = false;
  bool holds(const GridFrame& f) const {
    return !light[0].empty() && light[0].size() == f.cellCount() && frame.dims == f.dims &&
           frame.origin == f.origin && frame.cellSize == f.cellSize;
  }
  void clear() { *this = PropagationWarmStart{}; }
};

struct PropagationOptions {
  int steps = 8;
  bool autoSteps = false;
  /// --steps auto stops once both (worst channel, fractions of the power accumulated so
  /// far) a step adds less than `autoTolerance` and the power still to come, estimated
  /// as a geometric series from the last step's decay ratio, is below
  /// `autoTailTolerance`. That estimated tail is then added in the last step's shape.
  /// Late steps decay by a near-constant ratio r (the slowest mode), so the step rule
  /// alone stops far too early where r is near 1: the tail is r/(1-r) times the last step.
  double autoTolerance = 1e-3;
  double autoTailTolerance = 1e-2;
  int maxAutoSteps = 10000;
  bool recordEnergy = false;  ///< fill PropagationResult::energy for every step
  /// Steps of an isotropic field under a scheme that keeps it isotropic (the calibrated
  /// one) as a stencil on c0 alone: the same light up to float rounding, 5-9x faster on
  /// the CPU. Off only to compare with the general step.
  bool isotropicFastPath = true;
  /// --steps auto on isotropic steps (above) as a Chebyshev semi-iteration towards the
  /// lattice's converged light x = (I - T)^-1 y instead of summing the steps: after the
  /// first step (whose light is y), SSLPV_CHEBYSHEV_PROBE_STEPS plain steps estimate the
  /// spectral radius rho from their power ratio, then x_{k+1} = ω_k (T x_k + y - x_{k-1})
  /// + x_{k-1} (chebyshevOmega) until the light still to come is under autoTolerance.
  /// 2-12x fewer steps on the shipped scenes, within 0.05 % of the plain steps' image.
  /// Only the first step's energy is recorded, and no tail is added. Both renderers ask
  /// for it; the default keeps the plain steps, whose per-step light the tests inspect.
  /// On the GPU, device-resident runs only (GpuPropagator::runOnDevice, record).
  bool chebyshev = false;
  /// With chebyshev: where it holds a run on the same grid, start from its light (and
  /// radius) instead of probing from the new source; either way it receives this run's
  /// converged light. Null: every run starts cold.
  PropagationWarmStart* warmStart = nullptr;
  /// A warm start's error sits where the frame changed, where a share of the total that
  /// the usual stop lets through can be most of a region's light. So a warm run stops
  /// only once, besides that, the light still to come (its change, extrapolated as the
  /// total's) in every cell the shading reads (PropagationWarmStart::shell) is under this
  /// share of the cell's own light (for cells under SSLPV_WARM_START_LOCAL_FLOOR of the
  /// mean cell's, of that floor). A cold run's worst cell is about as far off.
  double warmLocalTolerance = 1e-2;
};

struct PropagationResult {
  int stepsRun = 0;
  glm::dvec3 initialPower{0.0};
  /// Auto steps: per channel, the multiple of the last step's light added to the
  /// accumulated light for the steps not run, r/(1-r); 0 when none was added.
  glm::dvec3 tailScale{0.0};
  std::vector<StepEnergy> energy;  ///< one entry per step when recordEnergy
  /// Auto steps: the run reached maxAutoSteps before its stop rule held, so the light is
  /// not converged (reported by the CLI and in the timing table).
  bool capped = false;
  /// The Chebyshev run started from a previous frame's light (PropagationWarmStart).
  bool warmStarted = false;
  /// The Chebyshev run started from a coarser grid's light (volume/cpu/coarse_start.h).
  bool coarseStarted = false;
};

/// Per-cell transport factors of one step, derived from the material grid. Seed scheme:
/// the DC band scales by e + a(1-e), the linear band by e + a(1-e)g, with
/// e = exp(-σt Δx), a = σs/σt. Calibrated scheme: see volume/calibration/lpv_calibration.h.
struct StepFactors {
  LpvScheme scheme = LpvScheme::Seed;
  std::array<std::vector<float>, 3> dc;      ///< per channel, per cell
  std::array<std::vector<float>, 3> linear;  ///< per channel, per cell
  /// Per channel, per cell: multiplies the exitant radiance shading reads from the cell
  /// (all 1 in the seed scheme).
  std::array<std::vector<float>, 3> exitGain;
  /// Calibrated scheme: per channel, per cell, the reduced albedo α' that selects the
  /// cell's exit angular shape in shading (volume/calibration/exit_law.h). Empty in the seed scheme,
  /// whose exit stays Lambertian inside the boundary.
  std::array<std::vector<float>, 3> reducedAlbedo;
  /// Calibrated scheme: per channel, per cell, ρ times the number of the cell's six
  /// neighbours that are outside the object: each step a boundary cell keeps that many
  /// times ρ of what it sends one neighbour (isotropic cells send each neighbour 1/6).
  /// Empty in the seed scheme, whose boundary loses everything sent across it.
  /// Where `conductance` is set, it is everything the cell keeps each step (the boundary's
  /// return and the hold of varyDiffusivity) in the same unit, divided by conductance².
  std::array<std::vector<float>, 3> retention;
  /// Calibrated scheme with a spatially varying diffusion coefficient: per channel, per
  /// cell, sqrt(D / D_ref); light crossing the face between cells i and j is weighted by
  /// conductance[i] · conductance[j] (docs/design.md §6.7.7). Empty (all 1) when the
  /// medium's D is uniform, and in the seed scheme.
  std::array<std::vector<float>, 3> conductance;
  /// Calibrated scheme: per channel, per cell, the gain on the injected light as it enters
  /// the accumulated light (gridPhaseFreshGain; 1 away from aligned faces that fall inside
  /// their cells). The propagation carries the injected light unscaled. Empty in the seed
  /// scheme.
  std::array<std::vector<float>, 3> freshGain;
  /// Calibrated scheme: per channel, per cell, CellTransport::injectionDepth (scene
  /// units). Empty in the seed scheme.
  std::array<std::vector<float>, 3> injectionDepth;
  /// Calibrated scheme: per channel, per cell, kObliqueIntervals consecutive values of
  /// CellTransport::obliqueGain. Empty in the seed scheme.
  std::array<std::vector<float>, 3> obliqueGain;
  /// Calibrated scheme: per channel, per cell, the square root of the cell's
  /// CellTransport::exitGain. Light injected through the cell is scaled by it and
  /// `exitGain` is divided by it, so light entering and leaving one material sees the
  /// calibrated gain, and light entering through A and leaving through B sees
  /// sqrt(gain_A · gain_B), the same both ways round (reciprocity; docs/design.md
  /// §6.7.10). Empty in the seed scheme.
  std::array<std::vector<float>, 3> entryCoupling;
  /// The boundary's relative index, which turns a sample's refracted direction back into
  /// its incidence angle for the oblique-entry gain (incidentCosineSquared).
  double ior = 1.0;
  /// Calibrated scheme with a known mean chord: per channel, the object's optical
  /// thickness, its mean chord times the coverage-weighted mean σt' of its cells (0 when
  /// unknown). Below a few mean free paths the lattice's diffusion does not describe it.
  glm::dvec3 opticalThickness{0.0};
  std::vector<unsigned char> active;  ///< coverage > 0 and not on the outer ring
  /// Per (y, z) row: does it hold any active cell? Rows without one never hold light and
  /// are skipped, so cost follows the object's cells rather than its bounding box.
  std::vector<unsigned char> rowActive;
};
StepFactors computeStepFactors(const MaterialGrid& material, LpvScheme scheme = LpvScheme::Seed,
                               double ior = 1.0);

/// Do the factors' steps leave every cell isotropic (all linear factors 0, as in the
/// calibrated scheme)? Then every step after the first is a stencil on c0 alone, which
/// both backends run as such (PropagationOptions::isotropicFastPath).
bool keepsCellsIsotropic(const StepFactors& factors);

/// Beyond this ratio between the largest and the smallest diffusion coefficient of a
/// grid's cells (per channel), the densest cells pass light faster than their own D: the
/// propagation's step count grows as the ratio (docs/design.md §6.7.7).
constexpr double kMaxDiffusivityContrast = 8.0;

/// Per channel, per active cell, sqrt(D / D_ref) of the calibrated scheme's lattice
/// (StepFactors::conductance); empty arrays when every cell's is 1.
std::array<std::vector<float>, 3> diffusivityConductance(const MaterialGrid& material, const StepFactors& factors);

/// Makes calibrated `factors` (conductance still empty) pass light through each face at
/// conductance[i] · conductance[j] of the rate they were computed for, keeping each
/// homogeneous region's accumulated light, as read through the exit and fresh gains,
/// what it was (docs/design.md §6.7.7). Values in (0, 1].
void applyConductance(const MaterialGrid& material, std::array<std::vector<float>, 3> conductance,
                      StepFactors& factors);

/// Whether a propagation on `frame` with `options` runs any step (a grid under 3 cells
/// along an axis, or a step limit of 0, only accumulates the injected light).
inline bool propagationSteps(const GridFrame& frame, const PropagationOptions& options) {
  const int maxSteps = options.autoSteps ? options.maxAutoSteps : options.steps;
  return frame.dims.x >= 3 && frame.dims.y >= 3 && frame.dims.z >= 3 && maxSteps > 0;
}

/// accumulated += the injected light times `freshGain` per channel and cell
/// (StepFactors::freshGain; empty: 1). The start of a propagation that runs steps; with
/// no step the injected light is added as is (GpuPropagator starts the same way).
void addInjected(const std::array<std::vector<float>, 3>& freshGain, const ShGrid& injected, ShGrid& accumulated);

}  // namespace sslpv
