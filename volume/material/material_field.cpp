// The one material field every consumer samples (docs/design.md §4): point
// samples and exact box averages.
#include <algorithm>
#include <cmath>
#include <glm/mat3x3.hpp>
#include <limits>
#include <optional>
#include <stdexcept>
#include <vector>

#include "volume/material/material_field.h"

namespace sslpv {
namespace {

template <class TreeT>
using ConstAccessor = openvdb::tree::ValueAccessor<const TreeT, /*IsSafe=*/false>;

/// Per value type: how a voxel value becomes the double-precision sum type.
template <class TreeT>
struct Channel;
template <>
struct Channel<openvdb::Vec3STree> {
  using Sum = glm::dvec3;
  static Sum read(const openvdb::Vec3s& v) { return {v[0], v[1], v[2]}; }
};
template <>
struct Channel<openvdb::FloatTree> {
  using Sum = double;
  static Sum read(float v) { return v; }
};

/// How world points reach one grid's index space.
struct IndexMap {
  enum class Kind {
    AxisAligned,  ///< index = scale * world + offset, per axis: box averages are exact
    Affine,       ///< index = linear * world + translation (rotations, shears)
    General,      ///< non-linear grid transform or projective worldToRest
  };
  Kind kind = Kind::General;
  glm::dvec3 scale{1.0}, offset{0.0};
  glm::dmat3 linear{1.0};
  glm::dvec3 translation{0.0};
  glm::dmat4 worldToRest{1.0};
  const SpaceDeformation* deformation = nullptr;  ///< General only: deformed object -> rest
  const openvdb::math::Transform* transform = nullptr;

  glm::dvec3 toIndex(const glm::dvec3& world) const {
    switch (kind) {
      case Kind::AxisAligned:
        return scale * world + offset;
      case Kind::Affine:
        return linear * world + translation;
      case Kind::General:
        break;
    }
    return restToIndex(toRest(world));
  }

  /// General only: the object's rest-space point a world point came from.
  glm::dvec3 toRest(const glm::dvec3& world) const {
    const glm::dvec4 object = worldToRest * glm::dvec4(world, 1.0);
    const glm::dvec3 rest = glm::dvec3(object) / object.w;
    return deformation ? deformation->inverse(rest) : rest;
  }

  /// General only: the grid's index point of a rest-space point.
  glm::dvec3 restToIndex(const glm::dvec3& rest) const {
    const openvdb::Vec3d index = transform->worldToIndex(openvdb::Vec3d(rest.x, rest.y, rest.z));
    return {index[0], index[1], index[2]};
  }
};

IndexMap makeIndexMap(const openvdb::math::Transform& transform, const glm::dmat4& worldToRest,
                      const SpaceDeformation* deformation) {
  IndexMap map;
  map.worldToRest = worldToRest;
  map.transform = &transform;
  map.deformation = deformation;
  const bool restIsAffine =
      worldToRest[0][3] == 0.0 && worldToRest[1][3] == 0.0 && worldToRest[2][3] == 0.0 && worldToRest[3][3] == 1.0;
  if (!transform.isLinear() || !restIsAffine || deformation) return map;

  // OpenVDB matrices act on row vectors: index = rest * M, translation in row 3.
  const openvdb::Mat4d restToIndex = transform.baseMap()->getAffineMap()->getMat4().inverse();
  glm::dmat3 indexFromRest;
  glm::dvec3 indexOffset;
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) indexFromRest[col][row] = restToIndex(col, row);
    indexOffset[row] = restToIndex(3, row);
  }
  map.linear = indexFromRest * glm::dmat3(worldToRest);
  map.translation = indexFromRest * glm::dvec3(worldToRest[3]) + indexOffset;
  map.kind = IndexMap::Kind::Affine;

  double largest = 0.0, offDiagonal = 0.0;
  for (int col = 0; col < 3; ++col)
    for (int row = 0; row < 3; ++row) {
      largest = std::max(largest, std::abs(map.linear[col][row]));
      if (col != row) offDiagonal = std::max(offDiagonal, std::abs(map.linear[col][row]));
    }
  // Round-off of a composed rotation by exactly 0/90 degrees leaves ~1e-16 terms.
  if (offDiagonal <= 1e-12 * largest) {
    map.kind = IndexMap::Kind::AxisAligned;
    for (int a = 0; a < 3; ++a) map.scale[a] = map.linear[a][a];
    map.offset = map.translation;
  }
  return map;
}

