// The brush engine (formulas and conventions in brush_engine.h).
#include "editor/brush_engine.h"

#include <openvdb/math/Maps.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <stdexcept>

#include "volume/error.h"
#include "volume/ray_scene.h"

namespace sslpv {
namespace {

using openvdb::Coord;
using openvdb::Vec3s;
using Vec3Accessor = openvdb::Vec3SGrid::Accessor;
using FloatAccessor = openvdb::FloatGrid::Accessor;

constexpr double kMaxDabVoxels = double(1 << 26);
constexpr std::size_t kMaxDabsPerCall = 1000000;
constexpr int kMaxRayBisections = 12;
// Channel order of a voxel's material as doubles: σt rgb, σs rgb, g.
constexpr int kChannels = 7;

struct VoxelState {
  Vec3s t{0.0f}, s{0.0f};
  float g = 0.0f;
  std::uint8_t active = 0;  ///< bit 0: σt, bit 1: σs, bit 2: g
};

bool sameBits(const VoxelState& a, const VoxelState& b) {
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

}  // namespace

struct BrushEngine::Impl {
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

  Bounds worldBounds(const IndexBox& box) const {
    Bounds bounds;
    if (box.empty()) return bounds;
    for (int corner = 0; corner < 8; ++corner) {
      const Coord c((corner & 1) ? box.hi.x() + 1 : box.lo.x() - 1, (corner & 2) ? box.hi.y() + 1 : box.lo.y() - 1,
                    (corner & 4) ? box.hi.z() + 1 : box.lo.z() - 1);
      bounds.extend(glm::dvec3(target.restToWorld * glm::dvec4(rest(c), 1.0)));
    }
    return bounds;
  }

  IndexBox sphereBox(const glm::dvec3& centre, double radius) const {
    glm::dvec3 lo(1e300), hi(-1e300);
    for (int corner = 0; corner < 8; ++corner) {
      const glm::dvec3 p =
          centre + radius * glm::dvec3((corner & 1) ? 1 : -1, (corner & 2) ? 1 : -1, (corner & 4) ? 1 : -1);
      const glm::dvec3 i = index(p);
      lo = glm::min(lo, i);
      hi = glm::max(hi, i);
    }
    auto clampInt = [](double v) { return int(std::clamp(v, -1.0e9, 1.0e9)); };
    IndexBox box;
    box.lo = Coord(clampInt(std::floor(lo.x)), clampInt(std::floor(lo.y)), clampInt(std::floor(lo.z)));
    box.hi = Coord(clampInt(std::ceil(hi.x)), clampInt(std::ceil(hi.y)), clampInt(std::ceil(hi.z)));
    return box;
  }

  Coord mirrorIndex(Coord c) const {
    c[resolved.mirrorAxis] = resolved.twicePlaneIndex - c[resolved.mirrorAxis];
    return c;
  }

  double planeFor(const BrushMirror& mirror, int* twiceIndex) const {
    const int a = mirror.axis;
    const Bounds& rb = target.restBounds;
    double at = mirror.at ? *mirror.at : (rb.empty() ? 0.0 : 0.5 * (rb.min[a] + rb.max[a]));
    if (!axisAligned) return at;
    // Index coordinate of the plane, snapped to a multiple of 1/2 so that mirrored voxel
    // centres coincide with voxel centres.
    const double twice = std::round(2.0 * (at - indexToRestOffset[a]) / indexToRest[a][a]);
    if (std::abs(twice) > 2.0e9) throw InputError("mirror.at: plane too far from the grid");
    if (twiceIndex) *twiceIndex = int(twice);
    return indexToRestOffset[a] + indexToRest[a][a] * (twice / 2.0);
  }

