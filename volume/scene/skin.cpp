#include "volume/scene/skin.h"

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/matrix.hpp>
#include <glm/vector_relational.hpp>
#include <limits>

#include "volume/core/error.h"
#include "volume/core/input_ranges.h"
#include "volume/core/strict_json.h"

namespace sslpv {
namespace {

/// The segment of `times` holding t and how far along it: (i, f) with t between times[i]
/// and times[i + 1]; f = 0 before the first key, i = last with f = 0 after the last.
std::pair<std::size_t, double> locate(const std::vector<double>& times, double t) {
  if (!(t > times.front())) return {0, 0.0};
  if (t >= times.back()) return {times.size() - 1, 0.0};
  const std::size_t i = std::size_t(std::upper_bound(times.begin(), times.end(), t) - times.begin()) - 1;
  const double span = times[i + 1] - times[i];
  return {i, span > 0.0 ? (t - times[i]) / span : 0.0};
}

glm::dmat4 nodeLocal(const glm::dvec3& translation, const glm::dquat& rotation, const glm::dvec3& scale) {
  return glm::translate(glm::dmat4(1.0), translation) * glm::mat4_cast(rotation) * glm::scale(glm::dmat4(1.0), scale);
}

}  // namespace

glm::dvec3 Vec3Track::at(double t, const glm::dvec3& fallback) const {
  if (times.empty()) return fallback;
  const auto [i, f] = locate(times, t);
  if (f == 0.0) return values[i];
  return glm::mix(values[i], values[i + 1], f);
}

glm::dquat RotationTrack::at(double t, const glm::dquat& fallback) const {
  if (times.empty()) return fallback;
  const auto [i, f] = locate(times, t);
  if (f == 0.0) return values[i];
  glm::dquat b = values[i + 1];
  // q and -q are the same rotation; the shorter arc is the one an animator keyed.
  if (glm::dot(values[i], b) < 0.0) b = -b;
  return glm::normalize(glm::slerp(values[i], b, f));
}

double SkinClip::start() const {
  double first = std::numeric_limits<double>::infinity();
  for (const SkinChannel& c : channels)
    for (const auto* times : {&c.translation.times, &c.rotation.times, &c.scale.times})
      if (!times->empty()) first = std::min(first, times->front());
  return std::isfinite(first) ? first : 0.0;
}

double SkinClip::end() const {
  double last = -std::numeric_limits<double>::infinity();
  for (const SkinChannel& c : channels)
    for (const auto* times : {&c.translation.times, &c.rotation.times, &c.scale.times})
      if (!times->empty()) last = std::max(last, times->back());
  return std::isfinite(last) ? last : 0.0;
}

std::size_t selectClip(const SkinnedMesh& mesh, const std::string& name, int index) {
  const std::string file = mesh.rest.name;
  if (mesh.skin.joints.empty())
    throw InputError(file + ": the mesh has no skin (no joints weight its vertices): there is no animation to play");
  const auto& clips = mesh.skin.clips;
  if (clips.empty()) throw InputError(file + ": the mesh has a skin but no animation clips");
  std::string list;
  for (std::size_t i = 0; i < clips.size(); ++i) {
    if (i == 4 && clips.size() > 5) {
      list += ", ... (" + std::to_string(clips.size()) + " in all)";
      break;
    }
    list += (i ? ", " : "") + (clips[i].name.empty() ? "#" + std::to_string(i) : printable(clips[i].name));
  }
  if (index >= 0) {
    if (std::size_t(index) < clips.size()) return std::size_t(index);
    throw InputError(file + ": animation " + std::to_string(index) + " not found (" + std::to_string(clips.size()) +
                     (clips.size() == 1 ? " clip: " : " clips: ") + list + ")");
  }
  for (std::size_t i = 0; i < clips.size(); ++i)
    if (clips[i].name == name) return i;
  throw InputError(file + ": animation '" + printable(name) + "' not found (clips: " + list + ")");
}

std::vector<glm::dmat4> jointMatrices(const Skin& skin, const SkinClip* clip, double t) {
  std::vector<glm::dvec3> translation(skin.nodes.size()), scale(skin.nodes.size());
  std::vector<glm::dquat> rotation(skin.nodes.size());
  for (std::size_t n = 0; n < skin.nodes.size(); ++n) {
    translation[n] = skin.nodes[n].translation;
    rotation[n] = skin.nodes[n].rotation;
    scale[n] = skin.nodes[n].scale;
  }
  if (clip)
    for (const SkinChannel& c : clip->channels) {
      translation[c.node] = c.translation.at(t, translation[c.node]);
      rotation[c.node] = c.rotation.at(t, rotation[c.node]);
      scale[c.node] = c.scale.at(t, scale[c.node]);
    }
  std::vector<glm::dmat4> global(skin.nodes.size());
  for (std::size_t n = 0; n < skin.nodes.size(); ++n) {
    const glm::dmat4 local = nodeLocal(translation[n], rotation[n], scale[n]);
    const std::int32_t parent = skin.nodes[n].parent;
    global[n] = parent >= 0 ? global[std::size_t(parent)] * local : local;
  }
  std::vector<glm::dmat4> result(skin.joints.size());
  for (std::size_t j = 0; j < skin.joints.size(); ++j) result[j] = global[skin.joints[j].node] * skin.joints[j].restToJoint;
  return result;
}

PointGrid::PointGrid(std::vector<glm::dvec3> points) : points_(std::move(points)) {
  // Non-finite points (a pose thrown far off, which the caller then refuses) are left out.
  const auto usable = [](const glm::dvec3& p) { return std::isfinite(p.x + p.y + p.z); };
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  for (const glm::dvec3& p : points_)
    if (usable(p)) {
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
  if (!(lo.x <= hi.x)) lo = hi = glm::dvec3(0.0);
  const glm::dvec3 extent = glm::max(hi - lo, glm::dvec3(1e-9 * (1.0 + glm::length(hi - lo))));
  // About two points a cell for points spread through the box; a surface's points fill
  // fewer cells, which the ring search handles at the cost of a few empty cells.
  const double target = std::max(1.0, double(points_.size()) / 2.0);
  cell_ = std::cbrt(extent.x * extent.y * extent.z / target);
  cell_ = std::max(cell_, std::max({extent.x, extent.y, extent.z}) / 128.0);
  for (int a = 0; a < 3; ++a) dims_[a] = std::clamp(int(std::ceil(extent[a] / cell_)), 1, 128);
  origin_ = lo;
  const std::size_t cells = std::size_t(dims_.x) * std::size_t(dims_.y) * std::size_t(dims_.z);
  start_.assign(cells + 1, 0u);
  constexpr auto kLeftOut = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> cellOf(points_.size(), kLeftOut);
  for (std::size_t i = 0; i < points_.size(); ++i) {
    if (!usable(points_[i])) continue;
    const glm::ivec3 c = cellOf_(points_[i]);
    cellOf[i] = std::uint32_t((std::size_t(c.z) * std::size_t(dims_.y) + std::size_t(c.y)) * std::size_t(dims_.x) +
                              std::size_t(c.x));
    ++start_[cellOf[i] + 1];
  }
  for (std::size_t c = 0; c < cells; ++c) start_[c + 1] += start_[c];
  items_.resize(start_[cells]);
  std::vector<std::uint32_t> fill(start_.begin(), start_.end() - 1);
  for (std::size_t i = 0; i < points_.size(); ++i)
    if (cellOf[i] != kLeftOut) items_[fill[cellOf[i]]++] = std::uint32_t(i);
}

glm::ivec3 PointGrid::cellOf_(const glm::dvec3& p) const {
  // Clamped in double: a far query would overflow the conversion to int.
  return glm::ivec3(glm::clamp(glm::floor((p - origin_) / cell_), glm::dvec3(0.0), glm::dvec3(dims_ - 1)));
}

int PointGrid::nearest(const glm::dvec3& q, int k, std::uint32_t* index, double* distance2) const {
  k = std::clamp(k, 0, kMaxK);
  if (points_.empty() || k == 0 || !std::isfinite(q.x + q.y + q.z)) return 0;
  int found = 0;
  const glm::ivec3 c = cellOf_(q);
  const int maxRing = std::max({dims_.x, dims_.y, dims_.z});
  for (int r = 0; r <= maxRing; ++r) {
    const glm::ivec3 lo = glm::max(c - r, glm::ivec3(0)), hi = glm::min(c + r, dims_ - 1);
    for (int z = lo.z; z <= hi.z; ++z)
      for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) {
          // Only the shell at Chebyshev distance r: the inside was visited before.
          if (std::max({std::abs(x - c.x), std::abs(y - c.y), std::abs(z - c.z)}) != r) continue;
          const std::size_t cell = (std::size_t(z) * std::size_t(dims_.y) + std::size_t(y)) * std::size_t(dims_.x) +
                                   std::size_t(x);
          for (std::uint32_t s = start_[cell]; s < start_[cell + 1]; ++s) {
            const std::uint32_t i = items_[s];
            const glm::dvec3 d = points_[i] - q;
            const double d2 = glm::dot(d, d);
            if (found == k && d2 >= distance2[k - 1]) continue;
            int at = found < k ? found++ : k - 1;
            while (at > 0 && distance2[at - 1] > d2) {
              distance2[at] = distance2[at - 1];
              index[at] = index[at - 1];
              --at;
            }
            distance2[at] = d2;
            index[at] = i;
          }
        }
    if (found < k) continue;
    // Every unvisited cell lies beyond one of the visited block's faces that is not the
    // grid's boundary: stop once the k-th point is nearer than all of those faces.
    double bound = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
      if (c[a] - r > 0) bound = std::min(bound, q[a] - (origin_[a] + double(c[a] - r) * cell_));
      if (c[a] + r < dims_[a] - 1) bound = std::min(bound, origin_[a] + double(c[a] + r + 1) * cell_ - q[a]);
    }
    if (!std::isfinite(bound) || (bound > 0.0 && bound * bound >= distance2[k - 1])) break;
  }
  return found;
}

