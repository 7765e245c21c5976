#include "volume/reference/majorant_grid.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <glm/geometric.hpp>
#include <limits>

#include "volume/material/material_set.h"

namespace sslpv {
namespace {

/// Field values reach a double majorant through float conversions (the field returns
/// float σ; sigmaScale·v is not a float): this relative margin covers the half-ulp
/// roundings, at the price of a one-in-a-million null collision (or of a residual of 2e-6·σ
/// where majorant and minorant meet).
constexpr double kRoundOffMargin = 1e-6;

/// Index space of one grid -> world space.
class IndexToWorld {
 public:
  IndexToWorld(const openvdb::math::Transform& transform, const glm::dmat4& restToWorld)
      : transform_(transform), restToWorld_(restToWorld) {
    const bool affine =
        restToWorld[0][3] == 0.0 && restToWorld[1][3] == 0.0 && restToWorld[2][3] == 0.0 && restToWorld[3][3] == 1.0;
    linear_ = affine && transform.isLinear();
    if (linear_) {
      offset_ = map({0.0, 0.0, 0.0});
      for (int j = 0; j < 3; ++j) {
        glm::dvec3 unit(0.0);
        unit[j] = 1.0;
        columns_[j] = map(unit) - offset_;
      }
    }
  }

  glm::dvec3 map(const glm::dvec3& index) const {
    const openvdb::Vec3d rest = transform_.indexToWorld(openvdb::Vec3d(index.x, index.y, index.z));
    const glm::dvec4 world = restToWorld_ * glm::dvec4(rest[0], rest[1], rest[2], 1.0);
    return glm::dvec3(world) / world.w;
  }

  /// World bounds of the index box [lo, hi]. Affine maps: exact. Otherwise the bounds of
  /// the 8 mapped corners, which contain the image for the maps OpenVDB has (linear, and
  /// frustum maps that are trilinear in the index coordinates) under an affine restToWorld.
  Bounds mapBox(const glm::dvec3& lo, const glm::dvec3& hi) const {
    Bounds b;
    if (linear_) {
      const glm::dvec3 centre = 0.5 * (lo + hi), half = 0.5 * (hi - lo);
      glm::dvec3 c = offset_, radius(0.0);
      for (int j = 0; j < 3; ++j) {
        c += centre[j] * columns_[j];
        radius += half[j] * glm::abs(columns_[j]);
      }
      b.min = c - radius;
      b.max = c + radius;
      return b;
    }
    for (int k = 0; k < 8; ++k) b.extend(map({k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z}));
    return b;
  }