  void resolve(const Brush& b) {
    if (std::string problem = brushProblem(b); !problem.empty()) throw InputError(problem);
    Resolved r;
    r.radiusRest = b.radius / scale;
    r.spacing = b.radius / 4.0;
    const double k = sigmaToSet;
    auto driveRgb = [&](int first, const glm::dvec3& v, bool isSigma) {
      for (int c = 0; c < 3; ++c) {
        r.drive[first + c] = true;
        r.value[first + c] = isSigma ? v[c] * k : v[c];
      }
    };
    const bool sigmaValue = b.mode == BrushMode::Set || b.mode == BrushMode::Add;
    switch (b.channel) {
      case BrushChannel::SigmaT:
        driveRgb(0, b.rgb, sigmaValue);
        break;
      case BrushChannel::SigmaS:
        driveRgb(3, b.rgb, sigmaValue);
        break;
      case BrushChannel::G:
        r.drive[6] = true;
        r.value[6] = b.scalar;
        break;
      case BrushChannel::AlbedoMfp: {
        const glm::dvec3 sigmaT = 1.0 / b.meanFreePath;
        driveRgb(0, sigmaT, true);
        driveRgb(3, b.albedo * sigmaT, true);
        break;
      }
      case BrushChannel::Preset: {
        const MaterialSample p = *presetMaterial(b.preset, 0.0f, target.sceneUnitInMm);
        driveRgb(0, glm::dvec3(p.sigmaT), true);
        driveRgb(3, glm::dvec3(p.sigmaS), true);
        r.drive[6] = true;
        r.value[6] = 0.0;
        break;
      }
      case BrushChannel::All:
        for (bool& d : r.drive) d = true;
        break;
    }
    if (b.mirror) {
      r.mirror = true;
      r.mirrorAxis = b.mirror->axis;
      r.latticeMirror = axisAligned;
      r.planeRest = planeFor(*b.mirror, &r.twicePlaneIndex);
    }
    resolved = r;
  }

  Snapshot snapshot(Accessors& acc, const IndexBox& inner) const {
    Snapshot snap;
    snap.box.lo = inner.lo.offsetBy(-1);
    snap.box.hi = inner.hi.offsetBy(1);
    snap.values.resize(std::size_t(snap.box.voxels()) * kChannels);
    float* out = snap.values.data();
    for (int z = snap.box.lo.z(); z <= snap.box.hi.z(); ++z)
      for (int y = snap.box.lo.y(); y <= snap.box.hi.y(); ++y)
        for (int x = snap.box.lo.x(); x <= snap.box.hi.x(); ++x, out += kChannels) {
          const VoxelState v = acc.read(Coord(x, y, z));
          for (int c = 0; c < 3; ++c) {
            out[c] = (v.active & 1) ? v.t[c] : base.sigmaT[c];
            out[3 + c] = (v.active & 2) ? v.s[c] : base.sigmaS[c];
          }
          out[6] = (v.active & 4) ? v.g : base.g;
        }
    return snap;
  }

  /// Paints one voxel with brush amount t; returns whether it was written.
  bool paintVoxel(Accessors& acc, openvdb::tree::ValueAccessor<openvdb::Int32Tree>& indexAcc, const Coord& ijk,
                  double t, const Snapshot* snap) {
    const VoxelState old = acc.read(ijk);
    double x[kChannels];
    for (int c = 0; c < 3; ++c) {
      x[c] = (old.active & 1) ? old.t[c] : base.sigmaT[c];
      x[3 + c] = (old.active & 2) ? old.s[c] : base.sigmaS[c];
    }
    x[6] = (old.active & 4) ? old.g : base.g;

    double avg[kChannels] = {};
    if (snap) {
      // Summed as (left + right) + centre along x, then y, then z: a reflection of the
      // neighbourhood along any axis gives the same rounding, so mirrored smoothing stays
      // bit-exactly symmetric.
      for (int c = 0; c < kChannels; ++c) {
        double planes[3];
        for (int dz = -1; dz <= 1; ++dz) {
          double rows[3];
          for (int dy = -1; dy <= 1; ++dy) {
            auto at = [&](int dx) { return double(snap->at(ijk.offsetBy(dx, dy, dz))[c]); };
            rows[dy + 1] = (at(-1) + at(1)) + at(0);
          }
          planes[dz + 1] = (rows[0] + rows[2]) + rows[1];
        }
        avg[c] = ((planes[0] + planes[2]) + planes[1]) / 27.0;
      }
    }
    const BrushMode mode = brush.mode;
    for (int c = 0; c < kChannels; ++c) {
      if (!resolved.drive[c]) continue;
      const double v = resolved.value[c];
      switch (mode) {
        case BrushMode::Add:
          x[c] = x[c] + t * v;
          break;
        case BrushMode::Multiply:
          x[c] = x[c] * (1.0 + t * (v - 1.0));
          break;
        case BrushMode::Set:
        case BrushMode::Smooth:
        case BrushMode::Erase: {
          const double goal = mode == BrushMode::Set ? v : mode == BrushMode::Smooth ? avg[c] : baseValue[c];
          x[c] = t >= 1.0 ? goal : x[c] + t * (goal - x[c]);
          break;
        }
      }
    }
    // Validity: σt in [0, FLT_MAX], σs in [0, σt], |g| <= 0.99 (NaN cannot reach here:
    // every input is finite, and double does not overflow on these products).
    VoxelState now;
    for (int c = 0; c < 3; ++c) {
      const double st = x[c] > 0.0 ? std::min(x[c], double(FLT_MAX)) : 0.0;
      const double ss = x[3 + c] > 0.0 ? std::min(x[3 + c], st) : 0.0;
      now.t[c] = float(st);
      now.s[c] = float(ss);
    }
    now.g = float(std::clamp(x[6], -double(kBrushMaxG), double(kBrushMaxG)));

    bool isBase = now.g == base.g;
    for (int c = 0; c < 3; ++c) isBase = isBase && now.t[c] == base.sigmaT[c] && now.s[c] == base.sigmaS[c];
    if (isBase) {
      if (old.active == 0) return false;
      now.t = acc.t.tree().background();
      now.s = acc.s.tree().background();
      now.g = acc.g.tree().background();
      now.active = 0;
    } else {
      now.active = 7;
      if (sameBits(now, old)) return false;
    }
    int recorded = -1;
    if (!indexAcc.probeValue(ijk, recorded)) {
      indexAcc.setValueOn(ijk, int(records.size()));
      records.push_back({ijk, old, old});
    }
    acc.write(ijk, now);
    return true;
  }

