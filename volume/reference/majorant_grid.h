#pragma once
// Per-brick majorants for the reference path tracer (docs/design.md §7): a coarse grid of bricks
// over the object's world bounds, each holding per channel an upper bound of the
// material field's σt inside the brick. Delta and ratio tracking sample free flights
// brick by brick with the local bound instead of one global bound, so a dense blob in a
// thin base no longer forces millions of null collisions through the thin part.
//
// Conservative by construction: the field is base + Σ w_i (v_i − base) over the active
// voxels i whose trilinear support (index distance < 1 on every axis) contains the point,
// with w_i >= 0 and Σ w_i <= 1, i.e. a convex combination of the base and those v_i. So
// max(base, v_i over every voxel whose closed support touches the brick) bounds it, and
// the min of the same values bounds it from below.
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <vector>

#include "volume/scene/material.h"
#include "volume/scene/mesh.h"
#include "volume/material/material_field.h"

namespace sslpv {

struct MaterialSet;

struct MajorantBrick {
  /// Per channel, >= σt of the field everywhere in the brick.
  glm::dvec3 majorant{0.0};
  /// Per channel, <= σt of the field everywhere in the brick (min of the base and the
  /// same voxels, by the same convexity): the control of residual ratio tracking.
  glm::dvec3 minorant{0.0};
  /// No active voxel of any grid (σt, σs, g) reaches the brick: the field there is exactly
  /// the base material, minorant == majorant == base σt, and transmittance is
  /// exp(−σt·length).
  bool homogeneous = true;
};

struct MajorantGridOptions {
  /// Brick edge in voxels of the set's finest grid (world size through its transforms).
  int voxelsPerBrick = 8;
  /// Cap on bricks along each axis (memory, and DDA steps per ray).
  int maxBricksPerAxis = 64;
  /// One brick with the global majorant and a zero minorant (plain ratio tracking): the
  /// tracer's behaviour before bricks, kept for comparisons and tests.
  bool global = false;
  /// The set reaches world space through a non-linear map `restToWorld` does not describe
  /// (a deformation, volume/scene/deform.h): implies `global`, and the one brick is
  /// heterogeneous wherever the set has an active voxel, not only where `restToWorld`
  /// puts one inside the bounds.
  bool deformed = false;
};

class MajorantGrid {
 public:
  /// Bricks over `bounds` (world) for the field of `base` and `set` (nullptr: base only),
  /// whose grids reach world space through their own transforms and then `restToWorld`;
  /// set σ values are multiplied by `sigmaScale` (file units -> scene units), as
  /// MaterialField does. A field without active voxels gets a single brick: splitting a
  /// homogeneous field only adds traversal steps.
  MajorantGrid(const Bounds& bounds, const MaterialSample& base, const MaterialSet* set, const glm::dmat4& restToWorld,
               double sigmaScale, const MajorantGridOptions& options = {});

  const glm::ivec3& dims() const { return dims_; }
  /// World box the bricks tile: the bounds padded by a hair, so that points computed on
  /// the boundary with round-off still fall in a brick.
  const Bounds& box() const { return box_; }
  const glm::dvec3& brickSize() const { return brickSize_; }
  const MajorantBrick& brick(int x, int y, int z) const {
    return bricks_[(std::size_t(z) * std::size_t(dims_.y) + std::size_t(y)) * std::size_t(dims_.x) + std::size_t(x)];
  }
  /// The brick containing `p`, or a brick with the global majorant outside the box.
  const MajorantBrick& brickAt(const glm::dvec3& p) const;
  /// Max σt over the base and every active σt value, per channel (not inflated).
  const glm::dvec3& globalMajorant() const { return global_; }

  struct Segment {
    double t0 = 0.0, t1 = 0.0;
    const MajorantBrick* brick = nullptr;
  };

  /// Walks origin + t·dir, t in [0, tEnd] (tEnd finite), as consecutive segments of one
  /// brick each (3D DDA, Amanatides–Woo). Parts outside the box get the global majorant.
  class Walker {
   public:
    Walker(const MajorantGrid& grid, const glm::dvec3& origin, const glm::dvec3& dir, double tEnd);
    /// The next segment; false once tEnd is reached.
    bool next(Segment& segment);

   private:
    const MajorantGrid& grid_;
    double t_ = 0.0, tIn_ = 0.0, tOut_ = 0.0, tEnd_ = 0.0;
    glm::ivec3 cell_{0}, step_{0};
    glm::dvec3 tNext_{0.0}, tDelta_{0.0};
  };

 private:
  glm::ivec3 dims_{1};
  Bounds box_;
  glm::dvec3 brickSize_{1.0};
  glm::dvec3 global_{0.0};
  MajorantBrick outside_;
  std::vector<MajorantBrick> bricks_;
};

}  // namespace sslpv
