// Injection: refracted flux enters the LPV as clamped-cosine L1 lobes (seed scheme) or as
// isotropic sources at the medium's depth (calibrated), docs/design.md §6.2 "Injection".
#include "volume/cpu/inject.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <glm/geometric.hpp>
#include <tbb/parallel_for.h>
#include <vector>

#include "volume/lpv/lpv_stages.h"
#include "volume/lpv/sh.h"

namespace sslpv {

int activeTrilinearWeights(const MaterialGrid& material, const glm::dvec3& p, std::size_t cells[8],
                           float weights[8]) {
  const GridFrame& f = material.frame;
  // Cell centres sit at half-integer grid coordinates.
  const glm::dvec3 g = f.toGrid(p) - 0.5;
  const glm::ivec3 base(int(std::floor(g.x)), int(std::floor(g.y)), int(std::floor(g.z)));
  const glm::dvec3 t = g - glm::dvec3(base);
  int used = 0;
  double total = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const glm::ivec3 c = base + glm::ivec3(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
    if (!f.contains(c.x, c.y, c.z) || !isActiveCell(material, c.x, c.y, c.z)) continue;
    const std::size_t index = f.index(c.x, c.y, c.z);
    // Weighting by coverage makes a cell that barely touches the object fade in rather
    // than switch on, which would show as contour rings across curved surfaces.
    const double w = (corner & 1 ? t.x : 1.0 - t.x) * (corner & 2 ? t.y : 1.0 - t.y) *
                     (corner & 4 ? t.z : 1.0 - t.z) * material.coverage[index];
    if (w <= 0.0) continue;
    cells[used] = index;
    weights[used] = float(w);
    total += w;
    ++used;
  }
  for (int i = 0; i < used; ++i) weights[i] = float(weights[i] / total);
  return used;
}

namespace {

/// Adds `coefficients` of one channel into the cells with the weights.
void addToCells(ShGrid& grid, int ch, const sh::Coeffs& coefficients, const std::size_t* cells,
                const float* weights, int used) {
  float* c0 = grid.plane(ch, 0);
  float* cx = grid.plane(ch, 1);
  float* cy = grid.plane(ch, 2);
  float* cz = grid.plane(ch, 3);
  for (int i = 0; i < used; ++i) {
    c0[cells[i]] += weights[i] * coefficients.x;
    cx[cells[i]] += weights[i] * coefficients.y;
    cy[cells[i]] += weights[i] * coefficients.z;
    cz[cells[i]] += weights[i] * coefficients.w;
  }
}

/// The active cells around p - depth n, else around the point half a cell deeper (thin
/// features: from the seed's Δx / 2 that is a full cell inside).
int cellsAtDepth(const MaterialGrid& material, const glm::dvec3& p, const glm::dvec3& n, double depth,
                 std::size_t cells[8], float weights[8]) {
  const int used = activeTrilinearWeights(material, p - depth * n, cells, weights);
  if (used > 0) return used;
  return activeTrilinearWeights(material, p - (depth + 0.5 * material.frame.cellSize) * n, cells, weights);
}

/// The cell whose injection depth a sample uses: of the active cells around the point
/// half a cell inside, the one with the largest weight (the first of equals).
std::size_t depthCell(const std::size_t* cells, const float* weights, int used) {
  int best = 0;
  for (int i = 1; i < used; ++i)
    if (weights[i] > weights[best]) best = i;
  return cells[best];
}

/// Where one sample's light goes: the cells half a cell inside (`used` 0: dropped) and, in
/// the calibrated scheme, each channel's cells at its depth.
struct Placement {
  std::size_t cells[8];
  float weights[8];
  int used = 0;
  std::size_t deepCells[3][8];
  float deepWeights[3][8];
  int deepUsed[3] = {0, 0, 0};
  float gain[3] = {1.0f, 1.0f, 1.0f};  ///< the oblique-entry gain per channel
};

void place(const SurfaceFluxSample& s, const MaterialGrid& material, const StepFactors* calibrated,
           Placement& out) {
  const double halfCell = 0.5 * material.frame.cellSize;
  const glm::dvec3 p(s.position), n(s.normal);
  out.used = cellsAtDepth(material, p, n, halfCell, out.cells, out.weights);
  if (out.used == 0 || calibrated == nullptr) return;
  const std::size_t surfaceCell = depthCell(out.cells, out.weights, out.used);
  // The refracted beam first scatters about injectionDepth along its path, which is
  // shallower when it enters obliquely (more of it comes back out, as in the medium; the
  // oblique-entry gain makes how much more exact for a thick slab).
  const double cosRefracted = std::max(0.0, -glm::dot(glm::dvec3(s.direction), n));
  const double incidence = incidentCosineSquared(cosRefracted, calibrated->ior);
  for (int ch = 0; ch < 3; ++ch) {
    out.gain[ch] = float(
        obliqueEntryGain(&calibrated->obliqueGain[ch][surfaceCell * std::size_t(kObliqueIntervals)], incidence) *
        double(calibrated->entryCoupling[ch][surfaceCell]));
    const double depth = std::max(halfCell, double(calibrated->injectionDepth[ch][surfaceCell]) * cosRefracted);
    int& used = out.deepUsed[ch];
    used = depth == halfCell ? 0 : cellsAtDepth(material, p, n, depth, out.deepCells[ch], out.deepWeights[ch]);
    // At the floor, or deeper than the object is thick: where it entered.
    if (used == 0) {
      used = out.used;
      std::copy(out.cells, out.cells + used, out.deepCells[ch]);
      std::copy(out.weights, out.weights + used, out.deepWeights[ch]);
    }
  }
}

}  // namespace

InjectionStats injectSamples(const std::vector<SurfaceFluxSample>& samples, const MaterialGrid& material,
                             ShGrid& grid, const StepFactors* calibrated) {
  InjectionStats stats;
  // Finding the cells (4 trilinear lookups a sample in the calibrated scheme) runs in
  // parallel over a block of samples; adding their light stays serial, because samples of
  // neighbouring texels write the same cells. About 1 MB of placements per block.
  constexpr std::size_t kBlock = 4096;
  std::vector<Placement> placements(std::min(kBlock, samples.size()));
  for (std::size_t first = 0; first < samples.size(); first += kBlock) {
    const std::size_t count = std::min(kBlock, samples.size() - first);
    tbb::parallel_for(std::size_t(0), count,
                      [&](std::size_t k) { place(samples[first + k], material, calibrated, placements[k]); });
    for (std::size_t k = 0; k < count; ++k) {
      const SurfaceFluxSample& s = samples[first + k];
      const Placement& at = placements[k];
      if (at.used == 0) {
        stats.droppedFlux += glm::dvec3(s.flux);
        continue;
      }
      for (int ch = 0; ch < 3; ++ch) {
        if (calibrated == nullptr) {
          // A Lambertian emitter of power Φ has intensity (Φ/π) max(0, cos).
          addToCells(grid, ch, sh::cosineLobe(s.direction, s.flux[ch] / sh::kPi), at.cells, at.weights, at.used);
        } else {
          // Isotropic with power Φ: the c0 of a cosine lobe of power Φ, no linear band.
          const sh::Coeffs isotropic(sh::kLobeC0 * at.gain[ch] * s.flux[ch] / sh::kPi, 0.0f, 0.0f, 0.0f);
          addToCells(grid, ch, isotropic, at.deepCells[ch], at.deepWeights[ch], at.deepUsed[ch]);
        }
      }
      stats.injectedFlux += glm::dvec3(s.flux);
    }
  }
  return stats;
}

}  // namespace sslpv