  /// One dab (with its mirror) at a rest-space centre.
  void applyDab(const glm::dvec3& centre, DabResult& out, IndexBox& written) {
    const Resolved& r = resolved;
    IndexBox boxes[2];
    int count = 1;
    boxes[0] = sphereBox(centre, r.radiusRest);
    glm::dvec3 mirroredCentre = centre;
    if (r.mirror) {
      if (r.latticeMirror) {
        const int a = r.mirrorAxis;
        boxes[1] = boxes[0];
        boxes[1].lo[a] = r.twicePlaneIndex - boxes[0].hi[a];
        boxes[1].hi[a] = r.twicePlaneIndex - boxes[0].lo[a];
      } else {
        mirroredCentre[r.mirrorAxis] = 2.0 * r.planeRest - centre[r.mirrorAxis];
        boxes[1] = sphereBox(mirroredCentre, r.radiusRest);
      }
      count = 2;
    }
    for (int b = 0; b < count; ++b)
      if (boxes[b].voxels() > kMaxDabVoxels)
        throw InputError("radius: a dab covers " + std::to_string(std::llround(boxes[b].voxels())) +
                         " voxels, more than the limit of 2^26; use a smaller radius");

    Accessors acc(*target.set);
    openvdb::tree::ValueAccessor<openvdb::Int32Tree> indexAcc(recordIndex);
    // Smooth reads the neighbourhood as it was before this dab, whatever the visiting order.
    Snapshot snaps[2];
    const bool smooth = brush.mode == BrushMode::Smooth;
    if (smooth)
      for (int b = 0; b < count; ++b) snaps[b] = snapshot(acc, boxes[b]);
    const double r2 = r.radiusRest * r.radiusRest;
    // Squared rest-space distance from a voxel centre to c: a function of the voxel and c
    // only (never accumulated along a row), so a voxel and its mirror image get
    // bit-identical weights.
    const glm::dvec3 diag(indexToRest[0][0], indexToRest[1][1], indexToRest[2][2]);
    auto axisDistance = [&](int axis, int i, double c) { return (diag[axis] * i + indexToRestOffset[axis]) - c; };
    auto distance2 = [&](const Coord& ijk, const glm::dvec3& c) {
      if (axisAligned) {
        const double dx = axisDistance(0, ijk.x(), c.x), dy = axisDistance(1, ijk.y(), c.y),
                     dz = axisDistance(2, ijk.z(), c.z);
        return dx * dx + dy * dy + dz * dz;
      }
      const glm::dvec3 d = rest(ijk) - c;
      return glm::dot(d, d);
    };
    // Without a mirror on an axis-aligned grid, each row is cut to the sphere's chord.
    const bool chords = axisAligned && !r.mirror;
    for (int b = 0; b < count; ++b) {
      const IndexBox& box = boxes[b];
      for (int z = box.lo.z(); z <= box.hi.z(); ++z)
        for (int y = box.lo.y(); y <= box.hi.y(); ++y) {
          int x0 = box.lo.x(), x1 = box.hi.x();
          if (chords) {
            const double dy = axisDistance(1, y, centre.y), dz = axisDistance(2, z, centre.z);
            const double left = r2 - (dy * dy + dz * dz);
            if (left < 0.0) continue;
            const double half = std::sqrt(left) / std::abs(diag.x), mid = (centre.x - indexToRestOffset.x) / diag.x;
            // Clamped in double: a far-away centre must not overflow the int conversion.
            x0 = int(std::clamp(std::floor(mid - half) - 1.0, double(x0), double(x1)));
            x1 = int(std::clamp(std::ceil(mid + half) + 1.0, double(x0), double(x1)));
          }
          for (int x = x0; x <= x1; ++x) {
            const Coord ijk(x, y, z);
            if (b == 1 && boxes[0].contains(ijk)) continue;  // visited with the first box
            double d2 = distance2(ijk, centre);
            if (r.mirror)
              d2 = std::min(d2, r.latticeMirror ? distance2(mirrorIndex(ijk), centre) : distance2(ijk, mirroredCentre));
            if (d2 > r2) continue;
            const double t = falloffWeight(brush.falloff, std::sqrt(d2) / r.radiusRest) * brush.strength;
            if (!(t > 0.0)) continue;
            if (paintVoxel(acc, indexAcc, ijk, t, smooth ? &snaps[b] : nullptr)) {
              ++out.voxelsWritten;
              written.extend(ijk);
            }
          }
        }
    }
    ++out.dabs;
    ++dabs;
  }