 private:
  const openvdb::math::Transform& transform_;
  glm::dmat4 restToWorld_;
  bool linear_ = false;
  glm::dvec3 offset_{0.0};
  std::array<glm::dvec3, 3> columns_{};
};

glm::dvec3 valueOf(const openvdb::Vec3s& v) { return {v[0], v[1], v[2]}; }
glm::dvec3 valueOf(float) { return glm::dvec3(0.0); }

/// Smallest world length of one index step of `grid`, near its active voxels.
template <class GridT>
double worldVoxelSize(const GridT& grid, const glm::dmat4& restToWorld) {
  openvdb::CoordBBox active;
  if (!grid.tree().evalActiveVoxelBoundingBox(active)) return std::numeric_limits<double>::infinity();
  const IndexToWorld toWorld(grid.constTransform(), restToWorld);
  const openvdb::Vec3d c = active.getCenter();
  const glm::dvec3 centre(c[0], c[1], c[2]);
  double size = std::numeric_limits<double>::infinity();
  for (int j = 0; j < 3; ++j) {
    glm::dvec3 step(0.0);
    step[j] = 1.0;
    size = std::min(size, glm::length(toWorld.map(centre + step) - toWorld.map(centre)));
  }
  return size;
}

}  // namespace

MajorantGrid::MajorantGrid(const Bounds& bounds, const MaterialSample& base, const MaterialSet* set,
                           const glm::dmat4& restToWorld, double sigmaScale, const MajorantGridOptions& givenOptions) {
  MajorantGridOptions options = givenOptions;
  options.global = options.global || options.deformed;
  const glm::dvec3 baseSigmaT(base.sigmaT);
  global_ = baseSigmaT;
  const glm::dvec3 extent = glm::max(bounds.extent(), glm::dvec3(0.0));
  const double size = std::max(
      {extent.x, extent.y, extent.z, glm::length(glm::max(glm::abs(bounds.min), glm::abs(bounds.max))), 1e-12});
  const glm::dvec3 pad(1e-5 * size);
  box_.min = bounds.min - pad;
  box_.max = bounds.max + pad;

  // Brick size from the finest grid that has active voxels.
  double voxel = std::numeric_limits<double>::infinity();
  if (set) {
    if (set->sigmaT) voxel = std::min(voxel, worldVoxelSize(*set->sigmaT, restToWorld));
    if (set->sigmaS) voxel = std::min(voxel, worldVoxelSize(*set->sigmaS, restToWorld));
    if (set->g) voxel = std::min(voxel, worldVoxelSize(*set->g, restToWorld));
  }
  const glm::dvec3 boxExtent = box_.max - box_.min;
  dims_ = glm::ivec3(1);
  if (!options.global && std::isfinite(voxel) && voxel > 0.0) {
    const double edge = std::max(1, options.voxelsPerBrick) * voxel;
    for (int a = 0; a < 3; ++a)
      dims_[a] = int(std::clamp(std::ceil(boxExtent[a] / edge), 1.0, double(std::max(1, options.maxBricksPerAxis))));
  }
  brickSize_ = boxExtent / glm::dvec3(dims_);
  MajorantBrick initial;
  initial.majorant = initial.minorant = baseSigmaT;
  bricks_.assign(std::size_t(dims_.x) * std::size_t(dims_.y) * std::size_t(dims_.z), initial);

  // Splat every active value's trilinear footprint (index box widened by one voxel on
  // each side, closed) into the bricks it touches, padded by a hair against round-off in
  // the tracer's brick lookups at brick faces.
  const glm::dvec3 splatPad = 1e-7 * brickSize_;
  auto splat = [&](const auto& grid, double scale, bool isSigmaT) {
    const IndexToWorld toWorld(grid.constTransform(), restToWorld);
    for (auto it = grid.cbeginValueOn(); it; ++it) {
      if (isSigmaT) global_ = glm::max(global_, scale * valueOf(*it));
      openvdb::CoordBBox voxels;
      it.getBoundingBox(voxels);
      const glm::dvec3 lo(voxels.min().x() - 1.0, voxels.min().y() - 1.0, voxels.min().z() - 1.0);
      const glm::dvec3 hi(voxels.max().x() + 1.0, voxels.max().y() + 1.0, voxels.max().z() + 1.0);
      const Bounds world = toWorld.mapBox(lo, hi);
      glm::ivec3 first, last;
      bool inside = true;
      for (int a = 0; a < 3; ++a) {
        const double from = std::floor((world.min[a] - splatPad[a] - box_.min[a]) / brickSize_[a]);
        const double to = std::floor((world.max[a] + splatPad[a] - box_.min[a]) / brickSize_[a]);
        if (!(to >= 0.0 && from <= dims_[a] - 1.0)) inside = false;  // also NaN
        first[a] = int(std::clamp(from, 0.0, dims_[a] - 1.0));
        last[a] = int(std::clamp(to, 0.0, dims_[a] - 1.0));
      }
      if (options.deformed) inside = true;  // one brick: first = last = 0
      if (!inside) continue;
      const glm::dvec3 value = scale * valueOf(*it);
      for (int z = first.z; z <= last.z; ++z)
        for (int y = first.y; y <= last.y; ++y)
          for (int x = first.x; x <= last.x; ++x) {
            MajorantBrick& b = bricks_[(std::size_t(z) * std::size_t(dims_.y) + std::size_t(y)) * std::size_t(dims_.x) +
                                       std::size_t(x)];
            b.homogeneous = false;
            if (isSigmaT) {
              b.majorant = glm::max(b.majorant, value);
              b.minorant = glm::min(b.minorant, value);
            }
          }
    }
  };
  if (set) {
    if (set->sigmaT) splat(*set->sigmaT, sigmaScale, true);
    if (set->sigmaS) splat(*set->sigmaS, sigmaScale, false);
    if (set->g) splat(*set->g, 1.0, false);
  }
  bool anyHeterogeneous = false;
  for (MajorantBrick& b : bricks_) {
    if (b.homogeneous) continue;
    anyHeterogeneous = true;
    b.majorant = (options.global ? global_ : b.majorant) * (1.0 + kRoundOffMargin);
    b.minorant = options.global ? glm::dvec3(0.0) : b.minorant * (1.0 - kRoundOffMargin);
  }
  outside_.homogeneous = !anyHeterogeneous;
  outside_.majorant = anyHeterogeneous ? global_ * (1.0 + kRoundOffMargin) : baseSigmaT;
  outside_.minorant = anyHeterogeneous ? glm::dvec3(0.0) : baseSigmaT;
}

const MajorantBrick& MajorantGrid::brickAt(const glm::dvec3& p) const {
  glm::ivec3 cell;
  for (int a = 0; a < 3; ++a) {
    const double f = std::floor((p[a] - box_.min[a]) / brickSize_[a]);
    if (!(f >= 0.0 && f < dims_[a])) return outside_;
    cell[a] = int(f);
  }
  return brick(cell.x, cell.y, cell.z);
}

MajorantGrid::Walker::Walker(const MajorantGrid& grid, const glm::dvec3& origin, const glm::dvec3& dir, double tEnd)
    : grid_(grid), tEnd_(tEnd) {
  // Clip [0, tEnd] to the box (slabs method).
  double tIn = 0.0, tOut = tEnd;
  for (int a = 0; a < 3; ++a) {
    if (dir[a] != 0.0) {
      const double t1 = (grid.box_.min[a] - origin[a]) / dir[a];
      const double t2 = (grid.box_.max[a] - origin[a]) / dir[a];
      tIn = std::max(tIn, std::min(t1, t2));
      tOut = std::min(tOut, std::max(t1, t2));
    } else if (origin[a] < grid.box_.min[a] || origin[a] > grid.box_.max[a]) {
      tIn = tEnd;
    }
  }
  if (!(tIn < tOut)) {
    tIn_ = tOut_ = tEnd;
    return;
  }
  tIn_ = tIn;
  tOut_ = tOut;
  const glm::dvec3 p = origin + tIn * dir;
  for (int a = 0; a < 3; ++a) {
    const double f = std::floor((p[a] - grid.box_.min[a]) / grid.brickSize_[a]);
    cell_[a] = int(std::clamp(f, 0.0, grid.dims_[a] - 1.0));
    if (dir[a] > 0.0) {
      step_[a] = 1;
      tNext_[a] = (grid.box_.min[a] + (cell_[a] + 1) * grid.brickSize_[a] - origin[a]) / dir[a];
      tDelta_[a] = grid.brickSize_[a] / dir[a];
    } else if (dir[a] < 0.0) {
      step_[a] = -1;
      tNext_[a] = (grid.box_.min[a] + cell_[a] * grid.brickSize_[a] - origin[a]) / dir[a];
      tDelta_[a] = -grid.brickSize_[a] / dir[a];
    } else {
      tNext_[a] = std::numeric_limits<double>::infinity();
    }
  }
}

bool MajorantGrid::Walker::next(Segment& segment) {
  if (!(t_ < tEnd_)) return false;
  if (t_ < tIn_) {
    segment = {t_, tIn_, &grid_.outside_};
    t_ = tIn_;
    return true;
  }
  if (t_ < tOut_) {
    const int axis = tNext_.x <= tNext_.y ? (tNext_.x <= tNext_.z ? 0 : 2) : (tNext_.y <= tNext_.z ? 1 : 2);
    const double t1 = std::max(t_, std::min(tNext_[axis], tOut_));
    segment = {t_, t1, &grid_.brick(cell_.x, cell_.y, cell_.z)};
    t_ = t1;
    cell_[axis] += step_[axis];
    tNext_[axis] += tDelta_[axis];
    // Leaving the bricks a hair before tOut (round-off): the rest counts as outside.
    if (cell_[axis] < 0 || cell_[axis] >= grid_.dims_[axis]) tOut_ = t_;
    return true;
  }
  segment = {t_, tEnd_, &grid_.outside_};
  t_ = tEnd_;
  return true;
}

}  // namespace sslpv
