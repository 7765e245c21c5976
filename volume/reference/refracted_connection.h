#pragma once
// Exact next-event connections through a flat face of a smooth dielectric boundary, for
// the reference path tracer (docs/design.md §7).
//
// Why: a point, spot or directional light outside reaches a point x inside only along
// the path that refracts at the boundary, a delta event that a shadow ray along the
// straight line to the light misses. For a flat face the refracting point is unique and
// found in closed form or by a 1D root search, and the irradiance that arrives at x has a
// closed-form geometric factor (the refracted ray tube's cross-section). A mesh whose
// triangles lie in a few planes (a box) gets exact connections by trying every plane; a
// curved mesh is a surface of many small flat faces (FacetedBoundary): its connections
// are the same per-face solutions, for the faces around where the path leaves.
//
// Conventions: the plane's unit normal points out of the medium; η = n_inside / n_outside.
#include <array>
#include <glm/vec3.hpp>
#include <optional>
#include <vector>

#include "volume/scene/mesh.h"
#include "volume/scene/ray_scene.h"

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

/// A mesh's triangles as flat faces, for exact connections through a curved boundary:
/// each triangle's plane, and the triangles across its edges (its neighbours). The
/// refracting point through face t lies in t or not at all; a light's paths to a point
/// leave through faces near one another (one face, or two to a few where the beams
/// refracted by neighbouring faces overlap), so a search around one face finds them all.
class FacetedBoundary {
 public:
  explicit FacetedBoundary(const TriangleMesh& mesh);
  std::size_t size() const { return planes_.size(); }
  /// Degenerate triangles get a zero normal: every connection through them fails.
  const BoundaryPlane& plane(std::size_t triangle) const { return planes_[triangle]; }
  /// Whether p, a point of the triangle's plane, lies inside it (edges included).
  bool contains(std::size_t triangle, const glm::dvec3& p) const { return clearance(triangle, p) >= 0.0; }
  /// The signed distance from p (in the triangle's plane) to the nearest of its edges'
  /// lines: positive inside, negative outside; `nearestEdge` receives that edge (from
  /// corner k to k + 1). -infinity for a degenerate triangle.
  double clearance(std::size_t triangle, const glm::dvec3& p, int* nearestEdge = nullptr) const;
  /// The triangle's longest edge.
  double size(std::size_t triangle) const;
  /// The triangle across the edge from corner k to corner k + 1, or -1 (an open edge).
  const std::array<int, 3>& neighbours(std::size_t triangle) const { return neighbours_[triangle]; }

 private:
  std::vector<glm::dvec3> corners_;  ///< three per triangle, counter-clockwise from outside
  std::vector<BoundaryPlane> planes_;
  std::vector<std::array<int, 3>> neighbours_;
};

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

/// A delta light as the connections see it.
struct LightTarget {
  bool directional = false;
  glm::dvec3 point{0.0};  ///< position (point, spot) or unit travel direction (directional)
};

std::optional<RefractedConnection> connectLight(const glm::dvec3& x, const LightTarget& light,
                                                const BoundaryPlane& plane, double eta);

/// The faces of a curved boundary through which a refracted path from x (inside) to the
/// light leaves: each face whose refracting point lies in it, with that path (appended to
/// `found`; the caller still checks that nothing of the boundary lies between x and that
/// point).
/// A walk from the face the straight line to the light crosses finds the first: each step
/// goes to the face that the current face's refracted path points at, until a face holds
/// its own refracting point (one or two steps on a smooth mesh). Where the beams that
/// neighbouring faces refract overlap (converging light, deep inside a convex object),
/// x is lit through several faces, a patch around that face; a breadth-first search
/// over the neighbours of the faces found collects it. A cycle, or a face without a
/// solution, ends the walk where it is: x then lies in a gap between diverging beams, or
/// near one, and that face's neighbours decide.
struct FaceConnection {
  int face = -1;
  RefractedConnection path;
};
void connectionFaces(const FacetedBoundary& boundary, const RayScene& rays, const glm::dvec3& x,
                     const LightTarget& light, double eta, std::vector<FaceConnection>& found);
/// connectionFaces in its two steps. The walk returns the face it ends on (-1: x sees no
/// boundary towards the light) and, when that face holds its refracting point, the
/// length of that path inside (else NaN): what the tracer's roulette weighs.
int connectionWalk(const FacetedBoundary& boundary, const RayScene& rays, const glm::dvec3& x,
                   const LightTarget& light, double eta, double* insideDistance = nullptr);
void connectionPatch(const FacetedBoundary& boundary, int face, const glm::dvec3& x, const LightTarget& light,
                     double eta, std::vector<FaceConnection>& found);

}  // namespace sslpv
