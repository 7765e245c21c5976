#include "volume/scene/deform.h"

#include <cmath>
#include <glm/common.hpp>
#include <glm/trigonometric.hpp>
#include <glm/vector_relational.hpp>
#include <nlohmann/json.hpp>

#include "volume/core/error.h"
#include "volume/core/input_ranges.h"
#include "volume/core/strict_json.h"
#include "volume/core/math_constants.h"

namespace sslpv {
namespace {

using nlohmann::json;


/// The two axes across `axis`, in cyclic order (x: y, z; y: z, x; z: x, y).
int across(int axis, int which) { return (axis + 1 + which) % 3; }

/// Largest |amount| of bend and twist (degrees per length) and of taper (per length): the
/// fold check decides what a mesh can take; these only keep products finite.
constexpr double kMaxAngle = 36000.0;
constexpr double kMaxTaper = 1e6;
/// squash_stretch factor range: beyond it a unit object becomes thinner than float resolves.
constexpr double kMinFactor = 1e-3, kMaxFactor = 1e3;

struct ParamSpec {
  const char* key;
  double lo, hi;
};

ParamSpec paramSpec(Deformer::Type type) {
  switch (type) {
    case Deformer::Type::Bend: return {"angle", -kMaxAngle, kMaxAngle};
    case Deformer::Type::Twist: return {"angle", -kMaxAngle, kMaxAngle};
    case Deformer::Type::Taper: return {"amount", -kMaxTaper, kMaxTaper};
    case Deformer::Type::SquashStretch: return {"factor", kMinFactor, kMaxFactor};
  }
  return {"amount", 0.0, 0.0};
}

double boundedNumber(const StrictJsonReader& in, const json& value, const std::string& path, double lo, double hi) {
  const double x = in.number(value, path);
  if (!(x >= lo && x <= hi))
    in.fail(path, "must be in [" + formatNumber(lo) + ", " + formatNumber(hi) + "], got " + formatNumber(x));
  return x;
}

AnimatedValue parseAnimated(const StrictJsonReader& in, const json& value, const std::string& path,
                            const ParamSpec& spec) {
  AnimatedValue result;
  if (value.is_number()) {
    result.keys.push_back({0.0, boundedNumber(in, value, path, spec.lo, spec.hi), Ease::Linear});
    return result;
  }
  if (!value.is_array() || value.empty())
    in.fail(path, "expected a number or a non-empty array of keyframes {\"t\", \"value\", \"ease\"}, got " +
                      (value.is_array() ? std::string("an empty array") : describeType(value)));
  for (std::size_t i = 0; i < value.size(); ++i) {
    const std::string keyPath = indexPath(path, i);
    const json& node = value[i];
    in.requireObject(node, keyPath);
    in.allowOnly(node, keyPath, {"t", "value", "ease"});
    Keyframe key;
    const std::string tPath = childPath(keyPath, "t");
    key.t = boundedNumber(in, in.required(node, keyPath, "t"), tPath, -kMaxTime, kMaxTime);
    if (i > 0 && !(key.t > result.keys.back().t))
      in.fail(tPath, "must exceed the previous keyframe's t (" + formatNumber(result.keys.back().t) + "), got " +
                         formatNumber(key.t));
    key.value = boundedNumber(in, in.required(node, keyPath, "value"), childPath(keyPath, "value"), spec.lo, spec.hi);
    if (const json* ease = in.optional(node, "ease"))
      key.ease = in.choice<Ease>(*ease, childPath(keyPath, "ease"), "ease",
                                 {{"linear", Ease::Linear}, {"smoothstep", Ease::Smoothstep}});
    result.keys.push_back(key);
  }
  return result;
}

int parseAxis(const StrictJsonReader& in, const json& value, const std::string& path) {
  return in.choice<int>(value, path, "axis", {{"x", 0}, {"y", 1}, {"z", 2}});
}

Deformer parseDeformer(const StrictJsonReader& in, const json& node, const std::string& path) {
  in.requireObject(node, path);
  Deformer d;
  d.type = in.choice<Deformer::Type>(in.required(node, path, "type"), childPath(path, "type"), "deformer type",
                                     {{"bend", Deformer::Type::Bend},
                                      {"twist", Deformer::Type::Twist},
                                      {"taper", Deformer::Type::Taper},
                                      {"squash_stretch", Deformer::Type::SquashStretch}});
  const ParamSpec spec = paramSpec(d.type);
  switch (d.type) {
    case Deformer::Type::Bend: in.allowOnly(node, path, {"type", "axis", "center", "angle", "length", "toward"}); break;
    case Deformer::Type::Twist:
      in.allowOnly(node, path, {"type", "axis", "center", "angle", "length"});
      break;
    case Deformer::Type::Taper: in.allowOnly(node, path, {"type", "axis", "center", "amount", "length"}); break;
    case Deformer::Type::SquashStretch: in.allowOnly(node, path, {"type", "axis", "center", "factor"}); break;
  }
  if (const json* v = in.optional(node, "axis")) d.axis = parseAxis(in, *v, childPath(path, "axis"));
  d.toward = across(d.axis, 1);
  if (const json* v = in.optional(node, "toward")) {
    const std::string towardPath = childPath(path, "toward");
    d.toward = parseAxis(in, *v, towardPath);
    if (d.toward == d.axis) in.fail(towardPath, "must differ from the deformer's axis");
  }
  if (const json* v = in.optional(node, "center")) {
    const std::string centerPath = childPath(path, "center");
    d.center = in.vec3(*v, centerPath);
    for (int i = 0; i < 3; ++i)
      boundedNumber(in, (*v)[std::size_t(i)], indexPath(centerPath, std::size_t(i)), -kMaxCoordinate, kMaxCoordinate);
  }
  if (const json* v = in.optional(node, "length")) {
    const std::string lengthPath = childPath(path, "length");
    d.length = boundedNumber(in, *v, lengthPath, kMinPrimitiveSize, kMaxCoordinate);
  }
  d.amount = parseAnimated(in, in.required(node, path, spec.key), childPath(path, spec.key), spec);
  return d;
}

double ease(double f, Ease e) { return e == Ease::Smoothstep ? f * f * (3.0 - 2.0 * f) : f; }

/// Turns q about the deformer's axis by phi radians (a twist's slice at q).
void turnAboutAxis(glm::dvec3& q, int axis, double phi) {
  const int a = across(axis, 0), b = across(axis, 1);
  const double c = std::cos(phi), sn = std::sin(phi);
  const double x = q[a], y = q[b];
  q[a] = c * x - sn * y;
  q[b] = sn * x + c * y;
}

/// Scales q by `along` along the axis and by `acrossScale` across it.
void scaleAlongAndAcross(glm::dvec3& q, int axis, double along, double acrossScale) {
  q[axis] *= along;
  q[across(axis, 0)] *= acrossScale;
  q[across(axis, 1)] *= acrossScale;
}

}  // namespace

const char* deformerTypeName(Deformer::Type type) {
  switch (type) {
    case Deformer::Type::Bend: return "bend";
    case Deformer::Type::Twist: return "twist";
    case Deformer::Type::Taper: return "taper";
    case Deformer::Type::SquashStretch: return "squash_stretch";
  }
  return "deformer";
}

double AnimatedValue::at(double t) const {
  if (keys.empty()) return 0.0;
  if (!(t > keys.front().t)) return keys.front().value;
  if (t >= keys.back().t) return keys.back().value;
  std::size_t i = 1;
  while (keys[i].t <= t) ++i;
  const Keyframe& a = keys[i - 1];
  const Keyframe& b = keys[i];
  const double f = ease((t - a.t) / (b.t - a.t), b.ease);
  return a.value + (b.value - a.value) * f;
}

glm::dvec3 PosedDeformer::forward(const glm::dvec3& rest) const {
  glm::dvec3 q = rest - center;
  switch (type) {
    case Deformer::Type::Bend: {
      if (k == 0.0) break;
      // Barr's bend: the axis becomes an arc of radius 1/|k| curving towards `toward`
      // (away from it for k < 0), lines across the axis stay straight and normal to it.
      // Written without R = 1/k so that a tiny bend loses no precision.
      const double s = k > 0.0 ? 1.0 : -1.0, kk = std::abs(k);
      const double u = q[axis], v = s * q[toward];
      const double theta = kk * u;
      const double half = std::sin(0.5 * theta);
      const double sinc = theta == 0.0 ? u : std::sin(theta) / kk;  // sin θ / kk
      q[axis] = (1.0 - kk * v) * sinc;
      q[toward] = s * (2.0 * half * half / kk + v * std::cos(theta));
      break;
    }
    case Deformer::Type::Twist:
      turnAboutAxis(q, axis, k * q[axis]);
      break;
    case Deformer::Type::Taper:
      scaleAlongAndAcross(q, axis, 1.0, 1.0 + k * q[axis]);
      break;
    case Deformer::Type::SquashStretch:
      scaleAlongAndAcross(q, axis, k, 1.0 / std::sqrt(k));
      break;
  }
  return center + q;
}

glm::dvec3 PosedDeformer::inverse(const glm::dvec3& deformed) const {
  glm::dvec3 q = deformed - center;
  switch (type) {
    case Deformer::Type::Bend: {
      if (k == 0.0) break;
      // In units of the radius R = 1/kk: the point's offset from the centre of curvature
      // is (kk x, 1 - kk y); its angle gives u, its distance R - v.
      const double s = k > 0.0 ? 1.0 : -1.0, kk = std::abs(k);
      const double x = q[axis], y = s * q[toward];
      const double along = kk * x, towardCentre = 1.0 - kk * y;
      const double theta = std::atan2(along, towardCentre);
      const double distance = std::hypot(along, towardCentre);  // (R - v) / R
      q[axis] = theta == 0.0 ? x / towardCentre : theta / kk;
      // v = R (1 - distance), as (1 - distance²) / (1 + distance) without cancellation.
      q[toward] = s * (y * (2.0 - kk * y) - kk * x * x) / (1.0 + distance);
      break;
    }
    case Deformer::Type::Twist:
      turnAboutAxis(q, axis, -k * q[axis]);  // a twist keeps the coordinate along its axis
      break;
    case Deformer::Type::Taper: {
      const double scale = 1.0 + k * q[axis];
      if (!(scale > 0.0)) return glm::dvec3(std::nan(""));
      scaleAlongAndAcross(q, axis, 1.0, 1.0 / scale);
      break;
    }
    case Deformer::Type::SquashStretch:
      scaleAlongAndAcross(q, axis, 1.0 / k, std::sqrt(k));
      break;
  }
  return center + q;
}

std::string PosedDeformer::outsideDomain(const glm::dvec3& rest) const {
  const glm::dvec3 q = rest - center;
  if (type == Deformer::Type::Bend && k != 0.0) {
    const double kk = std::abs(k), v = (k > 0.0 ? 1.0 : -1.0) * q[toward];
    if (!(kk * std::abs(q[axis]) < kPi))
      return "bends " + formatNumber(glm::degrees(kk * std::abs(q[axis]))) +
             " degrees from the centre, more than 180: the object folds onto itself";
    if (!(kk * v < 1.0))
      return "its radius of curvature (" + formatNumber(1.0 / kk) +
             ") is smaller than the object's extent towards the bend: the object folds onto itself";
  }
  if (type == Deformer::Type::Taper && !(1.0 + k * q[axis] > 0.0))
    return "shrinks the cross section to nothing (scale " + formatNumber(1.0 + k * q[axis]) + ")";
  return {};
}

DeformationPose::DeformationPose(const std::vector<Deformer>& deformers, double t) {
  for (const Deformer& d : deformers) {
    PosedDeformer posed;
    posed.type = d.type;
    posed.axis = d.axis;
    posed.toward = d.toward;
    posed.center = d.center;
    const double amount = d.amount.at(t);
    switch (d.type) {
      case Deformer::Type::Bend:
      case Deformer::Type::Twist: posed.k = glm::radians(amount) / d.length; break;
      case Deformer::Type::Taper: posed.k = amount / d.length; break;
      case Deformer::Type::SquashStretch: posed.k = amount; break;
    }
    stages_.push_back(posed);
  }
}

glm::dvec3 DeformationPose::forward(const glm::dvec3& rest) const {
  glm::dvec3 p = rest;
  for (const PosedDeformer& d : stages_) p = d.forward(p);
  return p;
}

glm::dvec3 DeformationPose::inverse(const glm::dvec3& deformed) const {
  glm::dvec3 p = deformed;
  for (auto d = stages_.rbegin(); d != stages_.rend(); ++d) p = d->inverse(p);
  return p;
}

std::vector<glm::vec3> deformPositions(const std::vector<glm::vec3>& rest, const DeformationPose& pose,
                                       const std::string& file, double t) {
  std::vector<glm::dvec3> points(rest.begin(), rest.end());
  const auto& stages = pose.stages();
  for (std::size_t s = 0; s < stages.size(); ++s) {
    for (std::size_t i = 0; i < points.size(); ++i) {
      const std::string problem = stages[s].outsideDomain(points[i]);
      if (!problem.empty())
        throw InputError((file.empty() ? std::string() : file + ": ") + indexPath("deformers", s) + ": at t = " +
                         formatNumber(t) + " the " + deformerTypeName(stages[s].type) + " " + problem);
      points[i] = stages[s].forward(points[i]);
    }
  }
  std::vector<glm::vec3> result(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!(glm::all(glm::lessThanEqual(glm::abs(points[i]), glm::dvec3(kMaxCoordinate)))))
      throw InputError((file.empty() ? std::string() : file + ": ") + "deformers: at t = " + formatNumber(t) +
                       " a vertex leaves the coordinate range");
    result[i] = glm::vec3(points[i]);
  }
  return result;
}

std::vector<Deformer> parseDeformers(const StrictJsonReader& in, const json& node) {
  if (!node.is_array()) in.fail("deformers", "expected an array of deformers, got " + describeType(node));
  std::vector<Deformer> result;
  for (std::size_t i = 0; i < node.size(); ++i) result.push_back(parseDeformer(in, node[i], indexPath("deformers", i)));
  return result;
}

}  // namespace sslpv
