#pragma once
// The CPU injection stage (GPU twin: gpu/passes/gpu_inject.h).
#include <cstddef>
#include <vector>

#include "volume/lpv/lpv_stages.h"

namespace sslpv {

/// Trilinear weights of the 8 cells around world point p (continuous cell coordinates,
/// cell centres at half-integers) times each cell's coverage, restricted to active cells and
/// renormalized. Returns the number of cells used (0: no active cell nearby).
int activeTrilinearWeights(const MaterialGrid& material, const glm::dvec3& p,
                           std::size_t cells[8], float weights[8]);

/// Seed scheme (`calibrated` null): adds each sample as a clamped cosine lobe about its
/// refracted direction, holding flux/π, half a cell inside the surface, spread
/// trilinearly over active cells. Calibrated scheme (`calibrated` holds its step factors):
/// per channel, an isotropic source of the sample's flux times the oblique-entry gain and
/// the entry coupling at depth max(injectionDepth cos θt, Δx / 2) along the inward normal,
/// injectionDepth, the gain's nodes and the coupling read from the cell half a cell inside
/// (lpv_calibration.h, StepFactors::entryCoupling), θt the
/// refracted direction's angle to the normal. Either way a sample that finds no active cell
/// there looks a cell deeper (Δx / 2 further) before it is dropped.
InjectionStats injectSamples(const std::vector<SurfaceFluxSample>& samples,
                             const MaterialGrid& material, ShGrid& grid,
                             const StepFactors* calibrated = nullptr);

}  // namespace sslpv
