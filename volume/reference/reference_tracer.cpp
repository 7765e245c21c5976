#include "volume/reference/reference_tracer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <limits>
#include <mutex>
#include <numeric>
#include <random>
#include <vector>

#include "volume/core/error.h"
#include "volume/core/fresnel.h"
#include "volume/reference/reference_tracer_impl.h"
#include "volume/reference/refracted_connection.h"
#include "volume/reference/majorant_grid.h"
#include "volume/scene/ray_scene.h"
#include "volume/material/scene_object.h"
#include "volume/material/material_field.h"
#include "volume/scene/camera_rays.h"

namespace sslpv {

using namespace reference_detail;

namespace {

/// Surface crossings and scattering events per path before it is cut: only reached by
/// pathological loops (total internal reflection in an empty region), never by the
/// estimator in practice; Russian roulette ends ordinary paths long before.
constexpr int kMaxSegments = 1 << 20;
/// Scattering events before Russian roulette starts.
constexpr int kRouletteStart = 8;

std::uint64_t splitmix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}


glm::dvec3 sampleHg(const glm::dvec3& d, double g, double u1, double u2) {
  double cosTheta;
  if (std::abs(g) < 1e-3) {
    cosTheta = 1.0 - 2.0 * u1;
  } else {
    const double s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u1);
    cosTheta = (1.0 + g * g - s * s) / (2.0 * g);
  }
  cosTheta = std::clamp(cosTheta, -1.0, 1.0);
  const double sinTheta = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta));
  const double phi = 2.0 * kPi * u2;
  // Orthonormal basis around d (Duff et al. 2017).
  const double sign = std::copysign(1.0, d.z);
  const double a = -1.0 / (sign + d.z);
  const double b = d.x * d.y * a;
  const glm::dvec3 t1(1.0 + sign * d.x * d.x * a, sign * b, -sign * d.x);
  const glm::dvec3 t2(b, sign + d.y * d.y * a, -d.y);
  return glm::normalize(sinTheta * std::cos(phi) * t1 + sinTheta * std::sin(phi) * t2 + cosTheta * d);
}


}  // namespace

ReferenceRng::ReferenceRng(std::uint64_t seed, std::uint64_t stream, std::uint64_t index) {
  const std::uint64_t key = splitmix(splitmix(seed) ^ splitmix(stream * 0x9e3779b97f4a7c15ull + 1) ^ index);
  inc_ = (splitmix(key ^ 0xda942042e4dd58b5ull) << 1u) | 1u;
  state_ = 0;
  uniform();
  state_ += key;
  uniform();
}