  DabResult applyDabs(const std::vector<glm::dvec3>& worldDabs, std::size_t missed) {
    DabResult out;
    out.raysMissed = missed;
    raysMissed += missed;
    IndexBox written;
    for (const glm::dvec3& p : worldDabs) applyDab(worldToRestPoint(p), out, written);
    out.worldBounds = worldBounds(written);
    return out;
  }

  /// Dabs from `from` (exclusive) to `to` (inclusive) at a spacing of at most radius/4.
  void segmentDabs(const glm::dvec3& from, const glm::dvec3& to, std::vector<glm::dvec3>& dabsOut) const {
    const double length = glm::length(to - from);
    if (!(length > 0.0)) return;
    const double steps = std::ceil(length / resolved.spacing);
    if (steps + double(dabsOut.size()) > double(kMaxDabsPerCall))
      throw InputError("points: the stroke needs more than 10^6 dabs (radius / 4 apart); use a larger radius");
    const int n = int(steps);
    for (int i = 1; i <= n; ++i) dabsOut.push_back(i == n ? to : from + (double(i) / n) * (to - from));
  }

  std::optional<SurfaceHit> cast(const SurfaceRay& ray) const {
    const RayHit hit = rayScene->intersect(glm::vec3(ray.origin), glm::vec3(ray.direction));
    if (!hit.hit) return std::nullopt;
    return SurfaceHit{ray, glm::dvec3(hit.position), glm::dvec3(hit.normal)};
  }

