// Derivation of the point-light geometry factor. Rays leave the light at height h1 above
// the plane at angle θ1 to its normal, refract to θ2 (sin θ1 = η sin θ2) and reach the
// depth h2 of x at the horizontal distance R(θ1) = h1 tan θ1 + h2 tan θ2 from the light's
// foot point. The power I sin θ1 dθ1 dφ between θ1 and θ1 + dθ1 crosses the horizontal
// plane at depth h2 over the area R dφ dR, and the area across the ray is cos θ2 times
// that, so the irradiance across the ray per unit intensity is
//   sin θ1 / (R · dR/dθ1 · cos θ2),  dR/dθ1 = h1 / cos² θ1 + h2 / cos² θ2 · cos θ1 / (η cos θ2).
// At η = 1 it is 1 / r²; straight below the light, 1 / (h1 + h2 / η)².
#include "volume/reference/refracted_connection.h"

#include <algorithm>
#include <cstdint>
#include <unordered_map>
#include <cmath>
#include <glm/geometric.hpp>
#include <limits>

#include "volume/core/fresnel.h"

namespace sslpv {

std::optional<std::vector<BoundaryPlane>> meshPlanes(const TriangleMesh& mesh, std::size_t maxPlanes,
                                                     std::vector<int>* planeOfTriangle, double tolerance) {
  const Bounds b = mesh.bounds();
  const double extent = std::max({b.max.x - b.min.x, b.max.y - b.min.y, b.max.z - b.min.z, 1e-30});
  std::vector<BoundaryPlane> planes;
  if (planeOfTriangle) planeOfTriangle->assign(mesh.triangles.size(), -1);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const glm::uvec3& tri = mesh.triangles[t];
    const glm::dvec3 a(mesh.positions[tri.x]), bb(mesh.positions[tri.y]), c(mesh.positions[tri.z]);
    const glm::dvec3 cross = glm::cross(bb - a, c - a);
    const double area2 = glm::length(cross);
    if (!(area2 > 0.0)) continue;  // degenerate: no plane, never hit
    const BoundaryPlane plane{cross / area2, glm::dot(cross / area2, a)};
    int found = -1;
    for (std::size_t k = 0; k < planes.size() && found < 0; ++k)
      if (glm::dot(planes[k].normal, plane.normal) > 1.0 - tolerance &&
          std::abs(planes[k].offset - plane.offset) < tolerance * extent)
        found = int(k);
    if (found < 0) {
      if (planes.size() == maxPlanes) return std::nullopt;
      planes.push_back(plane);
      found = int(planes.size() - 1);
    }
    if (planeOfTriangle) (*planeOfTriangle)[t] = found;
  }
  return planes;
}

FacetedBoundary::FacetedBoundary(const TriangleMesh& mesh) {
  const std::size_t count = mesh.triangles.size();
  corners_.reserve(3 * count);
  planes_.resize(count, BoundaryPlane{glm::dvec3(0.0), 0.0});
  for (std::size_t t = 0; t < count; ++t) {
    const glm::uvec3& tri = mesh.triangles[t];
    for (int k = 0; k < 3; ++k) corners_.emplace_back(mesh.positions[tri[k]]);
    const glm::dvec3* c = &corners_[3 * t];
    const glm::dvec3 cross = glm::cross(c[1] - c[0], c[2] - c[0]);
    const double area2 = glm::length(cross);
    if (area2 > 0.0) planes_[t] = BoundaryPlane{cross / area2, glm::dot(cross / area2, c[0])};
  }
  // The mesh is welded (mesh.h), so triangles sharing an edge share its corners' indices.
  neighbours_.assign(count, {-1, -1, -1});
  const auto edgeKey = [](unsigned a, unsigned b) { return (std::uint64_t(std::min(a, b)) << 32) | std::max(a, b); };
  std::unordered_map<std::uint64_t, int> firstOnEdge;
  firstOnEdge.reserve(3 * count);
  for (std::size_t t = 0; t < count; ++t)
    for (int k = 0; k < 3; ++k) {
      const auto [it, added] =
          firstOnEdge.emplace(edgeKey(mesh.triangles[t][k], mesh.triangles[t][(k + 1) % 3]), int(t) * 3 + k);
      if (added) continue;
      const int other = it->second / 3, otherEdge = it->second % 3;
      if (neighbours_[std::size_t(other)][otherEdge] < 0) neighbours_[std::size_t(other)][otherEdge] = int(t);
      neighbours_[t][k] = other;
    }
}

