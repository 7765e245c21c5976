#pragma once
// The CPU shadow-map stage (GPU twin: gpu/passes/gpu_shadow_map.h).
#include <vector>

#include "volume/lpv/lpv_stages.h"
#include "volume/scene/ray_scene.h"

namespace sslpv {

/// Casts a size x size shadow map of `light` over the object (`bounds`) and returns one
/// sample per texel that hits it, flux already multiplied by the Fresnel transmittance
/// for relative index `ior`. Point and spot lights use a perspective map aimed at the
/// object (a cube map when the light is inside its bounding sphere); directional lights
/// an orthographic map. Lights that cannot reach the object return nothing (culled).
/// With `entries`, also appends each view's every texel as the single-scattering term
/// reads it (volume/cpu/single_scattering.h), tagged `lightIndex`.
std::vector<SurfaceFluxSample> castShadowMap(const Light& light, const RayScene& rays,
                                             const Bounds& bounds, int size, double ior,
                                             ShadowMapStats* stats = nullptr,
                                             std::vector<EntryMap>* entries = nullptr, int lightIndex = 0);

}  // namespace sslpv