/// ∫ from -inf to x of the unit hat max(0, 1 - |t|).
double hatIntegral(double x) {
  if (x <= -1.0) return 0.0;
  if (x <= 0.0) return 0.5 * (x + 1.0) * (x + 1.0);
  if (x < 1.0) return 1.0 - 0.5 * (1.0 - x) * (1.0 - x);
  return 1.0;
}

/// The voxels along one axis that carry weight, restricted to [activeLo, activeHi]
/// (only active voxels are read), and their weights.
struct AxisWeights {
  int first = 0;
  int count = 0;
  std::vector<double> weight;  ///< weight[i - first]

  /// Mean of each hat over the index interval [a, b].
  bool setInterval(double a, double b, int activeLo, int activeHi) {
    // Neighbouring cells of a row share their y and z intervals: keep the last result.
    if (a == lastA_ && b == lastB_ && activeLo == lastLo_ && activeHi == lastHi_) return lastResult_;
    lastA_ = a;
    lastB_ = b;
    lastLo_ = activeLo;
    lastHi_ = activeHi;
    lastResult_ = computeInterval(a, b, activeLo, activeHi);
    return lastResult_;
  }

 private:
  /// Point sample at index coordinate p: the hats of floor(p) and floor(p)+1.
  bool setPoint(double p, int activeLo, int activeHi) {
    if (!std::isfinite(p)) return false;
    const double base = std::floor(p);
    return setRange(base, base + 1.0, activeLo, activeHi,
                    [&](double i) { return std::max(0.0, 1.0 - std::abs(p - i)); });
  }

  bool computeInterval(double a, double b, int activeLo, int activeHi) {
    if (!std::isfinite(a) || !std::isfinite(b)) return false;
    const double length = b - a;
    if (length <= 1e-9 * std::max(1.0, std::abs(a))) return setPoint(0.5 * (a + b), activeLo, activeHi);
    return setRange(std::floor(a), std::ceil(b), activeLo, activeHi,
                    [&](double i) { return (hatIntegral(b - i) - hatIntegral(a - i)) / length; });
  }

  template <class WeightOf>
  bool setRange(double lo, double hi, int activeLo, int activeHi, WeightOf weightOf) {
    lo = std::max(lo, double(activeLo));
    hi = std::min(hi, double(activeHi));
    if (lo > hi) return false;
    first = int(lo);
    count = int(hi) - first + 1;
    weight.resize(std::size_t(count));
    for (int k = 0; k < count; ++k) weight[std::size_t(k)] = weightOf(double(first + k));
    return true;
  }

  double lastA_ = std::numeric_limits<double>::quiet_NaN(), lastB_ = lastA_;  // NaN: nothing cached
  int lastLo_ = 0, lastHi_ = 0;
  bool lastResult_ = false;
};

/// One AxisWeights per axis and grid, so each grid's y and z weights survive the row.
struct BoxWeights {
  AxisWeights x, y, z;
};