  void fillBetween(const SurfaceHit& a, const SurfaceHit& b, int level, std::vector<SurfaceHit>& out) const {
    if (level >= kMaxRayBisections || glm::length(a.position - b.position) <= resolved.spacing) return;
    const glm::dvec3 dir = glm::normalize(a.ray.direction) + glm::normalize(b.ray.direction);
    if (!(glm::length(dir) > 0.0)) return;
    const std::optional<SurfaceHit> mid = cast({0.5 * (a.ray.origin + b.ray.origin), glm::normalize(dir)});
    if (!mid) return;
    fillBetween(a, *mid, level + 1, out);
    out.push_back(*mid);
    fillBetween(*mid, b, level + 1, out);
  }
};

BrushEngine::BrushEngine(PaintTarget target) : impl_(std::make_unique<Impl>()) {
  initializeOpenVdb();
  Impl& m = *impl_;
  MaterialSet* set = target.set.get();
  if (!set || !set->sigmaT || !set->sigmaS)
    throw InputError("material set: painting needs both 'sigma_t' and 'sigma_s' grids");
  const std::optional<double> fileUnit = unitInMm(set->units);
  if (!fileUnit) throw InputError("material set: unknown units '" + set->units + "'");
  if (!(target.sceneUnitInMm > 0.0)) throw InputError("scene: unit must be positive");
  m.sigmaToSet = *fileUnit / target.sceneUnitInMm;
  for (int c = 0; c < 3; ++c) {
    m.base.sigmaT[c] = float(double(target.base.sigmaT[c]) * m.sigmaToSet);
    m.base.sigmaS[c] = float(double(target.base.sigmaS[c]) * m.sigmaToSet);
  }
  m.base.g = target.base.g;
  for (int c = 0; c < 3; ++c) {
    m.baseValue[c] = m.base.sigmaT[c];
    m.baseValue[3 + c] = m.base.sigmaS[c];
  }
  m.baseValue[6] = m.base.g;

  const openvdb::math::Transform& transform = set->sigmaT->constTransform();
  if (!(transform == set->sigmaS->constTransform()) || (set->g && !(transform == set->g->constTransform())))
    throw InputError("material set: painting needs 'sigma_t', 'sigma_s' and 'g' on one transform");
  if (!transform.isLinear()) throw InputError("material set: painting needs a linear grid transform");
  if (!set->g) {
    set->g = openvdb::FloatGrid::create(m.base.g);
    set->g->setName("g");
    set->g->setTransform(transform.copy());
  }
  // OpenVDB matrices act on row vectors: rest = index * M, translation in row 3.
  const openvdb::Mat4d M = transform.baseMap()->getAffineMap()->getMat4();
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) m.indexToRest[col][row] = M(col, row);
    m.indexToRestOffset[row] = M(3, row);
  }
  if (!(std::abs(glm::determinant(m.indexToRest)) > 0.0))
    throw InputError("material set: the grid transform is singular");
  m.restToIndex = glm::inverse(m.indexToRest);
  m.restToIndexOffset = -(m.restToIndex * m.indexToRestOffset);
  m.axisAligned = true;
  for (int col = 0; col < 3; ++col)
    for (int row = 0; row < 3; ++row)
      if (col != row && m.indexToRest[col][row] != 0.0) m.axisAligned = false;

  // The scene transform is a similarity: columns orthogonal and of one length.
  const glm::dmat3 linear(target.restToWorld);
  m.scale = glm::length(linear[0]);
  bool similarity = m.scale > 0.0 && target.restToWorld[0][3] == 0.0 && target.restToWorld[1][3] == 0.0 &&
                    target.restToWorld[2][3] == 0.0 && target.restToWorld[3][3] == 1.0;
  for (int a = 0; a < 3 && similarity; ++a) {
    similarity = std::abs(glm::length(linear[a]) - m.scale) <= 1e-9 * m.scale;
    for (int b = a + 1; b < 3 && similarity; ++b)
      similarity = std::abs(glm::dot(linear[a], linear[b])) <= 1e-9 * m.scale * m.scale;
  }
  if (!similarity) throw InputError("scene: the transform must be a similarity (uniform scale, rotation, translation)");
  m.worldToRest = glm::inverse(target.restToWorld);
  m.target = std::move(target);
}

BrushEngine::~BrushEngine() = default;

StrokeResult BrushEngine::applyStroke(const Stroke& stroke) {
  beginStroke(stroke.brush);
  try {
    if (!stroke.points.empty()) addPoints(stroke.points);
    if (!stroke.rays.empty()) addRays(stroke.rays);
  } catch (...) {
    endStroke();  // what was painted before the failure stays undoable
    throw;
  }
  return endStroke();
}

void BrushEngine::beginStroke(const Brush& brush) {
  Impl& m = *impl_;
  if (m.inStroke) endStroke();
  m.resolve(brush);
  m.brush = brush;
  m.inStroke = true;
  m.records.clear();
  m.recordIndex.clear();
  m.lastPoint.reset();
  m.lastHit.reset();
  m.dabs = m.raysMissed = 0;
}

bool BrushEngine::strokeInProgress() const { return impl_->inStroke; }

DabResult BrushEngine::addPoints(const std::vector<glm::dvec3>& worldPoints) {
  Impl& m = *impl_;
  if (!m.inStroke) throw std::logic_error("BrushEngine::addPoints outside a stroke");
  std::vector<glm::dvec3> dabs;
  for (const glm::dvec3& p : worldPoints) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) throw InputError("points: must be finite");
    if (!m.lastPoint)
      dabs.push_back(p);
    else
      m.segmentDabs(*m.lastPoint, p, dabs);
    m.lastPoint = p;
  }
  return m.applyDabs(dabs, 0);
}

