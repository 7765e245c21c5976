#pragma once
// Exact next-event connections through a flat face of a smooth dielectric boundary, for
// the reference path tracer (issue 4).
//
// Why: a point, spot or directional light outside reaches a point x inside only along
// the path that refracts at the boundary, a delta event that a shadow ray along the
// straight line to the light misses. For a flat face the refracting point is unique and
// found in closed form or by a 1D root search, and the irradiance that arrives at x has a
// closed-form geometric factor (the refracted ray tube's cross-section). A mesh whose
// triangles lie in a few planes (a box) therefore gets exact connections; curved meshes
// keep the straight-line approximation (reference_tracer.h).
//
// Conventions: the plane's unit normal points out of the medium; η = n_inside / n_outside.
#include <glm/vec3.hpp>
#include <optional>
#include <vector>

#include "volume/mesh.h"

namespace sslpv {

struct BoundaryPlane {
  glm::dvec3 normal{0.0, 0.0, 1.0};  ///< unit, outward
  double offset = 0.0;               ///< dot(normal, p) for every point p of the plane
};

/// The distinct planes of the mesh's triangles (triangles within `tolerance`, relative to
/// the mesh's extent, of a plane share it), or nothing when there are more than
/// `maxPlanes` (a curved surface). `planeOfTriangle` receives each triangle's plane index.
std::optional<std::vector<BoundaryPlane>> meshPlanes(const TriangleMesh& mesh, std::size_t maxPlanes,
                                                     std::vector<int>* planeOfTriangle = nullptr,
                                                     double tolerance = 1e-5);

/// A light path outside -> refracting point y on the plane -> x inside.
struct RefractedConnection {
  glm::dvec3 surfacePoint{0.0};  ///< y
  glm::dvec3 toLightInside{0.0};  ///< unit, from x towards y
  double insideDistance = 0.0;    ///< |y - x|
  glm::dvec3 toLightOutside{0.0};  ///< unit, from y towards the light
  double outsideDistance = 0.0;   ///< |light - y|; infinity for directional lights
  double cosOutside = 0.0;        ///< cos θ1 between toLightOutside and the normal
  /// Irradiance arriving at x on a surface facing the refracted ray, per unit light
  /// intensity (point) or per unit irradiance (directional), without the Fresnel
  /// transmittance and without attenuation inside: I·geometry resp. E·geometry.
  double geometry = 0.0;
};

/// The connection from x (inside, below the plane) to a point light at `light` (outside,
/// above it). None when either is on the wrong side. η = 1 gives the straight line and
/// geometry = 1 / |light - x|².
std::optional<RefractedConnection> connectPointLight(const glm::dvec3& x, const glm::dvec3& light,
                                                     const BoundaryPlane& plane, double eta);

/// The connection from x (inside) to a directional light travelling along `direction`
/// (unit). None when the light does not fall on the plane's outside. geometry =
/// cos θ1 / cos θ2: the refracted beam's irradiance across itself per unit irradiance
/// across the incident beam.
std::optional<RefractedConnection> connectDirectionalLight(const glm::dvec3& x, const glm::dvec3& direction,
                                                           const BoundaryPlane& plane, double eta);

}  // namespace sslpv
