// The record a GPU shadow map writes per texel and GPU injection reads: the twin of
// sslpv::SurfaceFluxSample (volume/lpv/lpv_stages.h). Four vec4 so that std430 and C++ agree
// without padding rules; a texel whose ray missed the object has positionValid.w == 0.
#ifndef SSLPV_FLUX_SAMPLE_SHARED_H
#define SSLPV_FLUX_SAMPLE_SHARED_H

#ifdef __cplusplus
#include <glm/vec4.hpp>
namespace sslpv::gpu {
#define SSLPV_VEC4 glm::vec4
#else
#define SSLPV_VEC4 vec4
#endif

struct GpuFluxSample {
  SSLPV_VEC4 positionValid;  ///< surface point (world), w = 1 hit / 0 miss
  SSLPV_VEC4 normal;         ///< outward unit normal, w unused
  SSLPV_VEC4 direction;      ///< unit refracted direction inside the medium, w unused
  SSLPV_VEC4 flux;           ///< transmitted power per channel (rgb), w unused
};

#undef SSLPV_VEC4
#ifdef __cplusplus
static_assert(sizeof(GpuFluxSample) == 64, "GpuFluxSample must match its std430 layout");
}  // namespace sslpv::gpu
#endif

#endif
