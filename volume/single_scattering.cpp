#include "volume/single_scattering.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/vector_relational.hpp>
#include <utility>

#include "volume/lpv_constants.h"
#include "volume/lpv_stages.h"

namespace sslpv {
namespace {

struct ReducedMedium {
  glm::dvec3 extinction{0.0};  ///< σt' per channel
  glm::dvec3 scattering{0.0};  ///< σs' per channel
};

/// σt' and σs' at q with the shading's coverage-weighted trilinear weights; false where no
/// active cell is near (q has left the object).
bool reducedMediumAt(const MaterialGrid& material, const glm::dvec3& q, ReducedMedium& out) {
  std::size_t cells[8];
  float weights[8];
  const int used = activeTrilinearWeights(material, q, cells, weights);
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

}  // namespace

int singleScatteringGroups(const glm::dvec3& extinction, int group[3], double reference[3]) {
  int order[3] = {0, 1, 2};
  std::sort(order, order + 3, [&](int a, int b) { return extinction[a] < extinction[b]; });
  int groups = 0;
  double low = 0.0, high = 0.0;
  for (int k = 0; k < 3; ++k) {
    const int ch = order[k];
    const double sigma = extinction[ch];
    if (!(sigma > 0.0)) {
      group[ch] = -1;  // no medium: nothing scatters
      continue;
    }
    if (groups == 0 || sigma > SSLPV_SINGLE_SCATTERING_GROUP_SPREAD * low) {
      low = sigma;
      ++groups;
    }
    high = sigma;
    group[ch] = groups - 1;
    reference[groups - 1] = std::sqrt(low) * std::sqrt(high);  // as shade.comp, whose float product overflows
  }
  return groups;
}

glm::vec3 singleScatteredRadiance(const MaterialGrid& material, const std::vector<EntryMap>& maps,
                                  const glm::dvec3& p, const glm::dvec3& inward, const glm::dvec3& into,
                                  double* reach) {
  const double cellSize = material.frame.cellSize;
  if (reach) *reach = 0.0;
  ReducedMedium surface;
  if (!reducedMediumAt(material, p + 0.5 * cellSize * inward, surface)) return glm::vec3(0.0f);
  // Channels whose σt' are close share their samples (spaced for the group's reference
  // σ): one medium and one shadow-map lookup serve them all.
  int group[3];
  double reference[3];
  const int groups = singleScatteringGroups(surface.extinction, group, reference);
  glm::dvec3 sum(0.0);
  // The samples sit at -log(1 - u) / σ0 (any σ0 > 0 is the same integral, weighted by
  // exp(σ0 s) / σ0); in an optically thin object spacing them by the mean free path put
  // every one beyond the object and the term read 0. Spacing them by at most the grid's
  // extent keeps ~60 % of them inside.
  const GridFrame& f = material.frame;
  const double extent = cellSize * std::max({f.dims.x, f.dims.y, f.dims.z});
  for (int gi = 0; gi < groups; ++gi) {
    const double sigma0 = std::max(reference[gi], 1.0 / extent);
    glm::dvec3 opticalDepth(0.0), lastSigma = surface.extinction;
    double lastS = 0.0;
    for (int k = 0; k < SSLPV_SINGLE_SCATTERING_SAMPLES; ++k) {
      const double u = (k + 0.5) / SSLPV_SINGLE_SCATTERING_SAMPLES;
      const double s = -std::log1p(-u) / sigma0;
      const glm::dvec3 q = p + s * into;
      if (reach) *reach = std::max(*reach, s);
      ReducedMedium medium;
      if (!reducedMediumAt(material, q, medium)) break;
      opticalDepth += 0.5 * (medium.extinction + lastSigma) * (s - lastS);
      lastS = s;
      lastSigma = medium.extinction;
      glm::dvec3 arriving(0.0);
      int lastLight = -1;
      for (const EntryMap& map : maps) {
        if (map.light == lastLight) continue;  // a cube map's other faces
        double along = 0.0;
        const EntryTexel* texel = texelThrough(map, q, along);
        if (texel == nullptr) continue;
        lastLight = map.light;
        if (texel->irradiance == glm::vec3(0.0f)) continue;
        // q can sit up to a texel in front of its entry point; light that would reach q
        // from in front of the surface by more than a cell went round the object.
        const double below = along - double(texel->distance);
        if (below < -cellSize) continue;
        const double path = std::max(0.0, below) * texel->pathScale;
        // The planar estimate puts the entry of the beam that reaches q at q − path·d_t.
        // Where the surface curves away from the entry's tangent plane (past the light's
        // terminator, behind a grazing entry) that point is not where light enters: the
        // light's own map sees its surface elsewhere, and q gets none of this light. The
        // cut is a ramp (full up to the tolerance, none beyond twice it), so that a texel
        // boundary or a rounding cannot switch a sample's light on or off.
        double entryAlong = 0.0;
        const glm::dvec3 start = q - path * glm::dvec3(texel->direction);
        const EntryTexel* entry = texelThrough(map, start, entryAlong);
        if (entry == nullptr || entry->irradiance == glm::vec3(0.0f)) continue;
        const double tolerance = std::max(1.5 * cellSize, 0.5 * below);
        const double onSurface =
            std::clamp(2.0 - glm::length(start - glm::dvec3(entry->position)) / tolerance, 0.0, 1.0);
        for (int ch = 0; ch < 3; ++ch)
          if (group[ch] == gi)
            arriving[ch] += onSurface * texel->irradiance[ch] * std::exp(-medium.extinction[ch] * path);
      }
      // ∫ σs' e^{-τ} f ds in the variable u: ds = du / (σ0 (1 − u)), and 1 − u = e^{-σ0 s}.
      for (int ch = 0; ch < 3; ++ch)
        if (group[ch] == gi)
          sum[ch] += medium.scattering[ch] / sigma0 * std::exp(sigma0 * s - opticalDepth[ch]) * arriving[ch];
    }
  }
  return glm::vec3(sum / (SSLPV_SINGLE_SCATTERING_SAMPLES * 4.0 * SSLPV_PI));
}

bool singleScatteringReads(const GridFrame& frame, const glm::dvec3& p, const glm::dvec3& inward,
                           const glm::dvec3& into, double reach, const CellRange& cells) {
  if (cells.empty()) return false;
  // activeTrilinearWeights reads cells floor(g) and floor(g) + 1, g = toGrid(q) − 0.5, so
  // cell c is read from g in [c − 1, c + 1); a margin keeps rounding on the safe side.
  constexpr double kMargin = 1e-3;
  const glm::dvec3 lo = glm::dvec3(cells.lo) - 1.0 - kMargin, hi = glm::dvec3(cells.hi) + 1.0 + kMargin;
  const auto grid = [&](const glm::dvec3& q) { return frame.toGrid(q) - 0.5; };
  const glm::dvec3 surface = grid(p + 0.5 * frame.cellSize * inward);
  if (glm::all(glm::greaterThanEqual(surface, lo)) && glm::all(glm::lessThanEqual(surface, hi))) return true;
  // The segment against the box, slab by slab.
  const glm::dvec3 a = grid(p), d = grid(p + reach * into) - a;
  double t0 = 0.0, t1 = 1.0;
  for (int axis = 0; axis < 3; ++axis) {
    if (std::abs(d[axis]) < 1e-12) {
      if (a[axis] < lo[axis] || a[axis] > hi[axis]) return false;
      continue;
    }
    double enter = (lo[axis] - a[axis]) / d[axis], leave = (hi[axis] - a[axis]) / d[axis];
    if (enter > leave) std::swap(enter, leave);
    t0 = std::max(t0, enter);
    t1 = std::min(t1, leave);
    if (t0 > t1) return false;
  }
  return true;
}

}  // namespace sslpv