SkinPose::SkinPose(const SkinnedMesh& mesh, std::shared_ptr<const PointGrid> restGrid, const SkinClip* clip, double t)
    : restGrid_(std::move(restGrid)) {
  const std::vector<glm::dmat4> joints = jointMatrices(mesh.skin, clip, t);
  const std::size_t n = mesh.rest.positions.size();
  vertexMatrices_.resize(n);
  posed_.resize(n);
  for (std::size_t v = 0; v < n; ++v) {
    const SkinInfluence& in = v < mesh.skin.influences.size() ? mesh.skin.influences[v] : SkinInfluence{};
    glm::dmat4 m(0.0);
    double total = 0.0;
    for (int i = 0; i < 4; ++i)
      if (in.weights[i] > 0.0f) {
        m += double(in.weights[i]) * joints[in.joints[i]];
        total += double(in.weights[i]);
      }
    // Weights were normalised at import; a vertex no joint holds stays where it is.
    vertexMatrices_[v] = total > 0.0 ? m / total : glm::dmat4(1.0);
    posed_[v] = glm::dvec3(vertexMatrices_[v] * glm::dvec4(glm::dvec3(mesh.rest.positions[v]), 1.0));
  }
  posedGrid_ = std::make_unique<PointGrid>(posed_);
}