double FacetedBoundary::clearance(std::size_t triangle, const glm::dvec3& p, int* nearestEdge) const {
  const glm::dvec3* c = &corners_[3 * triangle];
  const glm::dvec3& n = planes_[triangle].normal;
  double least = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    const glm::dvec3 edge = c[(k + 1) % 3] - c[k];
    const double distance = glm::dot(glm::cross(edge, p - c[k]), n) / glm::length(edge);
    if (distance < least) {
      least = distance;
      if (nearestEdge) *nearestEdge = k;
    }
  }
  return glm::dot(n, n) > 0.0 ? least : -std::numeric_limits<double>::infinity();
}

double FacetedBoundary::size(std::size_t triangle) const {
  const glm::dvec3* c = &corners_[3 * triangle];
  return std::max({glm::length(c[1] - c[0]), glm::length(c[2] - c[1]), glm::length(c[0] - c[2])});
}

std::optional<RefractedConnection> connectPointLight(const glm::dvec3& x, const glm::dvec3& light,
                                                     const BoundaryPlane& plane, double eta) {
  const glm::dvec3& n = plane.normal;
  const double h1 = glm::dot(n, light) - plane.offset;
  const double h2 = plane.offset - glm::dot(n, x);
  if (!(h1 > 0.0) || !(h2 > 0.0) || !(eta > 0.0)) return std::nullopt;
  const glm::dvec3 lightFoot = light - h1 * n;
  const glm::dvec3 horizontal = (x + h2 * n) - lightFoot;
  const double rho = glm::length(horizontal);
  RefractedConnection c;
  if (rho <= 1e-12 * (h1 + h2)) {
    c.surfacePoint = lightFoot;
    c.cosOutside = 1.0;
    c.geometry = 1.0 / ((h1 + h2 / eta) * (h1 + h2 / eta));
  } else {
    // Snell along the foot-to-foot line, in the unknown u = sin θ2: the horizontal
    // distance covered, F(u) = h1 tan θ1 + h2 tan θ2 with sin θ1 = η u, must be rho. F is
    // increasing and convex, so Newton from the right of the root descends onto it
    // monotonically and quadratically (4-6 steps). Where one leg alone covers rho is right
    // of the root, as the other leg adds to F. Curved meshes solve a dozen or more faces
    // per light per scattering vertex: this is the reference tracer's hot loop.
    double u = std::min(rho / std::sqrt(rho * rho + h2 * h2), rho / (eta * std::sqrt(rho * rho + h1 * h1)));
    double cos1 = 1.0, cos2 = 1.0;
    for (int i = 0; i < 100; ++i) {
      const double cos1Squared = 1.0 - eta * eta * u * u, cos2Squared = 1.0 - u * u;
      cos1 = std::sqrt(cos1Squared);
      cos2 = std::sqrt(cos2Squared);
      const double excess = h1 * eta * u / cos1 + h2 * u / cos2 - rho;
      const double slope = h1 * eta / (cos1Squared * cos1) + h2 / (cos2Squared * cos2);
      const double step = excess / slope;
      if (!(step > 1e-15 * u) || !(u - step > 0.0)) break;  // converged, to rounding
      u -= step;
    }
    const double sin1 = eta * u;
    const double a = h1 * sin1 / cos1;
    const double dRdTheta1 = h1 / (cos1 * cos1) + h2 / (cos2 * cos2) * cos1 / (eta * cos2);
    c.surfacePoint = lightFoot + (a / rho) * horizontal;
    c.cosOutside = cos1;
    c.geometry = sin1 / (rho * dRdTheta1 * cos2);
  }
  const glm::dvec3 down = c.surfacePoint - x, up = light - c.surfacePoint;
  c.insideDistance = glm::length(down);
  c.outsideDistance = glm::length(up);
  if (!(c.insideDistance > 0.0) || !(c.outsideDistance > 0.0)) return std::nullopt;
  c.toLightInside = down / c.insideDistance;
  c.toLightOutside = up / c.outsideDistance;
  return c;
}

