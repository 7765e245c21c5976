#pragma once
// The views a light's shadow map is cast through. The CPU shadow map (Embree rays through
// texel centres, volume/cpu/shadow_map.cpp) and the GPU one (rasterization, gpu/gpu_shadow_map)
// both plan their views here, so both see the same texel rays and texel weights.
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <glm/vec3.hpp>
#include <vector>

#include "volume/scene/mesh.h"
#include "volume/scene/scene.h"

namespace sslpv {

/// The ray of one shadow-map texel.
struct TexelRay {
  glm::dvec3 origin;
  glm::dvec3 dir;  ///< unit
  double weight;   ///< solid angle (perspective) or area across the beam (orthographic)
};

/// One square map of `size` x `size` texels. Texel (x, y) lies at x along `right` and y
/// along `up`, its centre at (x + 0.5, y + 0.5) / size of the map's extent; maps are stored
/// row by row (index y * size + x), views of one light one after the other.
struct ShadowView {
  enum class Projection { Perspective, Orthographic };
  Projection projection = Projection::Perspective;
  int size = 0;
  /// Perspective: the light's position. Orthographic: the centre of the plane the rays
  /// start from (outside the object's bounding sphere, on the side the light comes from).
  glm::dvec3 origin{0.0};
  glm::dvec3 forward{0.0, 0.0, 1.0};  ///< unit, the map's axis
  glm::dvec3 right{1.0, 0.0, 0.0};    ///< unit, perpendicular to forward
  glm::dvec3 up{0.0, 1.0, 0.0};       ///< cross(right, forward)
  /// Perspective: tan of the half-angle from the axis to the map's edge (a square map
  /// whose inscribed cone has the planned half-angle).
  double tanHalf = 1.0;
  /// Orthographic: half the map's side in world units.
  double halfSize = 1.0;

  /// Perspective: 4 tan²(half) / size², the solid angle of the central texel. A texel's
  /// solid angle is this times cos³θ (the seed's Δω_p): exact in the limit of small
  /// texels and within 0.1 % at 64² for the angles planned here.
  double perspectiveTexelScale() const { return 4.0 * tanHalf * tanHalf / (double(size) * size); }
  /// Orthographic: the side of one texel in world units.
  double orthographicTexel() const { return 2.0 * halfSize / size; }

  TexelRay texelRay(int x, int y) const {
    if (projection == Projection::Orthographic) {
      const double texel = orthographicTexel();
      const glm::dvec3 start = origin;
      const double u = (x + 0.5) * texel - halfSize, v = (y + 0.5) * texel - halfSize;
      return TexelRay{start + u * right + v * up, forward, texel * texel};
    }
    const double u = (2.0 * (x + 0.5) / size - 1.0) * tanHalf;
    const double v = (2.0 * (y + 0.5) / size - 1.0) * tanHalf;
    const glm::dvec3 d = forward + u * right + v * up;
    const double len = glm::length(d);
    const double cosTheta = 1.0 / len;
    return TexelRay{origin, d / len, perspectiveTexelScale() * cosTheta * cosTheta * cosTheta};
  }
};

/// Centre and radius of the sphere every view is planned around: the bounding box's
/// circumscribed sphere, 1 % larger so that silhouette texels are never cut off.
struct ShadowBoundingSphere {
  glm::dvec3 center{0.0};
  double radius = 0.0;
};
ShadowBoundingSphere shadowBoundingSphere(const Bounds& bounds);

/// The views of `light`'s size x size shadow map over the object inside `bounds`:
/// - point and spot lights outside the bounding sphere: one perspective map aimed at the
///   sphere (at a spot's cone instead, when the cone is narrower than the sphere);
/// - point and spot lights inside it: a cube map, six 90° perspective maps (-x, +x, -y,
///   +y, -z, +z);
/// - directional lights: one orthographic map across the sphere;
/// - a spot whose cone misses the sphere: no view (the light is culled).
/// A spot's hard cone edge is not part of the view: texels outside the cone carry no
/// light (the casters test each texel ray against the cone).
std::vector<ShadowView> planShadowViews(const Light& light, const Bounds& bounds, int size);

/// Cosine of a spot's half cone angle: a texel ray whose direction d has
/// dot(d, light.direction) below it carries no light (the hard edge).
inline double spotCosHalfAngle(const Light& light) { return std::cos(glm::radians(0.5 * light.fovDeg)); }

}  // namespace sslpv
