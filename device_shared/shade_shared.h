// Push constants of the GPU shading pass (gpu/passes/gpu_shade.cpp, shaders/shade.*),
// shared verbatim by C++ and GLSL. Only vec4-sized fields, so C++ and push-constant
// layouts agree without padding rules (offsets are checked below); 112 bytes, within
// the 128 every Vulkan device offers.
#ifndef SSLPV_SHADE_SHARED_H
#define SSLPV_SHADE_SHARED_H

#ifdef __cplusplus
#include <cstddef>
#include <glm/vec4.hpp>
namespace sslpv::gpu {
#define SSLPV_SH_VEC4 glm::vec4
#define SSLPV_SH_IVEC4 glm::ivec4
#else
#define SSLPV_SH_VEC4 vec4
#define SSLPV_SH_IVEC4 ivec4
#endif

/// The camera as shadeImage (volume/cpu/shade.cpp) builds it, the grid, and the radiance scale.
struct GpuShadePush {
  SSLPV_SH_VEC4 eye;         ///< xyz: camera position; w: near clip distance
  SSLPV_SH_VEC4 forward;     ///< xyz: unit view direction; w: tan(fov_y / 2) * width / height
  SSLPV_SH_VEC4 right;       ///< xyz: normalize(cross(forward, up)); w: tan(fov_y / 2)
  SSLPV_SH_VEC4 up;          ///< xyz: cross(right, forward); w: relative index of refraction η
  SSLPV_SH_VEC4 viewport;    ///< x: width, y: height (pixels); z: 1 / (A π η²), A the cell face area; w: 0
  SSLPV_SH_VEC4 gridOrigin;  ///< xyz: GridFrame::origin; w: GridFrame::cellSize
  SSLPV_SH_IVEC4 gridDims;   ///< xyz: GridFrame::dims; w: shadow-map views the single-scattering term reads (0: none)
};

/// Workgroup of shaders/shade.comp: wide rows, as the pixels of a row are contiguous.
#define SSLPV_SHADE_GROUP_X 16
#define SSLPV_SHADE_GROUP_Y 8

#undef SSLPV_SH_VEC4
#undef SSLPV_SH_IVEC4
#ifdef __cplusplus
}  // namespace sslpv::gpu
static_assert(sizeof(sslpv::gpu::GpuShadePush) == 7 * 16, "GpuShadePush must match its push-constant layout");
static_assert(offsetof(sslpv::gpu::GpuShadePush, gridOrigin) == 5 * 16, "GpuShadePush field order");
static_assert(offsetof(sslpv::gpu::GpuShadePush, gridDims) == 6 * 16, "GpuShadePush field order");
#endif

#endif
