// Derivation of the point-light geometry factor. Rays leave the light at height h1 above
// the plane at angle θ1 to its normal, refract to θ2 (sin θ1 = η sin θ2) and reach the
// depth h2 of x at the horizontal distance R(θ1) = h1 tan θ1 + h2 tan θ2 from the light's
// foot point. The power I sin θ1 dθ1 dφ between θ1 and θ1 + dθ1 crosses the horizontal
// plane at depth h2 over the area R dφ dR, and the area across the ray is cos θ2 times
// that, so the irradiance across the ray per unit intensity is
//   sin θ1 / (R · dR/dθ1 · cos θ2),  dR/dθ1 = h1 / cos² θ1 + h2 / cos² θ2 · cos θ1 / (η cos θ2).
// At η = 1 it is 1 / r²; straight below the light, 1 / (h1 + h2 / η)².
#include "volume/refracted_connection.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <limits>

#include "volume/fresnel.h"

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
    // Snell along the foot-to-foot line: f(a) = sin θ1 - η sin θ2 rises from -η sin θ2 < 0
    // at a = 0 to sin θ1 > 0 at a = rho; bisection to the last bit.
    const auto mismatch = [&](double a) {
      return a / std::hypot(a, h1) - eta * (rho - a) / std::hypot(rho - a, h2);
    };
    double low = 0.0, high = rho;
    for (int i = 0; i < 200 && high - low > 1e-15 * rho; ++i) {
      const double mid = 0.5 * (low + high);
      (mismatch(mid) > 0.0 ? high : low) = mid;
    }
    const double a = 0.5 * (low + high);
    const double outside = std::hypot(a, h1), inside = std::hypot(rho - a, h2);
    const double sin1 = a / outside, cos1 = h1 / outside, cos2 = h2 / inside;
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

}  // namespace sslpv
