// Records of the GPU shadow map (gpu/passes/gpu_shadow_map.cpp, shaders/shadow_map.*), shared
// verbatim by C++ and GLSL. Only vec4-sized fields, so C++ and std430/push-constant
// layouts agree without padding rules (offsets are checked below).
#ifndef SSLPV_SHADOW_MAP_SHARED_H
#define SSLPV_SHADOW_MAP_SHARED_H

#ifdef __cplusplus
#include <cstddef>
#include <cstdint>
#include <glm/vec4.hpp>
namespace sslpv::gpu {
#define SSLPV_SM_VEC4 glm::vec4
#define SSLPV_SM_UVEC4 glm::uvec4
#define SSLPV_SM_UINT std::uint32_t
#else
#define SSLPV_SM_VEC4 vec4
#define SSLPV_SM_UVEC4 uvec4
#define SSLPV_SM_UINT uint
#endif

#define SSLPV_SHADOW_PERSPECTIVE 0.0
#define SSLPV_SHADOW_ORTHOGRAPHIC 1.0
/// power.w of lights without a cone: below every cosine, so no texel is cut off.
#define SSLPV_SHADOW_NO_CONE (-2.0)

/// One view of a light's shadow map (sslpv::ShadowView) with what the resolve needs of
/// its light: a std430 array, one record per view of every light.
struct GpuShadowView {
  /// xyz: the light position (perspective) or the centre of the plane the rays start
  /// from (orthographic); w: SSLPV_SHADOW_PERSPECTIVE or SSLPV_SHADOW_ORTHOGRAPHIC.
  SSLPV_SM_VEC4 origin;
  /// xyz: unit axis; w: tan of the half-angle (perspective) or half the side (orthographic).
  SSLPV_SM_VEC4 forward;
  /// xyz: unit; w: the solid angle of the central texel, 4 tan²(half) / size²
  /// (perspective), or the side of a texel (orthographic).
  SSLPV_SM_VEC4 right;
  /// xyz: unit, cross(right, forward); w: near clip distance (perspective; the reversed
  /// depth is near / distance along the axis) or the depth range 4 halfSize (orthographic).
  SSLPV_SM_VEC4 up;
  /// rgb: intensity (W/sr, point and spot) or irradiance (directional); w: cosine of a
  /// spot's half cone angle, SSLPV_SHADOW_NO_CONE for other lights.
  SSLPV_SM_VEC4 power;
  /// xyz: a spot's unit axis (the way it shines); w: relative index of refraction η.
  SSLPV_SM_VEC4 coneAxis;
  /// x: texels per side; y: index of the view's first texel in the sample buffer (views
  /// are concatenated, texel (x, y) of a view at first + y * size + x); z: index of the
  /// view's light (a cube map's six views share it); w: 0.
  SSLPV_SM_UVEC4 texels;
};

/// Push constants of shaders/shadow_map.vert: which GpuShadowView to rasterize.
struct ShadowRasterPush {
  SSLPV_SM_UINT viewIndex;
};

/// Workgroup side of shaders/shadow_map.comp (square tiles of texels, one view per z).
#define SSLPV_SHADOW_RESOLVE_GROUP 8

#undef SSLPV_SM_VEC4
#undef SSLPV_SM_UVEC4
#undef SSLPV_SM_UINT
#ifdef __cplusplus
}  // namespace sslpv::gpu
static_assert(sizeof(sslpv::gpu::GpuShadowView) == 7 * 16, "GpuShadowView must match its std430 layout");
static_assert(offsetof(sslpv::gpu::GpuShadowView, coneAxis) == 5 * 16, "GpuShadowView field order");
static_assert(offsetof(sslpv::gpu::GpuShadowView, texels) == 6 * 16, "GpuShadowView field order");
static_assert(sizeof(sslpv::gpu::ShadowRasterPush) == 4, "ShadowRasterPush is one uint");
#endif

#endif
