#pragma once
// Ranges of the scene's and the command line's real-valued inputs. Finite is not enough:
// a light at 9e18 or an exposure of 1e38 overflows float downstream (a ray direction of
// Inf, a NaN ray that Embree aborts on). The ranges are far beyond any sane scene yet
// keep every product of them finite in float: coordinate² · sigma · intensity · exposure
// = 1e12 · 1e6 · 1e12 · 1e6 = 1e36 < 3.4e38.
namespace sslpv {

/// |x|, |y|, |z| of positions, targets, primitive corners and centres, translate, and of
/// every mesh vertex after the transform (scene units).
inline constexpr double kMaxCoordinate = 1e6;
/// Sphere radius and box extent: the smallest a float vertex can resolve around the
/// origin with room to spare, and the whole coordinate range (scene units).
inline constexpr double kMinPrimitiveSize = 1e-6;
/// transform.scale.
inline constexpr double kMinScale = 1e-6;
inline constexpr double kMaxScale = 1e6;
/// |transform.rotate_deg[i]|: ten turns.
inline constexpr double kMaxRotationDeg = 3600.0;
/// Each direction component's magnitude, and the direction's least length.
inline constexpr double kMaxDirectionComponent = 1e6;
inline constexpr double kMinDirectionLength = 1e-6;
/// Light intensity (W/sr) and irradiance (W/unit²) per channel.
inline constexpr double kMaxRadiometric = 1e12;
/// material.base sigma_t and sigma_s per scene unit.
inline constexpr double kMaxSigma = 1e6;
/// render --exposure.
inline constexpr double kMinExposure = 1e-6;
inline constexpr double kMaxExposure = 1e6;

}  // namespace sslpv
