// Exact light connections of the reference tracer through a dielectric boundary: every
// plane of a flat-faced mesh, with up to two internal reflections, and the walk over the
// faces of a curved one (reference_tracer.h, refracted_connection.h).
#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <limits>
#include <optional>
#include <vector>

#include "volume/core/fresnel.h"
#include "volume/reference/reference_tracer_impl.h"
#include "volume/material/material_field.h"

namespace sslpv {

using namespace reference_detail;

double ReferenceTracer::Impl::delivered(const glm::dvec3& d, const glm::dvec3& toLight, double g,
                                        const LightView& view, const RefractedConnection& path) const {
  return hgPhase(glm::dot(d, toLight), g) * view.value * path.geometry *
         (1.0 - fresnelReflectance(path.cosOutside, eta));
}

double ReferenceTracer::Impl::pathRadiance(const MaterialField::Sampler& field, const glm::dvec3& x,
                                           const glm::dvec3& d, double g, const RefractedConnection& path,
                                           const LightView& view, int c, ReferenceRng& rng) const {
  if (glm::dot(-path.toLightOutside, view.direction) < view.spotCosHalf) return 0.0;
  const RayHit exit = rays->intersect(glm::vec3(x), glm::vec3(path.toLightInside), 0.0f,
                                      float(path.insideDistance * (1.0 + 1e-4) + 10.0 * epsilon));
  if (!exit.hit || std::abs(double(exit.t) - path.insideDistance) > 1e-4 * path.insideDistance + 10.0 * epsilon)
    return 0.0;
  const float outsideFar = std::isfinite(path.outsideDistance) ? float(path.outsideDistance) : 3.0e38f;
  if (rays->intersect(glm::vec3(path.surfacePoint), glm::vec3(path.toLightOutside), float(epsilon), outsideFar).hit)
    return 0.0;
  return delivered(d, path.toLightInside, g, view, path) *
         insideTransmittance(field, x, path.toLightInside, path.insideDistance, c, rng);
}

double ReferenceTracer::Impl::refractedLight(const MaterialField::Sampler& field, const glm::dvec3& x,
                                             const glm::dvec3& d, double g, const Light& light, int c,
                                             ReferenceRng& rng) const {
  const LightView view(light, c);
  if (!(view.value > 0.0)) return 0.0;
  const bool directional = view.target.directional;
  double sum = 0.0;
  int mirrors[kMaxInternalReflections];
  // A directional light's refracted direction through each lit face, shared by every sequence.
  glm::dvec3 inward[kMaxConnectionPlanes];
  if (directional)
    for (std::size_t k = 0; k < planes.size(); ++k)
      if (glm::dot(view.direction, planes[k].normal) < 0.0)
        inward[k] = -refractInto(view.direction, planes[k].normal, eta);
  // Every sequence of mirror planes (no plane twice in a row) of length 0..maxReflections.
  for (int m = 0; m <= maxReflections; ++m) {
    std::size_t count = 1;
    for (int i = 0; i < m; ++i) count *= planes.size();
    for (std::size_t code = 0; code < count; ++code) {
      std::size_t rest = code;
      bool valid = true;
      glm::dvec3 image = x;  // x mirrored through the planes in path order
      for (int i = 0; i < m; ++i) {
        mirrors[i] = int(rest % planes.size());
        rest /= planes.size();
        if (i > 0 && mirrors[i] == mirrors[i - 1]) valid = false;
        const BoundaryPlane& q = planes[std::size_t(mirrors[i])];
        image += 2.0 * (q.offset - glm::dot(q.normal, image)) * q.normal;
      }
      if (!valid) continue;
      // Russian roulette on the reflected paths (unbiased, and they are many: 6·5^m on a
      // box) against a bound of their transmittance: they are at least as long as the way
      // from x to the first mirror and from the image to the refracting plane.
      const double firstMirror =
          m > 0 ? planes[std::size_t(mirrors[0])].offset - glm::dot(planes[std::size_t(mirrors[0])].normal, x) : 0.0;
      for (std::size_t k = 0; k < planes.size(); ++k) {
        if (m > 0 && int(k) == mirrors[m - 1]) continue;
        // The light must be on the outside of plane k.
        if (directional ? !(glm::dot(view.direction, planes[k].normal) < 0.0)
                        : !(glm::dot(planes[k].normal, view.target.point) > planes[k].offset))
          continue;
        double keep = 1.0;
        if (m > 0) {
          const double depth = planes[k].offset - glm::dot(planes[k].normal, image);
          if (!(depth > 0.0)) continue;
          keep = std::min(1.0, std::exp(-minorantSigmaT[c] * std::max(firstMirror, depth)) / kConnectionRouletteLevel);
          if (keep < 1.0 && !(rng.uniform() < keep)) continue;
        }
        sum += reflectedConnection(field, x, image, d, g, view, inward, mirrors, m, k, c, rng) / keep;
      }
    }
  }
  return sum;
}

bool ReferenceTracer::Impl::nearestPlaneIs(const glm::dvec3& p, const glm::dvec3& dir, int plane, double length) const {
  for (std::size_t q = 0; q < planes.size(); ++q) {
    const double along = glm::dot(dir, planes[q].normal);
    if (int(q) == plane || !(along > 0.0)) continue;
    if ((planes[q].offset - glm::dot(planes[q].normal, p)) / along < length * (1.0 - 1e-9)) return false;
  }
  return true;
}

double ReferenceTracer::Impl::reflectedConnection(const MaterialField::Sampler& field, const glm::dvec3& x,
                                                  const glm::dvec3& image, const glm::dvec3& d, double g,
                                                  const LightView& view, const glm::dvec3* inward, const int* mirrors,
                                                  int m, std::size_t k, int c, ReferenceRng& rng) const {
  const bool directional = view.target.directional;
  // Directions of the segments from x: the last one is the unfolded direction, known
  // before the connection for a directional light, so that most plane sequences fail the
  // cheap tests below first.
  glm::dvec3 dirs[kMaxInternalReflections + 1];
  std::optional<RefractedConnection> path;
  if (directional) {
    dirs[m] = inward[k];  // refractedLight passes only planes the light falls on
  } else {
    path = connectPointLight(image, view.target.point, planes[k], eta);
    if (!path) return 0.0;
    dirs[m] = path->toLightInside;
  }
  for (int i = m - 1; i >= 0; --i) {
    const glm::dvec3& n = planes[std::size_t(mirrors[i])].normal;
    dirs[i] = dirs[i + 1] - 2.0 * glm::dot(dirs[i + 1], n) * n;
  }
  // Segment lengths from the planes (exact); whether the faces are really there is checked below.
  glm::dvec3 p = x;
  double lengths[kMaxInternalReflections + 1];
  double total = 0.0;
  for (int i = 0; i <= m; ++i) {
    const BoundaryPlane& q = planes[i < m ? std::size_t(mirrors[i]) : k];
    const double along = glm::dot(dirs[i], q.normal);
    if (!(along > 0.0)) return 0.0;
    lengths[i] = (q.offset - glm::dot(q.normal, p)) / along;
    if (!(lengths[i] > 0.0)) return 0.0;
    p += lengths[i] * dirs[i];
    total += lengths[i];
  }
  if (directional) path = connectDirectionalLight(image, view.direction, planes[k], eta);
  if (!path) return 0.0;
  if (glm::dot(-path->toLightOutside, view.direction) < view.spotCosHalf) return 0.0;
  if (std::abs(total - path->insideDistance) > 1e-6 * path->insideDistance + 10.0 * epsilon) return 0.0;
  double weight = 1.0;
  p = x;
  for (int i = 0; i <= m; ++i) {
    const int plane = i < m ? mirrors[i] : int(k);
    if (convex) {
      if (!nearestPlaneIs(p, dirs[i], plane, lengths[i])) return 0.0;
    } else {
      const RayHit exit = rays->intersect(glm::vec3(p), glm::vec3(dirs[i]), i == 0 ? 0.0f : float(epsilon),
                                          float(lengths[i] * (1.0 + 1e-4) + 10.0 * epsilon));
      if (!exit.hit || planeOfTriangle[exit.triangle] != plane ||
          std::abs(double(exit.t) - lengths[i]) > 1e-4 * lengths[i] + 10.0 * epsilon)
        return 0.0;
    }
    if (i < m) weight *= fresnelReflectanceFromInside(glm::dot(dirs[i], planes[std::size_t(plane)].normal), eta);
    p += lengths[i] * dirs[i];
  }
  // A ray leaving a convex mesh never meets it again.
  const float outsideFar = std::isfinite(path->outsideDistance) ? float(path->outsideDistance) : 3.0e38f;
  if (!convex &&
      rays->intersect(glm::vec3(path->surfacePoint), glm::vec3(path->toLightOutside), float(epsilon), outsideFar).hit)
    return 0.0;
  p = x;
  for (int i = 0; i <= m && weight > 0.0; ++i) {
    weight *= insideTransmittance(field, p, dirs[i], lengths[i], c, rng);
    p += lengths[i] * dirs[i];
  }
  return delivered(d, dirs[0], g, view, *path) * weight;
}

double ReferenceTracer::Impl::facetedLight(const MaterialField::Sampler& field, const glm::dvec3& x,
                                           const glm::dvec3& d, double g, const Light& light, int c,
                                           ReferenceRng& rng) const {
  const LightView view(light, c);
  if (!(view.value > 0.0)) return 0.0;
  double pathLength = 0.0;
  const int face = connectionWalk(*facets, *rays, x, view.target, eta, &pathLength);
  // Roulette: light reaching x after more than a few mean free paths inside contributes
  // little, and the patch search and the shadow rays cost most of the connection.
  // Evaluating it with probability ∝ its attenuation along the walk's path (weighted by
  // the inverse) keeps the estimate unbiased; the other paths of the patch are about as
  // long. The minorant bounds the attenuation from above.
  double weight = 1.0;
  if (pathLength > 0.0) {
    const double keep = std::clamp(std::exp(-minorantSigmaT[c] * pathLength) / kConnectionRouletteLevel,
                                   kConnectionRouletteFloor, 1.0);
    if (keep < 1.0) {
      if (!(rng.uniform() < keep)) return 0.0;
      weight = 1.0 / keep;
    }
  }
  thread_local std::vector<FaceConnection> lit;
  lit.clear();
  connectionPatch(*facets, face, x, view.target, eta, lit);
  double sum = 0.0;
  for (const FaceConnection& through : lit) sum += pathRadiance(field, x, d, g, through.path, view, c, rng);
  return weight * sum;
}

}  // namespace sslpv
