#pragma once
// The CPU propagation stage (GPU twin: gpu/passes/gpu_propagation.h).
#include <array>

#include "volume/lpv/lpv_stages.h"

namespace sslpv {

/// The Chebyshev semi-iteration's weight for iterate k + 1 (k ≥ 1; iterate 1 has weight
/// 1) when the step operator's eigenvalues lie in [-rho, rho]:
/// ω = 2 / (1 + tanh(k acosh(1/rho)) sqrt(1 - rho²)), the closed form of the three-term
/// recurrence ω_{k+1} = 1 / (1 - rho² ω_k / 4). Both backends take it from here.
double chebyshevOmega(int k, double rho);

/// The factor by which the semi-iteration's error shrinks per step in the limit,
/// rho / (1 + sqrt(1 - rho²)); its --steps auto rule extrapolates the rest with it (or
/// with the shrink it observes, where that is slower).
double chebyshevRate(double rho);

/// Flux a cell with coefficients (c0, cx, cy, cz) sends through the 5 faces of each of
/// its 6 neighbours (order -x, +x, -y, +y, -z, +z), clamped as the propagation clamps.
std::array<float, 6> neighbourFaceFlux(float c0, float cx, float cy, float cz);

/// Propagates `field` (the injected light, replaced by the last step's light) for the
/// requested steps and adds every step, including the injected one, into `accumulated`
/// (with auto steps, also the estimated tail of the steps not run).
/// Each step gathers flux from the 6 neighbours through 5 faces of each destination
/// (exact face solid angles), re-emits it as cosine lobes, then applies extinction and
/// scattering. The max(0,·) clamp of the face evaluation is renormalized per source cell
/// so a step never emits more power than the cell holds.
PropagationResult propagate(const MaterialGrid& material, const StepFactors& factors,
                            ShGrid& field, ShGrid& accumulated, const PropagationOptions& options);

}  // namespace sslpv
