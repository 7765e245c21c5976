#pragma once
// The one continuous material field every consumer samples (docs/design.md §4).
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <memory>

#include "volume/material/material_set.h"
#include "volume/scene/deform.h"
#include "volume/scene/material.h"

namespace sslpv {

/// The continuous material field: trilinear between voxel centres (BoxSampler
/// convention) of each grid through its own transform; inactive voxels and anything
/// outside a grid take the base material's value. `worldToRest` maps world points into
/// the grids' (object rest) space. `sigmaScale` multiplies the σ read from the grids to
/// convert the file's units to the scene's (σ is intrinsic: scaling the object does not
/// change it). With `deformation`, `worldToRest` reaches the deformed object space and
/// the deformation's inverse then the rest space the grids live in (volume/scene/deform.h); box
/// averages are then stratified point averages, the map being non-linear.
/// Thread-safe: each thread makes its own Sampler.
class MaterialField {
 public:
  MaterialField(const MaterialSample& base, std::shared_ptr<const MaterialSet> set,
                const glm::dmat4& worldToRest, double sigmaScale,
                std::shared_ptr<const SpaceDeformation> deformation = nullptr);

  /// Holds ValueAccessors and scratch buffers: cheap to create (one allocation, no tree
  /// traversal), one per thread. Copies share that state: do not use a Sampler and its
  /// copy on two threads. Non-finite points and boxes give the base material.
  class Sampler {
   public:
    /// The field at a world point.
    MaterialSample sample(const glm::dvec3& world) const;
    /// The field averaged over a world-axis-aligned box: exact for the trilinear field
    /// when the grids are axis-aligned in world space, else a dense stratified average.
    MaterialSample boxAverage(const glm::dvec3& worldMin, const glm::dvec3& worldMax) const;

   private:
    friend class MaterialField;
    struct Impl;
    std::shared_ptr<Impl> impl_;
  };

  Sampler sampler() const;
  const MaterialSample& base() const { return base_; }
  bool homogeneous() const { return !set_; }
  /// Painted and posed (deformers or a skinned clip): every sample goes back to rest space
  /// through the pose's inverse.
  bool deformed() const { return set_ && deformation_; }

 private:
  MaterialSample base_;
  std::shared_ptr<const MaterialSet> set_;
  glm::dmat4 worldToRest_;
  double sigmaScale_;
  std::shared_ptr<const SpaceDeformation> deformation_;
  /// Per-grid maps from world to index space and active bounding boxes, computed once
  /// here so that making a Sampler costs no tree traversal.
  struct Prepared;
  std::shared_ptr<const Prepared> prepared_;
};

}  // namespace sslpv
