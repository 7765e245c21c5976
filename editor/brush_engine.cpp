// The brush engine (formulas and conventions in brush_engine.h): construction, brush
// resolution, stroke paths, history and the public API. Dabs and the per-voxel update of
// each mode are in brush_paint.cpp.
#include "editor/brush_engine.h"

#include <openvdb/math/Maps.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <stdexcept>

#include "editor/brush_engine_impl.h"
#include "volume/core/error.h"
#include "volume/scene/ray_scene.h"

namespace sslpv {

using namespace brush_detail;

namespace {

constexpr std::size_t kMaxDabsPerCall = 1000000;
constexpr int kMaxRayBisections = 12;

}  // namespace

double BrushEngine::Impl::planeFor(const BrushMirror& mirror, int* twiceIndex) const {
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

void BrushEngine::Impl::resolve(const Brush& b) {
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
    case BrushChannel::Colour: {
      const MaterialSample m = artistToPhysical(b.artist, target.ior);
      driveRgb(0, glm::dvec3(m.sigmaT), true);
      driveRgb(3, glm::dvec3(m.sigmaS), true);
      r.drive[6] = true;
      r.value[6] = b.artist.g;
      break;
    }
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

void BrushEngine::Impl::segmentDabs(const glm::dvec3& from, const glm::dvec3& to,
                                    std::vector<glm::dvec3>& dabsOut) const {
  const double length = glm::length(to - from);
  if (!(length > 0.0)) return;
  const double steps = std::ceil(length / resolved.spacing);
  if (steps + double(dabsOut.size()) > double(kMaxDabsPerCall))
    throw InputError("points: the stroke needs more than 10^6 dabs (radius / 4 apart); use a larger radius");
  const int n = int(steps);
  for (int i = 1; i <= n; ++i) dabsOut.push_back(i == n ? to : from + (double(i) / n) * (to - from));
}

std::optional<SurfaceHit> BrushEngine::Impl::cast(const SurfaceRay& ray) const {
  const RayHit hit = rayScene->intersect(glm::vec3(ray.origin), glm::vec3(ray.direction));
  if (!hit.hit) return std::nullopt;
  return SurfaceHit{ray, glm::dvec3(hit.position), glm::dvec3(hit.normal)};
}

void BrushEngine::Impl::fillBetween(const SurfaceHit& a, const SurfaceHit& b, int level,
                                    std::vector<SurfaceHit>& out) const {
  if (level >= kMaxRayBisections || glm::length(a.position - b.position) <= resolved.spacing) return;
  const glm::dvec3 dir = glm::normalize(a.ray.direction) + glm::normalize(b.ray.direction);
  if (!(glm::length(dir) > 0.0)) return;
  const std::optional<SurfaceHit> mid = cast({0.5 * (a.ray.origin + b.ray.origin), glm::normalize(dir)});
  if (!mid) return;
  fillBetween(a, *mid, level + 1, out);
  out.push_back(*mid);
  fillBetween(*mid, b, level + 1, out);
}

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
  // A dab farther than its radius from the object's bounds paints nothing the object
  // shows, yet the set grows a voxel tree wherever it lands (a point at y = 1e5 grew the
  // set by gigabytes): such points are refused before any dab is applied.
  Bounds reach = m.target.restBounds;
  reach.min -= glm::dvec3(m.resolved.radiusRest);
  reach.max += glm::dvec3(m.resolved.radiusRest);
  for (std::size_t i = 0; i < worldPoints.size(); ++i) {
    const glm::dvec3& p = worldPoints[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) throw InputError("points: must be finite");
    const glm::dvec3 q = m.worldToRestPoint(p);
    bool outside = false;
    for (int a = 0; a < 3; ++a) outside = outside || q[a] < reach.min[a] || q[a] > reach.max[a];
    if (outside && !reach.empty()) {
      const auto text = [](const glm::dvec3& v) {
        char buffer[96];
        std::snprintf(buffer, sizeof buffer, "(%.6g, %.6g, %.6g)", v.x, v.y, v.z);
        return std::string(buffer);
      };
      throw InputError("points[" + std::to_string(i) + "]: " + text(p) +
                       " is farther than the brush radius from the object, whose rest-space bounds are " +
                       text(m.target.restBounds.min) + " .. " + text(m.target.restBounds.max) +
                       "; a stroke must stay within its radius of the object");
    }
  }
  for (const glm::dvec3& p : worldPoints) {
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
