#pragma once
// Ground truth for SSLPV: a Monte Carlo volumetric path tracer over exactly the scene
// `sslpv render` reads. Delta tracking with per-brick majorants, residual ratio tracking
// for shadow rays, Henyey-Greenstein with the local g, a smooth dielectric boundary and
// next-event estimation through it along the refracted path (exact per flat face, faceted
// for curved meshes). Method, connections and what it misses: docs/design.md §7.
#include <cstdint>
#include <functional>
#include <glm/vec3.hpp>
#include <memory>

#include "volume/core/image_io.h"
#include "volume/reference/majorant_grid.h"
#include "volume/material/material_field.h"
#include "volume/scene/scene.h"

namespace sslpv {

class SceneObject;
class RayScene;

/// Counter-based random numbers: one stream per (seed, pixel, sample), so images do not
/// depend on the thread count or the tile order.
class ReferenceRng {
 public:
  ReferenceRng(std::uint64_t seed, std::uint64_t stream, std::uint64_t index);
  double uniform();  ///< in [0, 1)

 private:
  std::uint64_t state_;
  std::uint64_t inc_;
};

struct ReferenceOptions {
  int spp = 16;                 ///< samples per pixel (each traces R, G and B)
  std::uint64_t seed = 0;
  int threads = 0;              ///< 0: TBB's default
  /// Scattering events after which a path ends; 0 = unlimited. 1 gives single
  /// scattering only (the analytic tests use it).
  int maxScatterEvents = 0;
  /// Called with (done pixels, total pixels) from worker threads, serialized.
  std::function<void(std::size_t, std::size_t)> progress;
};

struct ReferenceResult {
  Image radiance;       ///< per-pixel mean radiance, same units as `sslpv render`
  Image standardError;  ///< per-pixel standard error of that mean
  double seconds = 0.0;
};

class ReferenceTracer {
 public:
  /// Loads the object (and its material set when the scene names one). InputError on bad input.
  explicit ReferenceTracer(const Scene& scene, const MajorantGridOptions& majorants = {});
  /// Uses `set` (in the scene's material.vdb units; nullptr: base only) instead of loading.
  ReferenceTracer(const Scene& scene, std::shared_ptr<const MaterialSet> set,
                  const MajorantGridOptions& majorants = {});
  ~ReferenceTracer();
  ReferenceTracer(const ReferenceTracer&) = delete;
  ReferenceTracer& operator=(const ReferenceTracer&) = delete;

  ReferenceResult render(const ReferenceOptions& options) const;

  /// One estimate of the radiance (channel 0..2) arriving at `origin` from direction
  /// -`dir` (dir: unit travel direction of the camera ray).
  double radianceSample(const glm::dvec3& origin, const glm::dvec3& dir, int channel, ReferenceRng& rng,
                        int maxScatterEvents = 0) const;

  /// One unbiased ratio-tracking estimate of the transmittance of channel `channel`
  /// along the segment a -> b (only the parts inside the object attenuate; boundaries
  /// are not counted).
  double estimateTransmittance(const glm::dvec3& a, const glm::dvec3& b, int channel, ReferenceRng& rng) const;

  /// The global per-channel majorant: max σt over the set's active values and the base.
  glm::dvec3 majorant() const { return majorant_; }
  /// The per-brick majorants the trackers use.
  const MajorantGrid& majorantGrid() const;
  /// How lights are connected to path vertices inside (see above).
  enum class LightConnection {
    StraightLine,  ///< ior 1: the boundary does not bend light
    FlatFaces,     ///< every plane of a mesh of at most 64 planes
    Faceted,       ///< a walk over the faces of a curved mesh
  };
  LightConnection lightConnection() const;
  /// The material field the tracer samples (for checks against the majorants).
  const MaterialField& field() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  glm::dvec3 majorant_{0.0};
};

}  // namespace sslpv