/// Σ over the active values in the weighted index box of (scale·v − base)·wx·wy·wz.
/// Walks leaf-sized blocks: a leaf's voxels are read straight from its buffer, and a
/// block without a leaf lies inside one tile (or the background), a single value.
template <class TreeT>
typename Channel<TreeT>::Sum weightedDeviation(ConstAccessor<TreeT>& accessor, const AxisWeights& wx,
                                               const AxisWeights& wy, const AxisWeights& wz, double scale,
                                               const typename Channel<TreeT>::Sum& base) {
  using LeafT = typename TreeT::LeafNodeType;
  using Sum = typename Channel<TreeT>::Sum;
  constexpr int kDim = int(LeafT::DIM);
  const openvdb::Coord lo(wx.first, wy.first, wz.first);
  const openvdb::Coord hi(wx.first + wx.count - 1, wy.first + wy.count - 1, wz.first + wz.count - 1);
  Sum total(0.0);
  for (int bz = lo.z() & ~(kDim - 1); bz <= hi.z(); bz += kDim) {
    const int z0 = std::max(bz, lo.z()), z1 = std::min(bz + kDim - 1, hi.z());
    for (int by = lo.y() & ~(kDim - 1); by <= hi.y(); by += kDim) {
      const int y0 = std::max(by, lo.y()), y1 = std::min(by + kDim - 1, hi.y());
      for (int bx = lo.x() & ~(kDim - 1); bx <= hi.x(); bx += kDim) {
        const int x0 = std::max(bx, lo.x()), x1 = std::min(bx + kDim - 1, hi.x());
        const openvdb::Coord origin(bx, by, bz);
        if (const LeafT* leaf = accessor.probeConstLeaf(origin)) {
          // Raw buffer and mask: LeafNode::getValue re-checks delayed loading per voxel.
          // Leaf memory is x-major (offset = 64x + 8y + z), so z runs innermost.
          const typename TreeT::ValueType* values = leaf->buffer().data();
          const auto& mask = leaf->getValueMask();
          for (int x = x0; x <= x1; ++x) {
            const double weightX = wx.weight[std::size_t(x - lo.x())];
            if (weightX == 0.0) continue;
            for (int y = y0; y <= y1; ++y) {
              const double weightXY = weightX * wy.weight[std::size_t(y - lo.y())];
              if (weightXY == 0.0) continue;
              const openvdb::Index row = LeafT::coordToOffset(openvdb::Coord(x, y, z0));
              for (int z = z0; z <= z1; ++z) {
                const openvdb::Index offset = row + openvdb::Index(z - z0);
                if (!mask.isOn(offset)) continue;
                const double weight = weightXY * wz.weight[std::size_t(z - lo.z())];
                total += weight * (scale * Channel<TreeT>::read(values[offset]) - base);
              }
            }
          }
        } else {
          typename TreeT::ValueType value;
          if (!accessor.probeValue(origin, value)) continue;  // inactive tile or background: base
          double sumX = 0.0, sumY = 0.0, sumZ = 0.0;
          for (int x = x0; x <= x1; ++x) sumX += wx.weight[std::size_t(x - lo.x())];
          for (int y = y0; y <= y1; ++y) sumY += wy.weight[std::size_t(y - lo.y())];
          for (int z = z0; z <= z1; ++z) sumZ += wz.weight[std::size_t(z - lo.z())];
          total += (sumX * sumY * sumZ) * (scale * Channel<TreeT>::read(value) - base);
        }
      }
    }
  }
  return total;
}

}  // namespace

/// One grid of the set as the field sees it.
template <class TreeT>
struct FieldChannel {
  const TreeT* tree = nullptr;  ///< null: the grid is absent, base everywhere
  IndexMap map;
  openvdb::CoordBBox active;  ///< active voxels and tiles; only these are read
  double scale = 1.0;         ///< multiplies the grid's values (sigmaScale for σ)
  typename Channel<TreeT>::Sum base{};
};

struct MaterialField::Prepared {
  std::shared_ptr<const MaterialSet> set;  ///< keeps the trees alive
  std::shared_ptr<const SpaceDeformation> deformation;  ///< keeps the channels' maps' pose alive
  FieldChannel<openvdb::Vec3STree> sigmaT, sigmaS;
  FieldChannel<openvdb::FloatTree> g;
};

namespace {

template <class GridT>
FieldChannel<typename GridT::TreeType> prepareChannel(const typename GridT::Ptr& grid, const glm::dmat4& worldToRest,
                                                      const SpaceDeformation* deformation, double scale,
                                                      const typename Channel<typename GridT::TreeType>::Sum& base) {
  FieldChannel<typename GridT::TreeType> channel;
  channel.scale = scale;
  channel.base = base;
  if (!grid) return channel;
  openvdb::CoordBBox active;
  if (!grid->tree().evalActiveVoxelBoundingBox(active)) return channel;  // nothing active: base
  channel.tree = &grid->tree();
  channel.active = active;
  channel.map = makeIndexMap(grid->constTransform(), worldToRest, deformation);
  return channel;
}

}  // namespace