glm::dmat4 SkinPose::blended(const PointGrid& grid, const glm::dvec3& p) const {
  std::uint32_t index[kNeighbours];
  double d2[kNeighbours];
  const int found = grid.nearest(p, kNeighbours, index, d2);
  if (found == 0) return glm::dmat4(1.0);
  // A point on a vertex takes that vertex's matrix exactly; the scale keeps the weights
  // finite for points very near one.
  if (!(d2[0] > 1e-24 * (1.0 + glm::dot(p, p)))) return vertexMatrices_[index[0]];
  glm::dmat4 m(0.0);
  double total = 0.0;
  for (int i = 0; i < found; ++i) {
    const double w = d2[0] / d2[i];  // 1/d², relative to the nearest to stay near 1
    m += w * vertexMatrices_[index[i]];
    total += w;
  }
  return m / total;
}

glm::dvec3 SkinPose::forward(const glm::dvec3& rest) const {
  return glm::dvec3(blended(*restGrid_, rest) * glm::dvec4(rest, 1.0));
}

glm::dvec3 SkinPose::blendedInverse(const glm::dvec3& deformed) const {
  const glm::dmat4 m = blended(*posedGrid_, deformed);
  const glm::dmat3 linear(m);
  const double det = glm::determinant(linear);
  // A blend of opposed rotations can collapse: such a point has no defined rest point.
  if (!(std::abs(det) > 1e-12)) return glm::dvec3(std::nan(""));
  return glm::inverse(linear) * (deformed - glm::dvec3(m[3]));
}

glm::dvec3 SkinPose::inverse(const glm::dvec3& deformed) const {
  glm::dvec3 rest = blendedInverse(deformed);
  if (!std::isfinite(rest.x + rest.y + rest.z)) return rest;
  // The one-step blend sees the posed neighbours, forward() the rest ones; where they
  // differ (across a joint's blend zone, where the inner side of a bend crowds vertices
  // of both bones together) the two disagree by up to half the bar's width. A few
  // fixed-point steps on forward(rest) = deformed make inverse() the inverse of
  // forward() wherever that is one-to-one (docs/accuracy.md, 2026-12-06).
  for (int i = 0; i < kRefinements; ++i) {
    const glm::dmat4 m = blended(*restGrid_, rest);
    const glm::dmat3 linear(m);
    if (!(std::abs(glm::determinant(linear)) > 1e-12)) break;
    const glm::dvec3 residual = deformed - glm::dvec3(m * glm::dvec4(rest, 1.0));
    const glm::dvec3 step = glm::inverse(linear) * residual;
    if (!std::isfinite(step.x + step.y + step.z)) break;
    rest += step;
    if (glm::dot(step, step) <= 1e-24 * (1.0 + glm::dot(rest, rest))) break;
  }
  return rest;
}

std::vector<glm::vec3> skinnedPositions(const SkinPose& pose, const std::string& file, double t) {
  std::vector<glm::vec3> result(pose.posedVertices().size());
  for (std::size_t i = 0; i < result.size(); ++i) {
    const glm::dvec3& p = pose.posedVertices()[i];
    if (!(glm::all(glm::lessThanEqual(glm::abs(p), glm::dvec3(kMaxCoordinate)))))
      throw InputError((file.empty() ? std::string() : file + ": ") + "mesh.animation: at t = " + formatNumber(t) +
                       " vertex " + std::to_string(i) + " leaves the coordinate range");
    result[i] = glm::vec3(p);
  }
  return result;
}

}  // namespace sslpv
