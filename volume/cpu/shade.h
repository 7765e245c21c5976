#pragma once
// The CPU shading stage (GPU twin: gpu/passes/gpu_shade.h).
#include <array>
#include <vector>

#include "volume/core/image_io.h"
#include "volume/lpv/lpv_stages.h"
#include "volume/scene/ray_scene.h"

namespace sslpv {

/// Rasterizes the object from the camera by ray casting; each pixel reads the accumulated
/// LPV half a cell inside the surface, converts intensity to exitant radiance through the
/// hemisphere integral, and applies the exit Fresnel transmittance (and the 1/η² radiance
/// change across the boundary). Background pixels are 0.
/// `exitGain` (StepFactors::exitGain) scales each cell's coefficients; null = 1.
/// `reducedAlbedo` (StepFactors::reducedAlbedo): with it (non-null, non-empty) each cell's
/// radiance also follows its medium's exit angular shape, exitLawShape(exitLawTable(ior),
/// α', cos θo), which keeps each cell's total exitant power; null or empty: Lambertian
/// inside the boundary.
/// `singleScattering`: the shadow maps' entry texels; with them the calibrated
/// single-scattering term is added.
Image shadeImage(const Camera& camera, const RayScene& rays, const MaterialGrid& material,
                 const ShGrid& accumulated, double ior,
                 const std::array<std::vector<float>, 3>* exitGain = nullptr,
                 const std::array<std::vector<float>, 3>* reducedAlbedo = nullptr,
                 const std::vector<EntryMap>* singleScattering = nullptr);

}  // namespace sslpv