DabResult BrushEngine::addRays(const std::vector<SurfaceRay>& worldRays) {
  Impl& m = *impl_;
  if (!m.inStroke) throw std::logic_error("BrushEngine::addRays outside a stroke");
  if (!m.target.worldMesh) throw InputError("rays: this paint target has no mesh to hit");
  if (!m.rayScene) m.rayScene = std::make_unique<RayScene>(*m.target.worldMesh);
  std::vector<SurfaceHit> hits;
  std::size_t missed = 0;
  for (const SurfaceRay& ray : worldRays) {
    const double len = glm::length(ray.direction);
    const bool finite = std::isfinite(ray.origin.x) && std::isfinite(ray.origin.y) && std::isfinite(ray.origin.z);
    if (!(len > 0.0) || !std::isfinite(len) || !finite)
      throw InputError("rays: origin and direction must be finite, direction non-zero");
    const std::optional<SurfaceHit> hit = m.cast(ray);
    if (!hit) {
      ++missed;
      m.lastHit.reset();
      continue;
    }
    if (m.lastHit) m.fillBetween(*m.lastHit, *hit, 0, hits);
    hits.push_back(*hit);
    m.lastHit = hit;
  }
  std::vector<glm::dvec3> dabs;
  const double depth = m.brush.depth;
  const int column = depth > 0.0 ? int(std::min(std::ceil(depth / m.resolved.spacing), double(kMaxDabsPerCall))) : 0;
  if (double(hits.size()) * double(column + 1) > double(kMaxDabsPerCall))
    throw InputError("rays: the stroke needs more than 10^6 dabs (radius / 4 apart); use a larger radius");
  for (const SurfaceHit& h : hits) {
    dabs.push_back(h.position);
    for (int q = 1; q <= column; ++q) dabs.push_back(h.position - (depth * double(q) / column) * h.normal);
  }
  return m.applyDabs(dabs, missed);
}

StrokeResult BrushEngine::endStroke() {
  Impl& m = *impl_;
  if (!m.inStroke) throw std::logic_error("BrushEngine::endStroke outside a stroke");
  m.inStroke = false;
  HistoryEntry entry;
  Accessors acc(*m.target.set);
  IndexBox changed;
  for (VoxelRecord& record : m.records) {
    record.after = acc.read(record.ijk);
    if (sameBits(record.before, record.after)) continue;  // written, then restored by later dabs
    changed.extend(record.ijk);
    entry.records.push_back(record);
  }
  m.records.clear();
  m.records.shrink_to_fit();
  m.recordIndex.clear();
  entry.records.shrink_to_fit();
  entry.result.voxelsChanged = entry.records.size();
  entry.result.worldBounds = m.worldBounds(changed);
  entry.result.dabs = m.dabs;
  entry.result.raysMissed = m.raysMissed;
  m.history.resize(m.applied);
  m.history.push_back(std::move(entry));
  m.applied = m.history.size();
  return m.history.back().result;
}

bool BrushEngine::canUndo() const { return !impl_->inStroke && impl_->applied > 0; }
bool BrushEngine::canRedo() const { return !impl_->inStroke && impl_->applied < impl_->history.size(); }

std::optional<StrokeResult> BrushEngine::undo() {
  if (!canUndo()) return std::nullopt;
  Impl& m = *impl_;
  const HistoryEntry& entry = m.history[--m.applied];
  Accessors acc(*m.target.set);
  for (const VoxelRecord& record : entry.records) acc.write(record.ijk, record.before);
  return entry.result;
}

std::optional<StrokeResult> BrushEngine::redo() {
  if (!canRedo()) return std::nullopt;
  Impl& m = *impl_;
  const HistoryEntry& entry = m.history[m.applied++];
  Accessors acc(*m.target.set);
  for (const VoxelRecord& record : entry.records) acc.write(record.ijk, record.after);
  return entry.result;
}

std::size_t BrushEngine::historyStrokes() const { return impl_->applied; }

std::size_t BrushEngine::historyBytes() const {
  std::size_t bytes = 0;
  for (const HistoryEntry& entry : impl_->history) bytes += entry.records.capacity() * sizeof(VoxelRecord);
  return bytes;
}

std::shared_ptr<const MaterialSet> BrushEngine::materialSet() const { return impl_->target.set; }
const MaterialSample& BrushEngine::baseInSetUnits() const { return impl_->base; }
double BrushEngine::sigmaToSetUnits() const { return impl_->sigmaToSet; }

double BrushEngine::mirrorPlane(const BrushMirror& mirror) const {
  if (mirror.axis < 0 || mirror.axis > 2) throw InputError("mirror.axis: must be x, y or z");
  return impl_->planeFor(mirror, nullptr);
}

}  // namespace sslpv