MaterialField::MaterialField(const MaterialSample& base, std::shared_ptr<const MaterialSet> set,
                             const glm::dmat4& worldToRest, double sigmaScale,
                             std::shared_ptr<const SpaceDeformation> deformation)
    : base_(base),
      set_(std::move(set)),
      worldToRest_(worldToRest),
      sigmaScale_(sigmaScale),
      deformation_(std::move(deformation)) {
  if (!std::isfinite(sigmaScale) || sigmaScale < 0.0)
    throw std::invalid_argument("MaterialField: sigmaScale must be finite and non-negative");
  if (!set_) return;
  auto prepared = std::make_shared<Prepared>();
  prepared->set = set_;
  prepared->deformation = deformation_;
  const SpaceDeformation* pose = deformation_.get();
  prepared->sigmaT =
      prepareChannel<openvdb::Vec3SGrid>(set_->sigmaT, worldToRest_, pose, sigmaScale_, glm::dvec3(base_.sigmaT));
  prepared->sigmaS =
      prepareChannel<openvdb::Vec3SGrid>(set_->sigmaS, worldToRest_, pose, sigmaScale_, glm::dvec3(base_.sigmaS));
  prepared->g = prepareChannel<openvdb::FloatGrid>(set_->g, worldToRest_, pose, 1.0, double(base_.g));
  prepared_ = std::move(prepared);
}

struct MaterialField::Sampler::Impl {
  MaterialSample base;
  std::shared_ptr<const Prepared> prepared;  ///< null when the field is homogeneous
  std::optional<ConstAccessor<openvdb::Vec3STree>> sigmaT, sigmaS;
  std::optional<ConstAccessor<openvdb::FloatTree>> g;
  BoxWeights sigmaTWeights, sigmaSWeights, gWeights;  ///< scratch: no per-sample allocation

  /// The trilinear deviation from the base at index point p: the 8 voxels around p.
  template <class TreeT>
  typename Channel<TreeT>::Sum pointDeviation(const FieldChannel<TreeT>& channel, ConstAccessor<TreeT>& accessor,
                                              const glm::dvec3& index) {
    using Sum = typename Channel<TreeT>::Sum;
    const openvdb::Coord& lo = channel.active.min();
    const openvdb::Coord& hi = channel.active.max();
    // Also rejects NaN and coordinates beyond int range before they are converted.
    if (!(index.x > lo.x() - 1.0 && index.x < hi.x() + 1.0 && index.y > lo.y() - 1.0 && index.y < hi.y() + 1.0 &&
          index.z > lo.z() - 1.0 && index.z < hi.z() + 1.0))
      return Sum(0.0);
    const glm::dvec3 corner = glm::floor(index);
    const glm::dvec3 f = index - corner;
    const openvdb::Coord origin(int(corner.x), int(corner.y), int(corner.z));
    using LeafT = typename TreeT::LeafNodeType;
    constexpr int kLast = int(LeafT::DIM) - 1;
    Sum total(0.0);
    typename TreeT::ValueType value;
    if ((origin.x() & kLast) != kLast && (origin.y() & kLast) != kLast && (origin.z() & kLast) != kLast) {
      // All 8 voxels in one leaf-sized block, the common case: one tree lookup.
      if (const LeafT* leaf = accessor.probeConstLeaf(origin)) {
        const typename TreeT::ValueType* values = leaf->buffer().data();
        const auto& mask = leaf->getValueMask();
        const openvdb::Index first = LeafT::coordToOffset(origin);
        for (int dx = 0; dx < 2; ++dx)
          for (int dy = 0; dy < 2; ++dy)
            for (int dz = 0; dz < 2; ++dz) {
              const openvdb::Index offset =
                  first + openvdb::Index((dx << (2 * LeafT::LOG2DIM)) + (dy << LeafT::LOG2DIM) + dz);
              if (!mask.isOn(offset)) continue;
              const double weight = (dx ? f.x : 1.0 - f.x) * (dy ? f.y : 1.0 - f.y) * (dz ? f.z : 1.0 - f.z);
              total += weight * (channel.scale * Channel<TreeT>::read(values[offset]) - channel.base);
            }
        return total;
      }
      // No leaf: the block lies in one tile or the background, whose weights sum to 1.
      if (accessor.probeValue(origin, value)) total = channel.scale * Channel<TreeT>::read(value) - channel.base;
      return total;
    }
    for (int dz = 0; dz < 2; ++dz) {
      const double weightZ = dz ? f.z : 1.0 - f.z;
      if (weightZ == 0.0) continue;
      for (int dy = 0; dy < 2; ++dy) {
        const double weightYZ = weightZ * (dy ? f.y : 1.0 - f.y);
        if (weightYZ == 0.0) continue;
        for (int dx = 0; dx < 2; ++dx) {
          const double weight = weightYZ * (dx ? f.x : 1.0 - f.x);
          if (weight == 0.0 || !accessor.probeValue(origin.offsetBy(dx, dy, dz), value)) continue;
          total += weight * (channel.scale * Channel<TreeT>::read(value) - channel.base);
        }
      }
    }
    return total;
  }

