#include "volume/cpu/single_scattering.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <glm/geometric.hpp>
#include <glm/vector_relational.hpp>
#include <utility>

#include "device_shared/lpv_constants.h"
#include "volume/lpv/lpv_stages.h"
#include "volume/cpu/inject.h"

namespace sslpv {
namespace {

struct ReducedMedium {
  glm::dvec3 extinction{0.0};  ///< σt' per channel
  glm::dvec3 scattering{0.0};  ///< σs' per channel
};

/// σt' and σs' over the cells and weights of activeTrilinearWeights; false for none (the
/// point has left the object).
bool reducedMedium(const MaterialGrid& material, const std::size_t* cells, const float* weights, int used,
                   ReducedMedium& out) {
  if (used == 0) return false;
  out = ReducedMedium{};
  for (int i = 0; i < used; ++i) {
    const glm::dvec3 sigmaT(material.sigmaT[cells[i]]), sigmaS(material.sigmaS[cells[i]]);
    const double g = material.g[cells[i]];
    out.extinction += double(weights[i]) * (sigmaT - g * sigmaS);
    out.scattering += double(weights[i]) * (1.0 - g) * sigmaS;
  }
  return true;
}

/// The texel of `map` whose ray passes through q, or null where q is outside the view.
/// `along` receives q's distance along that ray, measured as EntryTexel::distance is.
const EntryTexel* texelThrough(const EntryMap& map, const glm::dvec3& q, double& along) {
  const ShadowView& view = map.view;
  const glm::dvec3 d = q - view.origin;
  double u, v;
  if (view.projection == ShadowView::Projection::Orthographic) {
    u = glm::dot(d, view.right) / view.halfSize;
    v = glm::dot(d, view.up) / view.halfSize;
    along = glm::dot(d, view.forward);
  } else {
    const double z = glm::dot(d, view.forward);
    if (!(z > 0.0)) return nullptr;
    u = glm::dot(d, view.right) / (z * view.tanHalf);
    v = glm::dot(d, view.up) / (z * view.tanHalf);
    along = glm::length(d);
  }
  if (!(std::abs(u) <= 1.0 && std::abs(v) <= 1.0)) return nullptr;
  const int x = std::min(view.size - 1, int(0.5 * (u + 1.0) * view.size));
  const int y = std::min(view.size - 1, int(0.5 * (v + 1.0) * view.size));
  return &map.texels[std::size_t(y) * std::size_t(view.size) + std::size_t(x)];
}

/// -expm1(-x) / x, 1 at x = 0: the mean of e^{-x u} over u in [0, 1].
double meanDecay(double x) { return std::abs(x) < 1e-8 ? 1.0 - 0.5 * x : -std::expm1(-x) / x; }

}  // namespace

namespace {

/// ∫_a^b exp(−(c + r s)) ds, evaluated from the end with the larger exponent.
double exponentialSegment(double c, double r, double a, double b) {
  if (!(b > a)) return 0.0;
  const double x = r * (b - a);
  return x >= 0.0 ? std::exp(-(c + r * a)) * (b - a) * meanDecay(x) : std::exp(-(c + r * b)) * (b - a) * meanDecay(-x);
}

}  // namespace

double singleScatteringIntegral(double sigma, double p0, double k, double end) {
  if (!(sigma > 0.0) || !(end > 0.0)) return 0.0;
  const double infinite = std::numeric_limits<double>::infinity();
  // Where no exit was found, light from behind ends the ray at its own entry (P = 0).
  if (end == infinite && k < 0.0 && p0 >= 0.0) end = p0 / -k;
  // P(s) = p0 + k s changes sign at most once; on each side the integrand is one exponential.
  const double kink = k != 0.0 ? -p0 / k : -1.0;
  double total = 0.0, from = 0.0;
  for (const double to : {kink > 0.0 && kink < end ? kink : end, end}) {
    if (!(to > from)) continue;
    const double inside = to == infinite ? from + 1.0 : 0.5 * (from + to);
    const bool lit = p0 + k * inside > 0.0;
    const double c = lit ? sigma * p0 : 0.0, r = lit ? sigma * (1.0 + k) : sigma;
    total += to == infinite ? std::exp(-(c + r * from)) / r : exponentialSegment(c, r, from, to);
    from = to;
  }
  return total;
}

namespace {

int longestSide(const GridFrame& frame) { return std::max({frame.dims.x, frame.dims.y, frame.dims.z}); }

/// How deep singleScatteringGeometry searches for the exit: the steps of a medium of 1.5
/// optical depths per cell, so that in denser ones the search is all cached, and a clearer
/// one searches on from there.
constexpr int kCachedExitSteps = int(SSLPV_SINGLE_SCATTERING_EXIT_DEPTH / 1.5) + 1;

/// The first step i in [first, last] along `into` whose cell is not active; 0 for none.
int firstInactiveStep(const MaterialGrid& material, const glm::dvec3& p, const glm::dvec3& into, int first, int last) {
  const GridFrame& frame = material.frame;
  for (int i = first; i <= last; ++i) {
    const glm::dvec3 g = frame.toGrid(p + (i * frame.cellSize) * into);
    const glm::ivec3 c(int(std::floor(g.x)), int(std::floor(g.y)), int(std::floor(g.z)));
    if (!frame.contains(c.x, c.y, c.z) || !isActiveCell(material, c.x, c.y, c.z)) return i;
  }
  return 0;
}

/// Where viewRayExit searches to: SSLPV_SINGLE_SCATTERING_EXIT_DEPTH optical depths of
/// `extinction`, at most across the grid (an optically thin object is crossed whole: its
/// light comes from all of it).
int exitSearchSteps(const GridFrame& frame, double extinction) {
  return int(std::min<double>(longestSide(frame), std::ceil(SSLPV_SINGLE_SCATTERING_EXIT_DEPTH / (extinction * frame.cellSize))));
}

/// viewRayExit with the first `searched` steps' answer known (`exitStep`, 0: none there).
double exitAfter(const MaterialGrid& material, const glm::dvec3& p, const glm::dvec3& into, double extinction,
                 int exitStep, int searched) {
  const int steps = exitSearchSteps(material.frame, extinction);
  if (exitStep == 0 && steps > searched) exitStep = firstInactiveStep(material, p, into, searched + 1, steps);
  return exitStep > 0 && exitStep <= steps ? (exitStep - 0.5) * material.frame.cellSize
                                           : std::numeric_limits<double>::infinity();
}

}  // namespace

double viewRayExit(const MaterialGrid& material, const glm::dvec3& p, const glm::dvec3& into, double extinction) {
  return exitAfter(material, p, into, extinction, 0, 0);
}

SingleScatteringGeometry singleScatteringGeometry(const MaterialGrid& material, const glm::dvec3& p,
                                                  const glm::dvec3& inward, const glm::dvec3& into) {
  SingleScatteringGeometry geometry;
  geometry.used = activeTrilinearWeights(material, p + 0.5 * material.frame.cellSize * inward, geometry.cells.data(),
                                         geometry.weights.data());
  if (geometry.used > 0) {
    geometry.exitSearched = std::min(kCachedExitSteps, longestSide(material.frame));
    geometry.exitStep = firstInactiveStep(material, p, into, 1, geometry.exitSearched);
  }
  return geometry;
}

glm::vec3 singleScatteredRadiance(const MaterialGrid& material, const std::vector<EntryMap>& maps,
                                  const glm::dvec3& p, const glm::dvec3& inward, const glm::dvec3& into) {
  return singleScatteredRadiance(material, maps, p, inward, into, singleScatteringGeometry(material, p, inward, into));
}

glm::vec3 singleScatteredRadiance(const MaterialGrid& material, const std::vector<EntryMap>& maps,
                                  const glm::dvec3& p, const glm::dvec3& inward, const glm::dvec3& into,
                                  const SingleScatteringGeometry& geometry) {
  const double cellSize = material.frame.cellSize;
  glm::dvec3 q = p + 0.5 * cellSize * inward;
  ReducedMedium medium;
  if (!reducedMedium(material, geometry.cells.data(), geometry.weights.data(), geometry.used, medium))
    return glm::vec3(0.0f);
  // Where the view ray leaves the object, searched as deep as the most transparent
  // channel's light can come from.
  double clearest = std::numeric_limits<double>::infinity(), densest = 0.0;
  for (int ch = 0; ch < 3; ++ch)
    if (medium.extinction[ch] > 0.0) {
      clearest = std::min(clearest, medium.extinction[ch]);
      densest = std::max(densest, medium.extinction[ch]);
    }
  if (clearest == std::numeric_limits<double>::infinity()) return glm::vec3(0.0f);
  const double exit = exitAfter(material, p, into, clearest, geometry.exitStep, geometry.exitSearched);
  // Where the whole chord is under a mean free path, its light comes from all along it,
  // not from below the surface: the entry is read at the chord's middle (a point just
  // under the surface may lie past the terminator of a light that lights the inside).
  if (densest * exit < 1.0) q = p + 0.5 * exit * into;
  glm::dvec3 sum(0.0);
  int lastLight = -1;
  for (const EntryMap& map : maps) {
    if (map.light == lastLight) continue;  // a cube map's other faces
    double along = 0.0;
    const EntryTexel* texel = texelThrough(map, q, along);
    if (texel == nullptr) continue;
    lastLight = map.light;
    if (texel->irradiance == glm::vec3(0.0f)) continue;
    // q can sit up to a texel in front of its entry point; light that would reach q from
    // in front of the surface by more than a cell went round the object.
    const double below = along - double(texel->distance);
    if (below < -cellSize) continue;
    const double path = std::max(0.0, below) * texel->pathScale;
    // The planar estimate puts the entry of the beam that reaches q at q − path·d_t. Where
    // the surface curves away from the entry's tangent plane (past the light's terminator,
    // behind a grazing entry) that point is not where light enters: the light's own map
    // sees its surface elsewhere, and q gets none of this light. The cut is a ramp (full up
    // to the tolerance, none beyond twice it), so that a texel boundary or a rounding
    // cannot switch a pixel's light on or off.
    double entryAlong = 0.0;
    const glm::dvec3 start = q - path * glm::dvec3(texel->direction);
    const EntryTexel* entry = texelThrough(map, start, entryAlong);
    if (entry == nullptr || entry->irradiance == glm::vec3(0.0f)) continue;
    const double tolerance = std::max(1.5 * cellSize, 0.5 * below);
    const double onSurface = std::clamp(2.0 - glm::length(start - glm::dvec3(entry->position)) / tolerance, 0.0, 1.0);
    if (onSurface <= 0.0) continue;
    // P is linear below a planar entry face: at the surface point p it is p's depth below
    // the texel's tangent plane over cos θt (exact wherever p lies in the texel's
    // footprint, which a grazing light stretches over cells), and it changes along the
    // view ray by its gradient.
    const glm::dvec3 gradient(texel->pathGradient);
    const double p0 = glm::dot(p - glm::dvec3(texel->position), gradient);
    const double k = glm::dot(gradient, into);
    for (int ch = 0; ch < 3; ++ch)
      sum[ch] += onSurface * texel->irradiance[ch] * medium.scattering[ch] *
                 singleScatteringIntegral(medium.extinction[ch], p0, k, exit);
  }
  return glm::vec3(sum / (4.0 * SSLPV_PI));
}

}  // namespace sslpv
