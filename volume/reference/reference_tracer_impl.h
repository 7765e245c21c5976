#pragma once
// The reference tracer's internals (volume/reference/reference_tracer.h), shared by its two source
// files: reference_tracer.cpp (paths, free flights, shadow rays) and
// reference_connections.cpp (the exact light connections through a dielectric boundary).
// Not part of the volume library's interface.
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <memory>
#include <vector>

#include "volume/reference/majorant_grid.h"
#include "volume/scene/ray_scene.h"
#include "volume/reference/reference_tracer.h"
#include "volume/reference/refracted_connection.h"
#include "volume/scene/scene.h"
#include "volume/material/scene_object.h"
#include "volume/core/math_constants.h"
#include "volume/material/material_field.h"

namespace sslpv {

namespace reference_detail {

// A box has 6 planes, all tried at every vertex; a curved mesh has about as many as
// triangles and gets the walk over its faces instead (facetedLight).
constexpr std::size_t kMaxConnectionPlanes = 64;

/// Light connections attenuated below this along their path inside are evaluated with
/// probability attenuation / level (facetedLight: the walk's path; refractedLight's
/// reflected paths: a bound of theirs), never below the floor.
constexpr double kConnectionRouletteLevel = 0.05;
constexpr double kConnectionRouletteFloor = 1e-9;
/// Specular reflections inside followed by the flat-face connections (two reach into a
/// box's corners), and the most mirror-plane sequences per light and vertex they may cost.
constexpr int kMaxInternalReflections = 2;
constexpr std::size_t kMaxConnectionSequences = 256;

/// Henyey–Greenstein density of the angle between travel directions before and after.
inline double hgPhase(double cosTheta, double g) {
  const double denom = 1.0 + g * g - 2.0 * g * cosTheta;
  return (1.0 - g * g) / (4.0 * kPi * denom * std::sqrt(denom));
}

inline double channelOf(const glm::vec3& v, int c) { return double(v[c]); }

}  // namespace reference_detail

struct ReferenceTracer::Impl {
  Scene scene;
  std::unique_ptr<SceneObject> object;
  std::unique_ptr<RayScene> rays;
  double eta = 1.0;
  /// Rays leave a surface from the hit point itself and ignore hits closer than this
  /// (scene units): offsetting the origin instead would skip a sliver of medium, a bias
  /// of epsilon / thickness in thin slabs.
  double epsilon = 1e-5;
  MaterialSample base;  ///< the field outside every active voxel's reach
  std::unique_ptr<MajorantGrid> majorants;
  /// ior != 1: lights are connected exactly through the boundary, by trying every plane
  /// of a mesh of at most kMaxConnectionPlanes planes (refractedLight), or by the walk
  /// over the faces of a curved one (facetedLight, `facets` set).
  bool exactConnections = false;
  std::vector<BoundaryPlane> planes;
  std::vector<int> planeOfTriangle;
  std::unique_ptr<FacetedBoundary> facets;
  /// Internal reflections the flat-face connections follow (kMaxInternalReflections at
  /// most, fewer for meshes of many planes: the sequences number planes^(reflections + 1)).
  int maxReflections = 0;
  /// Every vertex on the inside of every plane (a box): the first boundary along a ray from
  /// inside is the nearest plane, so the flat-face connections need no ray casts.
  bool convex = false;
  glm::dvec3 minorantSigmaT{0.0};  ///< per channel, the least σt anywhere in the object

  struct LightSample {
    glm::dvec3 toLight{0.0};  ///< unit
    double distance = 0.0;    ///< infinity for directional lights
    double value = 0.0;       ///< irradiance on a surface facing the light (before any occlusion)
  };



  /// A light's constants for the exact connections, computed once per light and vertex.
  struct LightView {
    LightTarget target;
    double value = 0.0;  ///< intensity (point, spot) or irradiance (directional) in the channel
    glm::dvec3 direction{0.0};  ///< unit travel direction (directional, spot)
    double spotCosHalf = -2.0;  ///< below any cosine: no cone
    LightView(const Light& light, int c) : direction(glm::normalize(light.direction)) {
      target.directional = light.type == Light::Type::Directional;
      target.point = target.directional ? direction : light.position;
      value = reference_detail::channelOf(target.directional ? light.irradiance : light.intensity, c);
      if (light.type == Light::Type::Spot) spotCosHalf = std::cos(glm::radians(0.5 * light.fovDeg));
    }
  };

