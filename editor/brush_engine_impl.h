#pragma once
// Internals of the brush engine, shared by its two halves: brush_engine.cpp (construction,
// brush resolution, stroke paths, history, the public API) and brush_paint.cpp (dabs and
// the per-voxel update). Only those two files include this header.
#include <openvdb/openvdb.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <memory>
#include <optional>
#include <vector>

#include "editor/brush_engine.h"
#include "volume/scene/ray_scene.h"

namespace sslpv {
namespace brush_detail {

using openvdb::Coord;
using openvdb::Vec3s;
using Vec3Accessor = openvdb::Vec3SGrid::Accessor;
using FloatAccessor = openvdb::FloatGrid::Accessor;

// Channel order of a voxel's material as doubles: σt rgb, σs rgb, g.
constexpr int kChannels = 7;

struct VoxelState {
  Vec3s t{0.0f}, s{0.0f};
  float g = 0.0f;
  std::uint8_t active = 0;  ///< bit 0: σt, bit 1: σs, bit 2: g
};

inline bool sameBits(const VoxelState& a, const VoxelState& b) {
  return a.active == b.active && std::memcmp(a.t.asPointer(), b.t.asPointer(), 3 * sizeof(float)) == 0 &&
         std::memcmp(a.s.asPointer(), b.s.asPointer(), 3 * sizeof(float)) == 0 &&
         std::memcmp(&a.g, &b.g, sizeof(float)) == 0;
}

struct VoxelRecord {
  Coord ijk;
  VoxelState before, after;
};

struct HistoryEntry {
  std::vector<VoxelRecord> records;
  StrokeResult result;
};

struct Accessors {
  Vec3Accessor t, s;
  FloatAccessor g;
  explicit Accessors(MaterialSet& set)
      : t(set.sigmaT->getAccessor()), s(set.sigmaS->getAccessor()), g(set.g->getAccessor()) {}

  VoxelState read(const Coord& ijk) {
    VoxelState v;
    v.active = std::uint8_t((t.probeValue(ijk, v.t) ? 1 : 0) | (s.probeValue(ijk, v.s) ? 2 : 0) |
                            (g.probeValue(ijk, v.g) ? 4 : 0));
    return v;
  }
  void write(const Coord& ijk, const VoxelState& v) {
    if (v.active & 1)
      t.setValueOn(ijk, v.t);
    else
      t.setValueOff(ijk, v.t);
    if (v.active & 2)
      s.setValueOn(ijk, v.s);
    else
      s.setValueOff(ijk, v.s);
    if (v.active & 4)
      g.setValueOn(ijk, v.g);
    else
      g.setValueOff(ijk, v.g);
  }
};

/// An index-space box, inclusive.
struct IndexBox {
  Coord lo{INT32_MAX}, hi{INT32_MIN};
  bool empty() const { return lo.x() > hi.x() || lo.y() > hi.y() || lo.z() > hi.z(); }
  void extend(const Coord& c) {
    lo.minComponent(c);
    hi.maxComponent(c);
  }
  bool contains(const Coord& c) const {
    return c.x() >= lo.x() && c.x() <= hi.x() && c.y() >= lo.y() && c.y() <= hi.y() && c.z() >= lo.z() &&
           c.z() <= hi.z();
  }
  double voxels() const {
    return empty() ? 0.0 : double(hi.x() - lo.x() + 1) * double(hi.y() - lo.y() + 1) * double(hi.z() - lo.z() + 1);
  }
};

/// Effective material (inactive = base) of a box's voxels, read before a dab changes them.
struct Snapshot {
  IndexBox box;
  std::vector<float> values;  // kChannels per voxel, x fastest
  const float* at(const Coord& c) const {
    const std::size_t nx = std::size_t(box.hi.x() - box.lo.x() + 1), ny = std::size_t(box.hi.y() - box.lo.y() + 1);
    return &values[kChannels * ((std::size_t(c.z() - box.lo.z()) * ny + std::size_t(c.y() - box.lo.y())) * nx +
                                std::size_t(c.x() - box.lo.x()))];
  }
};

/// The brush resolved against the set: which channels it drives and its values in set units.
struct Resolved {
  bool drive[kChannels] = {};
  double value[kChannels] = {};  // set target, add value or multiply factor
  double radiusRest = 1.0;
  double spacing = 0.25;  // world units
  bool mirror = false;
  int mirrorAxis = 0;
  bool latticeMirror = false;
  int twicePlaneIndex = 0;  // lattice: mirror index i -> twicePlaneIndex - i
  double planeRest = 0.0;
};

struct SurfaceHit {
  SurfaceRay ray;
  glm::dvec3 position{0.0}, normal{0.0};
};

}  // namespace brush_detail

struct BrushEngine::Impl {
  // The shared types under their short names, for the member definitions in both files.
  using Coord = brush_detail::Coord;
  using VoxelRecord = brush_detail::VoxelRecord;
  using HistoryEntry = brush_detail::HistoryEntry;
  using Accessors = brush_detail::Accessors;
  using IndexBox = brush_detail::IndexBox;
  using Snapshot = brush_detail::Snapshot;
  using Resolved = brush_detail::Resolved;
  using SurfaceHit = brush_detail::SurfaceHit;
  static constexpr int kChannels = brush_detail::kChannels;