  template <class TreeT>
  typename Channel<TreeT>::Sum boxDeviation(const FieldChannel<TreeT>& channel, ConstAccessor<TreeT>& accessor,
                                            BoxWeights& weights, const glm::dvec3& worldMin,
                                            const glm::dvec3& worldMax) {
    using Sum = typename Channel<TreeT>::Sum;
    const IndexMap& map = channel.map;
    if (map.kind == IndexMap::Kind::AxisAligned) {
      const glm::dvec3 a = map.toIndex(worldMin), b = map.toIndex(worldMax);
      const openvdb::Coord& lo = channel.active.min();
      const openvdb::Coord& hi = channel.active.max();
      if (!weights.x.setInterval(std::min(a.x, b.x), std::max(a.x, b.x), lo.x(), hi.x()) ||
          !weights.y.setInterval(std::min(a.y, b.y), std::max(a.y, b.y), lo.y(), hi.y()) ||
          !weights.z.setInterval(std::min(a.z, b.z), std::max(a.z, b.z), lo.z(), hi.z()))
        return Sum(0.0);
      return weightedDeviation<TreeT>(accessor, weights.x, weights.y, weights.z, channel.scale, channel.base);
    }
    // Rotated or non-linear: a 4x4x4 stratified (cell-centred) average of point samples.
    constexpr int kStrata = 4;
    const glm::dvec3 step = (worldMax - worldMin) / double(kStrata);
    Sum total(0.0);
    for (int k = 0; k < kStrata; ++k)
      for (int j = 0; j < kStrata; ++j)
        for (int i = 0; i < kStrata; ++i) {
          const glm::dvec3 world = worldMin + step * (glm::dvec3(i, j, k) + 0.5);
          total += pointDeviation(channel, accessor, map.toIndex(world));
        }
    return total / double(kStrata * kStrata * kStrata);
  }
};

MaterialField::Sampler MaterialField::sampler() const {
  Sampler sampler;
  sampler.impl_ = std::make_shared<Sampler::Impl>();
  Sampler::Impl& impl = *sampler.impl_;
  impl.base = base_;
  impl.prepared = prepared_;
  if (prepared_) {
    if (prepared_->sigmaT.tree) impl.sigmaT.emplace(*prepared_->sigmaT.tree);
    if (prepared_->sigmaS.tree) impl.sigmaS.emplace(*prepared_->sigmaS.tree);
    if (prepared_->g.tree) impl.g.emplace(*prepared_->g.tree);
  }
  return sampler;
}