double ReferenceRng::uniform() {
  // PCG32 (O'Neill 2014): XSH-RR output of a 64-bit LCG.
  const std::uint64_t old = state_;
  state_ = old * 6364136223846793005ull + inc_;
  const auto xorshifted = static_cast<std::uint32_t>(((old >> 18u) ^ old) >> 27u);
  const auto rot = static_cast<std::uint32_t>(old >> 59u);
  const std::uint32_t out = (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  return double(out) * (1.0 / 4294967296.0);
}

ReferenceTracer::Impl::LightSample ReferenceTracer::Impl::sampleLight(const Light& light, const glm::dvec3& x,
                                                                    int c) const {
  LightSample s;
  if (light.type == Light::Type::Directional) {
    s.toLight = -glm::normalize(light.direction);
    s.distance = std::numeric_limits<double>::infinity();
    s.value = channelOf(light.irradiance, c);
    return s;
  }
  const glm::dvec3 v = light.position - x;
  s.distance = glm::length(v);
  if (!(s.distance > 0.0)) return s;
  s.toLight = v / s.distance;
  if (light.type == Light::Type::Spot) {
    // Hard cone of full angle fovDeg around the direction the light travels along.
    const double cosHalf = std::cos(glm::radians(0.5 * light.fovDeg));
    if (glm::dot(-s.toLight, glm::normalize(light.direction)) < cosHalf) return s;
  }
  s.value = channelOf(light.intensity, c) / (s.distance * s.distance);
  return s;
}

double ReferenceTracer::Impl::insideTransmittance(const MaterialField::Sampler& field, const glm::dvec3& p,
                                                  const glm::dvec3& dir, double length, int c,
                                                  ReferenceRng& rng) const {
  double tr = 1.0;
  MajorantGrid::Walker walk(*majorants, p, dir, length);
  MajorantGrid::Segment s;
  while (tr > 0.0 && walk.next(s)) {
    const double control = s.brick->minorant[c];
    const double residual = s.brick->majorant[c] - control;
    tr *= std::exp(-control * (s.t1 - s.t0));
    if (s.brick->homogeneous || !(residual > 0.0)) continue;
    for (double t = s.t0;;) {
      t -= std::log(1.0 - rng.uniform()) / residual;
      if (t >= s.t1) break;
      const double sigmaT = channelOf(field.sample(p + t * dir).sigmaT, c);
      tr *= std::max(0.0, 1.0 - (sigmaT - control) / residual);
      if (tr < 0.1) {  // Russian roulette keeps the estimator unbiased and the loop short
        if (rng.uniform() < 0.5) return 0.0;
        tr *= 2.0;
      }
    }
  }
  return tr;
}

double ReferenceTracer::Impl::transmittance(const MaterialField::Sampler& field, glm::dvec3 p, const glm::dvec3& dir,
                                            double distance, int c, ReferenceRng& rng, bool fromVolume) const {
  double tr = 1.0;
  double remaining = distance;
  for (int segment = 0; segment < kMaxSegments && tr > 0.0; ++segment) {
    const float tFar = std::isfinite(remaining) ? float(remaining) : 3.0e38f;
    const float tNear = segment == 0 && fromVolume ? 0.0f : float(epsilon);
    const RayHit hit = rays->intersect(glm::vec3(p), glm::vec3(dir), tNear, tFar);
    if (!hit.hit) break;  // no more boundary before the end point: outside, nothing attenuates
    const glm::dvec3 n(hit.normal);
    const double cosN = glm::dot(dir, n);
    const double length = double(hit.t);
    if (cosN > 0.0) tr *= insideTransmittance(field, p, dir, length, c, rng);
    p += length * dir;
    remaining -= length;
    if (remaining <= 0.0) break;
  }
  return tr;
}

double ReferenceTracer::Impl::trace(const MaterialField::Sampler& field, glm::dvec3 p, glm::dvec3 d, int c,
                                    ReferenceRng& rng, int maxScatterEvents) const {
  double beta = 1.0;
  double radiance = 0.0;
  int scatters = 0;
  // Only rays that leave a surface point skip hits closer than epsilon. From a scattering
  // vertex the boundary may be closer than that, and skipping it would let a path that
  // should be reflected back (ior != 1) escape instead: a bias of about -σt·epsilon·F
  // per approach of the boundary, measured at -0.4 % of Rd in a 1300-mean-free-path slab.
  bool fromVolume = false;
  for (int segment = 0; segment < kMaxSegments; ++segment) {
    const RayHit hit = rays->intersect(glm::vec3(p), glm::vec3(d), fromVolume ? 0.0f : float(epsilon));
    fromVolume = false;
    if (!hit.hit) return radiance;  // background 0 (or a leak out of the mesh)
    const glm::dvec3 n(hit.normal);
    const double cosN = glm::dot(d, n);
    const double length = double(hit.t);
    bool scattered = false;
    if (cosN > 0.0) {
      // Inside: delta tracking towards the boundary, brick by brick. A free flight that
      // passes a brick's far face restarts there with the next brick's majorant, which
      // the exponential's lack of memory makes exact.
      MajorantGrid::Walker walk(*majorants, p, d, length);
      MajorantGrid::Segment s;
      while (!scattered && walk.next(s)) {
        const double sigmaBar = s.brick->majorant[c];
        if (!(sigmaBar > 0.0)) continue;
        for (double t = s.t0;;) {
          t -= std::log(1.0 - rng.uniform()) / sigmaBar;
          if (t >= s.t1) break;
          const glm::dvec3 x = p + t * d;
          // Homogeneous bricks hold the base material exactly, with majorant == σt: every
          // tentative collision is real and no field lookup is needed.
          const MaterialSample m = s.brick->homogeneous ? base : field.sample(x);
          const double sigmaT = channelOf(m.sigmaT, c);
          if (!s.brick->homogeneous && rng.uniform() * sigmaBar >= sigmaT) continue;  // null collision
          beta *= channelOf(m.sigmaS, c) / sigmaT;
          for (const Light& light : scene.lights) {
            if (exactConnections) {
              radiance += beta * (facets ? facetedLight(field, x, d, double(m.g), light, c, rng)
                                         : refractedLight(field, x, d, double(m.g), light, c, rng));
              continue;
            }
            const LightSample ls = sampleLight(light, x, c);
            if (ls.value <= 0.0) continue;
            const double tr = transmittance(field, x, ls.toLight, ls.distance, c, rng, true);
            radiance += beta * hgPhase(glm::dot(d, ls.toLight), double(m.g)) * ls.value * tr;
          }
          ++scatters;
          if (maxScatterEvents > 0 && scatters >= maxScatterEvents) return radiance;
          if (scatters > kRouletteStart) {
            const double survive = std::min(1.0, beta);
            if (!(rng.uniform() < survive)) return radiance;
            beta /= survive;
          }
          if (beta <= 0.0) return radiance;
          const double u1 = rng.uniform();
          d = sampleHg(d, double(m.g), u1, rng.uniform());
          p = x;
          fromVolume = true;
          scattered = true;
          break;
        }
      }
    }
    if (scattered) continue;
    const glm::dvec3 at = p + length * d;
    if (cosN > 0.0) {
      // Leaving the medium. Radiance/n² is invariant across the boundary, so a camera
      // path crossing outwards gains η² (and loses it again on entering).
      const double reflect = fresnelReflectanceFromInside(cosN, eta);
      if (reflect > 0.0 && rng.uniform() < reflect) {
        d = glm::normalize(d - 2.0 * cosN * n);
      } else {
        d = refractInto(d, -n, 1.0 / eta);
        beta *= eta * eta;
      }
    } else {
      const double reflect = fresnelReflectance(-cosN, eta);
      if (reflect > 0.0 && rng.uniform() < reflect) {
        d = glm::normalize(d - 2.0 * cosN * n);
      } else {
        d = refractInto(d, n, eta);
        beta /= eta * eta;
      }
    }
    p = at;
  }
  return radiance;
}

ReferenceTracer::ReferenceTracer(const Scene& scene, const MajorantGridOptions& majorants)
    : ReferenceTracer(scene, scene.material.vdb ? loadMaterialSet(*scene.material.vdb) : nullptr, majorants) {}

ReferenceTracer::ReferenceTracer(const Scene& scene, std::shared_ptr<const MaterialSet> set,
                                 const MajorantGridOptions& majorants)
    : impl_(std::make_unique<Impl>()) {
  impl_->scene = scene;
  // The set is given here, so SceneObject must not load it again.
  Scene withoutVdb = scene;
  withoutVdb.material.vdb.reset();
  impl_->object = std::make_unique<SceneObject>(withoutVdb);
  double sigmaScale = 1.0;
  if (set) {
    const auto fileUnit = unitInMm(set->units);
    if (!fileUnit)
      throw InputError((scene.material.vdb ? scene.material.vdb->string() : std::string("material set")) +
                       ": unknown units '" + set->units + "' in file metadata (expected mm, cm, m or in)");
    sigmaScale = scene.unitInMm / *fileUnit;  // as SceneObject::setMaterialSet
    impl_->object->setMaterialSet(set);
  }
  impl_->base = impl_->object->field().base();
  // A deformed object's voxels reach world space through a non-linear map that the
  // bricks' corner bounds do not bound: one global majorant stays conservative.
  MajorantGridOptions brickOptions = majorants;
  brickOptions.deformed = impl_->object->deformed();
  impl_->majorants = std::make_unique<MajorantGrid>(impl_->object->bounds(), impl_->base, set.get(),
                                                    scene.transform.matrix(), sigmaScale, brickOptions);
  majorant_ = impl_->majorants->globalMajorant();
  impl_->rays = std::make_unique<RayScene>(impl_->object->mesh());
  impl_->eta = scene.material.ior;
  if (impl_->eta != 1.0) {
    std::optional<std::vector<BoundaryPlane>> planes =
        meshPlanes(impl_->object->mesh(), kMaxConnectionPlanes, &impl_->planeOfTriangle);
    if (planes) {
      impl_->planes = std::move(*planes);
      for (std::size_t sequences = impl_->planes.size(); impl_->maxReflections < kMaxInternalReflections &&
                                                         sequences * impl_->planes.size() <= kMaxConnectionSequences;
           sequences *= impl_->planes.size())
        ++impl_->maxReflections;
      const TriangleMesh& mesh = impl_->object->mesh();
      const Bounds meshBounds = mesh.bounds();
      const double size = glm::length(glm::dvec3(meshBounds.max - meshBounds.min));
      impl_->convex = true;
      for (const BoundaryPlane& q : impl_->planes)
        for (const glm::vec3& v : mesh.positions)
          if (glm::dot(q.normal, glm::dvec3(v)) - q.offset > 1e-5 * size) impl_->convex = false;
    } else {
      impl_->facets = std::make_unique<FacetedBoundary>(impl_->object->mesh());
    }
    const MajorantGrid& grid = *impl_->majorants;
    impl_->minorantSigmaT = grid.globalMajorant();
    for (int z = 0; z < grid.dims().z; ++z)
      for (int y = 0; y < grid.dims().y; ++y)
        for (int x = 0; x < grid.dims().x; ++x)
          impl_->minorantSigmaT = glm::min(impl_->minorantSigmaT, grid.brick(x, y, z).minorant);
    impl_->exactConnections = true;
  }
  const Bounds& b = impl_->object->bounds();
  const double extent = std::max({b.max.x - b.min.x, b.max.y - b.min.y, b.max.z - b.min.z, 1e-6});
  // Well above float round-off of Embree's hit distances, well below any feature size.
  impl_->epsilon = 2e-6 * std::max(extent, glm::length(glm::max(glm::abs(b.min), glm::abs(b.max))));
}

ReferenceTracer::~ReferenceTracer() = default;

double ReferenceTracer::radianceSample(const glm::dvec3& origin, const glm::dvec3& dir, int channel,
                                       ReferenceRng& rng, int maxScatterEvents) const {
  const MaterialField::Sampler field = impl_->object->field().sampler();
  return impl_->trace(field, origin, dir, channel, rng, maxScatterEvents);
}

const MajorantGrid& ReferenceTracer::majorantGrid() const { return *impl_->majorants; }


ReferenceTracer::LightConnection ReferenceTracer::lightConnection() const {
  if (!impl_->exactConnections) return LightConnection::StraightLine;
  return impl_->facets ? LightConnection::Faceted : LightConnection::FlatFaces;
}

const MaterialField& ReferenceTracer::field() const { return impl_->object->field(); }

double ReferenceTracer::estimateTransmittance(const glm::dvec3& a, const glm::dvec3& b, int channel,
                                              ReferenceRng& rng) const {
  const MaterialField::Sampler field = impl_->object->field().sampler();
  const double distance = glm::length(b - a);
  if (!(distance > 0.0)) return 1.0;
  return impl_->transmittance(field, a, (b - a) / distance, distance, channel, rng, false);
}

ReferenceResult ReferenceTracer::render(const ReferenceOptions& options) const {
  if (options.spp < 1) throw InputError("--spp: must be at least 1");
  const auto start = std::chrono::steady_clock::now();
  const Camera& camera = impl_->scene.camera;
  ReferenceResult result;
  result.radiance = Image(camera.width, camera.height);
  result.standardError = Image(camera.width, camera.height);
  const CameraRays pixelRays(camera);
  const std::size_t total = std::size_t(camera.width) * camera.height;
  std::atomic<std::size_t> done{0};
  std::mutex progressMutex;
  constexpr int kTile = 16;
  const int tilesX = (camera.width + kTile - 1) / kTile;
  const int tilesY = (camera.height + kTile - 1) / kTile;
  // Tiles in a fixed shuffled order: the object covers part of the image and its pixels
  // cost 100-1000× a background one, so in scanline order the share of pixels done said
  // nothing about the time left (a 100-minute marble reference showed "ETA 4s" at 16 %).
  // Shuffled, the share of pixels done tracks the share of work done. Each pixel's
  // samples depend only on (seed, pixel, sample), so the order changes no result.
  std::vector<int> tileOrder(std::size_t(tilesX) * std::size_t(tilesY));
  std::iota(tileOrder.begin(), tileOrder.end(), 0);
  std::shuffle(tileOrder.begin(), tileOrder.end(), std::mt19937(0x5eed));

  auto renderPixel = [&](const MaterialField::Sampler& field, int x, int y) {
    const glm::dvec3 dir = pixelRays.pixelDirection(x, y);
    const std::uint64_t pixel = std::uint64_t(y) * std::uint64_t(camera.width) + std::uint64_t(x);
    glm::dvec3 sum(0.0), sumSq(0.0);
    for (int s = 0; s < options.spp; ++s) {
      ReferenceRng rng(options.seed, pixel, std::uint64_t(s));
      for (int c = 0; c < 3; ++c) {
        const double l = impl_->trace(field, camera.position, dir, c, rng, options.maxScatterEvents);
        sum[c] += l;
        sumSq[c] += l * l;
      }
    }
    const double n = options.spp;
    const glm::dvec3 mean = sum / n;
    glm::dvec3 se(0.0);
    if (options.spp > 1) {
      const glm::dvec3 variance = glm::max(glm::dvec3(0.0), (sumSq - n * mean * mean) / (n - 1.0));
      se = glm::sqrt(variance / n);
    }
    result.radiance.at(x, y) = glm::vec3(mean);
    result.standardError.at(x, y) = glm::vec3(se);
  };
  auto work = [&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, tileOrder.size(), 1),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        const MaterialField::Sampler field = impl_->object->field().sampler();
                        for (std::size_t i = range.begin(); i < range.end(); ++i) {
                          const int x0 = tileOrder[i] % tilesX * kTile, y0 = tileOrder[i] / tilesX * kTile;
                          const int x1 = std::min(camera.width, x0 + kTile), y1 = std::min(camera.height, y0 + kTile);
                          for (int y = y0; y < y1; ++y)
                            for (int x = x0; x < x1; ++x) renderPixel(field, x, y);
                          const std::size_t pixels = std::size_t(x1 - x0) * std::size_t(y1 - y0);
                          const std::size_t now = done.fetch_add(pixels) + pixels;
                          if (options.progress) {
                            std::lock_guard<std::mutex> lock(progressMutex);
                            options.progress(now, total);
                          }
                        }
                      });
  };
  if (options.threads > 0) {
    tbb::task_arena arena(options.threads);
    arena.execute(work);
  } else {
    work();
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace sslpv
