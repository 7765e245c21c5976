// The brush engine's painting: dabs in index space and the per-voxel update of every mode
// (formulas in brush_engine.h; the stroke paths and the history are in brush_engine.cpp).
#include <algorithm>
#include <cstdio>
#include <cfloat>
#include <cmath>
#include <glm/geometric.hpp>
#include <string>

#include "editor/brush_engine_impl.h"
#include "volume/core/error.h"

namespace sslpv {

using namespace brush_detail;

namespace {

constexpr double kMaxDabVoxels = double(1 << 26);
/// Voxel visits of one addPoints/addRays call: about 10-30 s of painting at the rate a
/// smooth brush paints (the slowest mode), far beyond any hand-drawn stroke.
constexpr double kMaxStrokeVoxelVisits = double(1 << 30);

}  // namespace

Bounds BrushEngine::Impl::worldBounds(const IndexBox& box) const {
  Bounds bounds;
  if (box.empty()) return bounds;
  for (int corner = 0; corner < 8; ++corner) {
    const Coord c((corner & 1) ? box.hi.x() + 1 : box.lo.x() - 1, (corner & 2) ? box.hi.y() + 1 : box.lo.y() - 1,
                  (corner & 4) ? box.hi.z() + 1 : box.lo.z() - 1);
    bounds.extend(glm::dvec3(target.restToWorld * glm::dvec4(rest(c), 1.0)));
  }
  return bounds;
}

IndexBox BrushEngine::Impl::sphereBox(const glm::dvec3& centre, double radius) const {
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

Snapshot BrushEngine::Impl::snapshot(Accessors& acc, const IndexBox& inner) const {
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

bool BrushEngine::Impl::paintVoxel(Accessors& acc, openvdb::tree::ValueAccessor<openvdb::Int32Tree>& indexAcc,
                                   const Coord& ijk, double t, const Snapshot* snap) {
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

void BrushEngine::Impl::applyDab(const glm::dvec3& centre, DabResult& out, IndexBox& written) {
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

DabResult BrushEngine::Impl::applyDabs(const std::vector<glm::dvec3>& worldDabs, std::size_t missed) {
  // The work is bounded before any of it is done: every dab visits its index box (twice
  // with a mirror), so a long smooth stroke of large dabs could run for minutes.
  // A single dab over its own limit is left to applyDab, which names that limit.
  double visits = 0.0, largest = 0.0;
  for (const glm::dvec3& p : worldDabs) {
    const double voxels = sphereBox(worldToRestPoint(p), resolved.radiusRest).voxels();
    visits += voxels;
    largest = std::max(largest, voxels);
  }
  if (resolved.mirror) visits *= 2.0;
  if (visits > kMaxStrokeVoxelVisits && largest <= kMaxDabVoxels) {
    char count[32];
    std::snprintf(count, sizeof count, "%.3g", visits);
    throw InputError("radius: the stroke's " + std::to_string(worldDabs.size()) + " dabs would visit " + count +
                     " voxels, more than the limit of 2^30; use a smaller radius or a shorter stroke");
  }
  DabResult out;
  out.raysMissed = missed;
  raysMissed += missed;
  IndexBox written;
  for (const glm::dvec3& p : worldDabs) applyDab(worldToRestPoint(p), out, written);
  out.worldBounds = worldBounds(written);
  return out;
}

}  // namespace sslpv