MaterialSample MaterialField::Sampler::sample(const glm::dvec3& world) const {
  Impl& impl = *impl_;
  if (!impl.prepared) return impl.base;
  const Prepared& prepared = *impl.prepared;
  glm::dvec3 sigmaT(impl.base.sigmaT), sigmaS(impl.base.sigmaS);
  double g = impl.base.g;
  if (impl.sigmaT) sigmaT += impl.pointDeviation(prepared.sigmaT, *impl.sigmaT, prepared.sigmaT.map.toIndex(world));
  if (impl.sigmaS) sigmaS += impl.pointDeviation(prepared.sigmaS, *impl.sigmaS, prepared.sigmaS.map.toIndex(world));
  if (impl.g) g += impl.pointDeviation(prepared.g, *impl.g, prepared.g.map.toIndex(world));
  return MaterialSample{glm::vec3(sigmaT), glm::vec3(sigmaS), float(g)};
}

MaterialSample MaterialField::Sampler::boxAverage(const glm::dvec3& worldMin, const glm::dvec3& worldMax) const {
  Impl& impl = *impl_;
  if (!impl.prepared) return impl.base;
  const Prepared& prepared = *impl.prepared;
  const glm::dvec3 lo = glm::min(worldMin, worldMax), hi = glm::max(worldMin, worldMax);
  glm::dvec3 sigmaT(impl.base.sigmaT), sigmaS(impl.base.sigmaS);
  double g = impl.base.g;
  if (prepared.deformation) {
    // Every channel's map is General and shares the way back to rest space, the deformers'
    // inverse, which was most of a deformed resample's time. It is evaluated at the box's 8
    // corners only, and boxDeviation's 4x4x4 strata take their rest points trilinearly
    // from them, once for all three channels. The deformers are smooth: over a box of
    // size h bent with radius R the interpolated point is off by about h² / (8 R), 0.2 %
    // of a cell for the shipped bending bar at 32³ (R ≥ 76 mm at its mid-bend), far below
    // a painted voxel.
    constexpr int kStrata = 4;
    const IndexMap& shared = prepared.sigmaT.tree ? prepared.sigmaT.map
                             : prepared.sigmaS.tree ? prepared.sigmaS.map
                                                    : prepared.g.map;
    glm::dvec3 corner[2][2][2];
    for (int c = 0; c < 8; ++c)
      corner[c >> 2][(c >> 1) & 1][c & 1] = shared.toRest(glm::mix(lo, hi, glm::dvec3(c & 1, (c >> 1) & 1, c >> 2)));
    glm::dvec3 dT(0.0), dS(0.0);
    double dG = 0.0;
    for (int k = 0; k < kStrata; ++k)
      for (int j = 0; j < kStrata; ++j)
        for (int i = 0; i < kStrata; ++i) {
          const glm::dvec3 f = (glm::dvec3(i, j, k) + 0.5) / double(kStrata);
          const auto alongX = [&](int z, int y) { return glm::mix(corner[z][y][0], corner[z][y][1], f.x); };
          const glm::dvec3 rest = glm::mix(glm::mix(alongX(0, 0), alongX(0, 1), f.y),
                                           glm::mix(alongX(1, 0), alongX(1, 1), f.y), f.z);
          if (impl.sigmaT)
            dT += impl.pointDeviation(prepared.sigmaT, *impl.sigmaT, prepared.sigmaT.map.restToIndex(rest));
          if (impl.sigmaS)
            dS += impl.pointDeviation(prepared.sigmaS, *impl.sigmaS, prepared.sigmaS.map.restToIndex(rest));
          if (impl.g) dG += impl.pointDeviation(prepared.g, *impl.g, prepared.g.map.restToIndex(rest));
        }
    constexpr double kSamples = double(kStrata * kStrata * kStrata);
    return MaterialSample{glm::vec3(sigmaT + dT / kSamples), glm::vec3(sigmaS + dS / kSamples),
                          float(g + dG / kSamples)};
  }
  if (impl.sigmaT) sigmaT += impl.boxDeviation(prepared.sigmaT, *impl.sigmaT, impl.sigmaTWeights, lo, hi);
  if (impl.sigmaS) sigmaS += impl.boxDeviation(prepared.sigmaS, *impl.sigmaS, impl.sigmaSWeights, lo, hi);
  if (impl.g) g += impl.boxDeviation(prepared.g, *impl.g, impl.gWeights, lo, hi);
  return MaterialSample{glm::vec3(sigmaT), glm::vec3(sigmaS), float(g)};
}

}  // namespace sslpv
