// Shadow maps on the CPU: one ray per texel from the light, refracted flux per hit. The
// views (and so the texel rays) are planned by planShadowViews, shared with the GPU twin.
#include "volume/cpu/shadow_map.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "volume/core/fresnel.h"
#include "volume/lpv/lpv_stages.h"
#include "volume/scene/ray_scene.h"
#include "volume/scene/shadow_view.h"
#include "volume/cpu/single_scattering.h"

namespace sslpv {
namespace {

/// An orthonormal basis around `forward`: up = cross(right, forward).
ShadowView viewAlong(const glm::dvec3& forward, int size) {
  const glm::dvec3 helper = std::abs(forward.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
  ShadowView view;
  view.size = size;
  view.forward = forward;
  view.right = glm::normalize(glm::cross(forward, helper));
  view.up = glm::cross(view.right, forward);
  return view;
}

ShadowView perspectiveView(const glm::dvec3& eye, const glm::dvec3& forward, double tanHalf, int size) {
  ShadowView view = viewAlong(forward, size);
  view.projection = ShadowView::Projection::Perspective;
  view.origin = eye;
  view.tanHalf = tanHalf;
  return view;
}

class ShadowCaster {
 public:
  ShadowCaster(const Light& light, const RayScene& rays, double ior)
      : light_(light), rays_(rays), ior_(ior), spotCosHalf_(spotCosHalfAngle(light)) {}

  void cast(const ShadowView& view, std::vector<SurfaceFluxSample>& out, ShadowMapStats& stats,
            EntryMap* entry) const {
    const int size = view.size;
    const std::size_t texels = std::size_t(size) * size;
    if (entry) {
      entry->view = view;
      entry->texels.assign(texels, EntryTexel{});
    }
    std::vector<SurfaceFluxSample> samples(texels);
    std::vector<unsigned char> valid(texels, 0);
    std::vector<glm::dvec3> incident(texels, glm::dvec3(0.0));
    tbb::parallel_for(tbb::blocked_range<int>(0, size), [&](const tbb::blocked_range<int>& rows) {
      std::vector<glm::vec3> origins(size), dirs(size);
      std::vector<TexelRay> texelRays(size);
      std::vector<RayHit> hits(size);
      for (int y = rows.begin(); y < rows.end(); ++y) {
        for (int x = 0; x < size; ++x) {
          texelRays[x] = view.texelRay(x, y);
          origins[x] = glm::vec3(texelRays[x].origin);
          dirs[x] = glm::vec3(texelRays[x].dir);
        }
        rays_.intersectMany(origins.data(), dirs.data(), hits.data(), std::size_t(size));
        for (int x = 0; x < size; ++x) {
          const RayHit& hit = hits[x];
          if (!hit.hit) continue;
          const TexelRay& ray = texelRays[x];
          const glm::dvec3 n(hit.normal);
          const double cosI = -glm::dot(ray.dir, n);
          if (cosI <= 0.0) continue;  // grazing or from inside: no light enters here
          const glm::vec3 power = arrivingPower(ray);
          if (power == glm::vec3(0.0f)) continue;
          const double transmittance = 1.0 - fresnelReflectance(cosI, ior_);
          const std::size_t i = std::size_t(y) * size + x;
          samples[i] = SurfaceFluxSample{hit.position, hit.normal, glm::vec3(refractInto(ray.dir, n, ior_)),
                                         power * float(transmittance)};
          incident[i] = glm::dvec3(power);
          valid[i] = 1;
          if (entry) {
            // Across the refracted beam: the texel's power over its cross-section at the hit
            // (its area, or its solid angle times the distance squared), compressed by
            // cos θi / cos θt.
            const double cosT = -glm::dot(glm::dvec3(samples[i].direction), n);
            const double across =
                view.projection == ShadowView::Projection::Orthographic ? ray.weight : ray.weight * hit.t * hit.t;
            const double scale = cosT > 0.0 ? cosI / cosT : 0.0;
            entry->texels[i] = EntryTexel{hit.position, float(scale),
                                          glm::vec3(glm::dvec3(samples[i].flux) * (scale / across)), float(hit.t),
                                          samples[i].direction,
                                          glm::vec3(cosT > 0.0 ? -n / cosT : glm::dvec3(0.0))};
          }
        }
      }
    });
    stats.texels += texels;
    for (std::size_t i = 0; i < texels; ++i) {
      if (!valid[i]) continue;
      ++stats.hits;
      stats.incidentFlux += incident[i];
      stats.transmittedFlux += glm::dvec3(samples[i].flux);
      out.push_back(samples[i]);
    }
  }

 private:
  /// I dω for point and spot lights (zero outside a spot's hard-edged cone), E dA for
  /// directional lights.
  glm::vec3 arrivingPower(const TexelRay& ray) const {
    switch (light_.type) {
      case Light::Type::Directional:
        return light_.irradiance * float(ray.weight);
      case Light::Type::Spot:
        if (glm::dot(ray.dir, light_.direction) < spotCosHalf_) return glm::vec3(0.0f);
        return light_.intensity * float(ray.weight);
      case Light::Type::Point:
        break;
    }
    return light_.intensity * float(ray.weight);
  }

  const Light& light_;
  const RayScene& rays_;
  double ior_;
  double spotCosHalf_;
};

}  // namespace

ShadowBoundingSphere shadowBoundingSphere(const Bounds& bounds) {
  return {0.5 * (bounds.min + bounds.max), 0.5 * glm::length(bounds.extent()) * 1.01 + 1e-9};
}

std::vector<ShadowView> planShadowViews(const Light& light, const Bounds& bounds, int size) {
  std::vector<ShadowView> views;
  const ShadowBoundingSphere sphere = shadowBoundingSphere(bounds);
  const glm::dvec3 center = sphere.center;
  const double radius = sphere.radius;

  if (light.type == Light::Type::Directional) {
    ShadowView view = viewAlong(glm::normalize(light.direction), size);
    view.projection = ShadowView::Projection::Orthographic;
    view.halfSize = radius;
    view.origin = center - view.forward * (2.0 * radius);
    views.push_back(view);
    return views;
  }
  const glm::dvec3 toObject = center - light.position;
  const double distance = glm::length(toObject);
  if (distance <= radius) {
    // Inside the bounding sphere: a cube map, six 90° faces.
    for (int axis = 0; axis < 3; ++axis)
      for (int sign = -1; sign <= 1; sign += 2) {
        glm::dvec3 forward(0.0);
        forward[axis] = sign;
        views.push_back(perspectiveView(light.position, forward, 1.0, size));
      }
    return views;
  }
  const glm::dvec3 axisToObject = toObject / distance;
  const double objectHalf = std::asin(std::min(1.0, radius / distance));
  double half = objectHalf;
  glm::dvec3 forward = axisToObject;
  if (light.type == Light::Type::Spot) {
    const double coneHalf = glm::radians(0.5 * light.fovDeg);
    const double offAxis = std::acos(std::clamp(glm::dot(axisToObject, light.direction), -1.0, 1.0));
    if (offAxis > coneHalf + objectHalf) return views;  // the cone misses the bounding sphere
    if (coneHalf < objectHalf) {                        // spend the texels on the cone, not the whole object
      half = coneHalf;
      forward = light.direction;
    }
  }
  // A square map whose inscribed cone has the half-angle: tan(half) covers its edge.
  views.push_back(perspectiveView(light.position, forward, std::tan(std::min(half, 1.5)), size));
  return views;
}

std::vector<SurfaceFluxSample> castShadowMap(const Light& light, const RayScene& rays, const Bounds& bounds, int size,
                                             double ior, ShadowMapStats* statsOut, std::vector<EntryMap>* entries,
                                             int lightIndex) {
  ShadowMapStats stats;
  std::vector<SurfaceFluxSample> samples;
  const std::vector<ShadowView> views = planShadowViews(light, bounds, size);
  stats.culled = views.empty();
  const ShadowCaster caster(light, rays, ior);
  for (const ShadowView& view : views) {
    EntryMap* entry = nullptr;
    if (entries) {
      entries->emplace_back();
      entry = &entries->back();
      entry->light = lightIndex;
    }
    caster.cast(view, samples, stats, entry);
  }
  if (statsOut) *statsOut = stats;
  return samples;
}

}  // namespace sslpv