  PaintTarget target;
  MaterialSample base;  // set units
  double baseValue[kChannels] = {};
  double sigmaToSet = 1.0;
  glm::dmat3 indexToRest{1.0}, restToIndex{1.0};
  glm::dvec3 indexToRestOffset{0.0}, restToIndexOffset{0.0};
  bool axisAligned = false;
  glm::dmat4 worldToRest{1.0};
  double scale = 1.0;
  std::unique_ptr<RayScene> rayScene;

  std::vector<HistoryEntry> history;
  std::size_t applied = 0;  // history[0, applied) is applied; the rest can be redone

  // The stroke in progress.
  bool inStroke = false;
  Brush brush;
  Resolved resolved;
  std::vector<VoxelRecord> records;
  openvdb::Int32Tree recordIndex{-1};
  std::optional<glm::dvec3> lastPoint;
  std::optional<SurfaceHit> lastHit;
  std::size_t dabs = 0, raysMissed = 0;

  glm::dvec3 rest(const Coord& c) const { return indexToRest * glm::dvec3(c.x(), c.y(), c.z()) + indexToRestOffset; }
  glm::dvec3 index(const glm::dvec3& restPoint) const { return restToIndex * restPoint + restToIndexOffset; }
  glm::dvec3 worldToRestPoint(const glm::dvec3& p) const { return glm::dvec3(worldToRest * glm::dvec4(p, 1.0)); }

  Coord mirrorIndex(Coord c) const {
    c[resolved.mirrorAxis] = resolved.twicePlaneIndex - c[resolved.mirrorAxis];
    return c;
  }

  // Brush and stroke paths (brush_engine.cpp).
  double planeFor(const BrushMirror& mirror, int* twiceIndex) const;
  void resolve(const Brush& b);
  /// Dabs from `from` (exclusive) to `to` (inclusive) at a spacing of at most radius/4.
  void segmentDabs(const glm::dvec3& from, const glm::dvec3& to, std::vector<glm::dvec3>& dabsOut) const;
  std::optional<SurfaceHit> cast(const SurfaceRay& ray) const;
  void fillBetween(const SurfaceHit& a, const SurfaceHit& b, int level, std::vector<SurfaceHit>& out) const;

  // Painting (brush_paint.cpp).
  Bounds worldBounds(const IndexBox& box) const;
  IndexBox sphereBox(const glm::dvec3& centre, double radius) const;
  Snapshot snapshot(Accessors& acc, const IndexBox& inner) const;
  /// Paints one voxel with brush amount t; returns whether it was written.
  bool paintVoxel(Accessors& acc, openvdb::tree::ValueAccessor<openvdb::Int32Tree>& indexAcc, const Coord& ijk,
                  double t, const Snapshot* snap);
  /// One dab (with its mirror) at a rest-space centre.
  void applyDab(const glm::dvec3& centre, DabResult& out, IndexBox& written);
  DabResult applyDabs(const std::vector<glm::dvec3>& worldDabs, std::size_t missed);
};

}  // namespace sslpv