std::optional<RefractedConnection> connectDirectionalLight(const glm::dvec3& x, const glm::dvec3& direction,
                                                           const BoundaryPlane& plane, double eta) {
  const glm::dvec3& n = plane.normal;
  const double cos1 = -glm::dot(direction, n);
  const double h2 = plane.offset - glm::dot(n, x);
  if (!(cos1 > 0.0) || !(h2 > 0.0) || !(eta > 0.0)) return std::nullopt;
  const glm::dvec3 refracted = refractInto(direction, n, eta);
  const double cos2 = -glm::dot(refracted, n);
  if (!(cos2 > 0.0)) return std::nullopt;
  RefractedConnection c;
  c.insideDistance = h2 / cos2;
  c.toLightInside = -refracted;
  c.surfacePoint = x + c.insideDistance * c.toLightInside;
  c.toLightOutside = -direction;
  c.outsideDistance = std::numeric_limits<double>::infinity();
  c.cosOutside = cos1;
  c.geometry = cos1 / cos2;
  return c;
}

std::optional<RefractedConnection> connectLight(const glm::dvec3& x, const LightTarget& light,
                                                const BoundaryPlane& plane, double eta) {
  return light.directional ? connectDirectionalLight(x, light.point, plane, eta)
                           : connectPointLight(x, light.point, plane, eta);
}

int connectionWalk(const FacetedBoundary& boundary, const RayScene& rays, const glm::dvec3& x,
                   const LightTarget& light, double eta, double* insideDistance) {
  // Steps of the walk: rays jump to the right region, then edge steps settle in a few.
  constexpr int kMaxSteps = 64;
  const glm::dvec3 straight = light.directional ? -light.point : glm::normalize(light.point - x);
  const RayHit first = rays.intersect(glm::vec3(x), glm::vec3(straight), 0.0f);
  if (insideDistance) *insideDistance = std::numeric_limits<double>::quiet_NaN();
  if (!first.hit) return -1;
  int face = int(first.triangle), before = -1;
  for (int step = 0; step < kMaxSteps; ++step) {
    const std::optional<RefractedConnection> path = connectLight(x, light, boundary.plane(std::size_t(face)), eta);
    if (!path) break;
    int edge = 0;
    const double clearance = boundary.clearance(std::size_t(face), path->surfacePoint, &edge);
    if (clearance >= 0.0) {
      if (insideDistance) *insideDistance = path->insideDistance;
      break;
    }
    int next = boundary.neighbours(std::size_t(face))[std::size_t(edge)];
    if (clearance < -0.5 * boundary.size(std::size_t(face))) {  // far: jump along the refracted path
      const RayHit hit = rays.intersect(glm::vec3(x), glm::vec3(path->toLightInside), 0.0f);
      if (hit.hit) next = int(hit.triangle);
    }
    if (next < 0 || next == face || next == before) break;
    before = face;
    face = next;
  }
  return face;
}

void connectionPatch(const FacetedBoundary& boundary, int face, const glm::dvec3& x, const LightTarget& light,
                     double eta, std::vector<FaceConnection>& found) {
  if (face < 0) return;
  // A face whose refracting point lies outside it by less than this many times its size
  // is close enough to the patch that its neighbours may hold theirs.
  constexpr double kNearPatch = 0.25;
  // Breadth-first over neighbours, from the walk's face and then from every face whose
  // refracting point lies in it or near it. The patch is a face or a few, so a flat list
  // of the faces queued so far (in order, the queue itself) does.
  thread_local std::vector<int> queued;
  queued.assign(1, face);
  for (std::size_t next = 0; next < queued.size(); ++next) {
    const int centre = queued[next];
    const std::optional<RefractedConnection> path = connectLight(x, light, boundary.plane(std::size_t(centre)), eta);
    const double clearance = path ? boundary.clearance(std::size_t(centre), path->surfacePoint) : -1e300;
    if (clearance >= 0.0) found.push_back({centre, *path});
    // The walk's own face looks around even without a path (x may lie in a gap).
    if (next > 0 && !(clearance >= -kNearPatch * boundary.size(std::size_t(centre)))) continue;
    for (const int t : boundary.neighbours(std::size_t(centre)))
      if (t >= 0 && std::find(queued.begin(), queued.end(), t) == queued.end()) queued.push_back(t);
  }
}

void connectionFaces(const FacetedBoundary& boundary, const RayScene& rays, const glm::dvec3& x,
                     const LightTarget& light, double eta, std::vector<FaceConnection>& found) {
  connectionPatch(boundary, connectionWalk(boundary, rays, x, light, eta), x, light, eta, found);
}

}  // namespace sslpv
