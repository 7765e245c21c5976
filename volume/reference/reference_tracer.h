#pragma once
// Ground truth for SSLPV: a Monte Carlo volumetric path tracer over exactly the scene
// `sslpv render` reads (docs/design.md §7). Delta tracking (free flights) and residual ratio
// tracking (shadow rays) with a majorant and a minorant per brick and channel
// (volume/reference/majorant_grid.h), exact exp(-σt·length) and no field lookups in bricks the
// material set does not reach, Henyey–Greenstein phase
// with the local g, RGB traced one channel at a time, a smooth dielectric boundary
// (ior 1 = invisible boundary) and next-event estimation to point, spot and directional
// lights.
//
// Connections to lights through the boundary (ior != 1): lights are delta lights outside
// the object, so a path vertex inside can reach them only through the refracting
// boundary, and that connection is itself a delta event. When the mesh's triangles lie in
// at most 64 planes (a box, any flat-faced solid), each face's refracted path is found
// exactly (volume/reference/refracted_connection.h): the refracting point, the ray tube's
// compression, the Fresnel transmittance at the outside angle, the attenuation along the
// refracted segment; the face must be the first boundary from the vertex and the light
// visible from the refracting point. Light that reaches a vertex after specular
// reflections inside without scattering in between is followed through up to two
// reflections (one for meshes of 7 to 16 planes, none beyond): it is not negligible even
// for thick objects, since next to an edge the light refracted in through one face is
// totally reflected by the other (a box furnace at η 1.4 lost 1.9 % at a face centre and
// 8.8 % near two edges without it). Longer unscattered paths are missed (they cross the
// object: negligible for objects many mean free paths thick, not for thin ones: a box
// 2 mean free paths across is still 14 % dark). The reflected connections are many
// (6·5^m per light and vertex on a box) and are Russian-rouletted against a bound of their
// transmittance; they still make next-event estimation on a box several times dearer.
// Curved meshes are connected the same way through their faces (FacetedBoundary): the
// geometry the camera paths see, whose normals are the flat triangles' own; a walk finds
// the face the light's path leaves through and a search around it the faces whose beams
// overlap there (internal reflections are not followed: a curved object's chords are
// long). Until 2026-11-30 they used the straight line to the light with the Fresnel
// transmittance at the crossing: a white furnace in a unit sphere at ior 1.4 returned
// 75 % of the right radiance at σt = 0.5 and 88 % at σt = 2.
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