  LightSample sampleLight(const Light& light, const glm::dvec3& x, int c) const;

  /// Residual ratio tracking (Novák et al. 2014) along p + t*dir, t in [0, length], all
  /// inside the medium: the brick's minorant σc attenuates analytically, only σt - σc is
  /// tracked, with majorant σ̄ - σc. Homogeneous bricks have σc = σ̄ = σt: exact, no lookups.
  double insideTransmittance(const MaterialField::Sampler& field, const glm::dvec3& p, const glm::dvec3& dir,
                             double length, int c, ReferenceRng& rng) const;

  /// What a refracted path (leaving x along toLight) delivers before β and before the
  /// attenuation inside: phase × light × the ray tube's geometry × Fresnel transmittance.
  double delivered(const glm::dvec3& d, const glm::dvec3& toLight, double g, const LightView& view,
                   const RefractedConnection& path) const;

  /// What one refracted path brings to x, before β: phase × light × the ray tube's geometry
  /// × Fresnel transmittance × attenuation inside, for a curved boundary's face. Zero
  /// unless the path really leaves x at its refracting point (the first boundary from x is
  /// there) and reaches the light unobstructed outside.
  double pathRadiance(const MaterialField::Sampler& field, const glm::dvec3& x, const glm::dvec3& d, double g,
                      const RefractedConnection& path, const LightView& view, int c, ReferenceRng& rng) const;

  /// In-scattered radiance at x (before β) from `light` through the flat faces of the
  /// boundary (exact connections, refracted_connection.h): per face the refracted path, if
  /// it leaves x through that face and reaches the light unobstructed outside, and the
  /// paths that reach x from that face after up to maxReflections specular reflections
  /// inside without scattering. Those are not negligible: next to an edge of a box the
  /// light refracted in through one face falls on the other at more than the critical
  /// angle (η 1.4: 44-90° against 45.6°), so it is totally reflected into the region
  /// within a mean free path of the edge, which a white furnace's long walks reach often
  /// (without them a box furnace at σt 8 was 1.9 % dark at a face centre and 7 % at 0.1
  /// from two edges).
  double refractedLight(const MaterialField::Sampler& field, const glm::dvec3& x, const glm::dvec3& d, double g,
                        const Light& light, int c, ReferenceRng& rng) const;

  /// Whether the ray p + t dir (p inside or on the mesh) leaves a convex mesh through `plane`
  /// at t = length: no other plane it moves towards is nearer.
  bool nearestPlaneIs(const glm::dvec3& p, const glm::dvec3& dir, int plane, double length) const;

  /// One path light -> refraction at plane k -> reflections at planes mirrors[m-1] ... mirrors[0]
  /// -> x, found by unfolding: `image` is x mirrored through the planes, from which the
  /// refracted connection is straight. Each segment must end on its own plane (the first
  /// boundary along it: the nearest plane of a convex mesh, else checked by ray casting)
  /// and the light must be visible from the refracting point. Mirrors keep a ray tube's
  /// cross-section, so the geometry factor is that of the unfolded path; each reflection
  /// weighs the inside Fresnel reflectance.
  double reflectedConnection(const MaterialField::Sampler& field, const glm::dvec3& x, const glm::dvec3& image,
                             const glm::dvec3& d, double g, const LightView& view, const glm::dvec3* inward,
                             const int* mirrors, int m, std::size_t k, int c, ReferenceRng& rng) const;

  /// The same through a curved (faceted) boundary: every face whose refracting point lies
  /// in it (connectionWalk, connectionPatch) contributes; where the beams of neighbouring faces overlap,
  /// x receives light through each.
  double facetedLight(const MaterialField::Sampler& field, const glm::dvec3& x, const glm::dvec3& d, double g,
                      const Light& light, int c, ReferenceRng& rng) const;

  /// Residual ratio tracking over the inside parts of origin + t*dir, t in [0, distance],
  /// brick by brick with each brick's minorant and majorant; homogeneous bricks contribute
  /// exp(-σt·length) exactly. Boundaries do not bend the line: the light connection of an
  /// index-matched object, where they do not.
  double transmittance(const MaterialField::Sampler& field, glm::dvec3 p, const glm::dvec3& dir, double distance,
                       int c, ReferenceRng& rng, bool fromVolume) const;

  double trace(const MaterialField::Sampler& field, glm::dvec3 p, glm::dvec3 d, int c, ReferenceRng& rng,
               int maxScatterEvents) const;
};

}  // namespace sslpv
