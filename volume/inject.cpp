// Injection: refracted flux enters the LPV as clamped-cosine L1 lobes (DESIGN.md).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <glm/geometric.hpp>

#include "volume/lpv_stages.h"
#include "volume/sh.h"

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

}  // namespace

InjectionStats injectSamples(const std::vector<SurfaceFluxSample>& samples, const MaterialGrid& material,
                             ShGrid& grid, const StepFactors* calibrated) {
  InjectionStats stats;
  const double halfCell = 0.5 * material.frame.cellSize;
  // Serial on purpose: samples of neighbouring texels write the same cells, and a 256²
  // map injects in about a millisecond.
  for (const SurfaceFluxSample& s : samples) {
    std::size_t cells[8];
    float weights[8];
    const glm::dvec3 p(s.position), n(s.normal);
    const int used = cellsAtDepth(material, p, n, halfCell, cells, weights);
    if (used == 0) {
      stats.droppedFlux += glm::dvec3(s.flux);
      continue;
    }
    if (calibrated == nullptr) {
      for (int ch = 0; ch < 3; ++ch)
        // A Lambertian emitter of power Φ has intensity (Φ/π) max(0, cos).
        addToCells(grid, ch, sh::cosineLobe(s.direction, s.flux[ch] / sh::kPi), cells, weights, used);
    } else {
      const std::size_t surfaceCell = depthCell(cells, weights, used);
      // The refracted beam first scatters about injectionDepth along its path, which is
      // shallower when it enters obliquely (more of it comes back out, as in the medium).
      const double cosRefracted = std::max(0.0, -glm::dot(glm::dvec3(s.direction), n));
      for (int ch = 0; ch < 3; ++ch) {
        const double depth = std::max(halfCell, double(calibrated->injectionDepth[ch][surfaceCell]) * cosRefracted);
        std::size_t deepCells[8];
        float deepWeights[8];
        int deepUsed = cellsAtDepth(material, p, n, depth, deepCells, deepWeights);
        // Deeper than the object is thick: keep the light where it entered.
        if (deepUsed == 0) {
          deepUsed = used;
          std::copy(cells, cells + used, deepCells);
          std::copy(weights, weights + used, deepWeights);
        }
        // Isotropic with power Φ: the c0 of a cosine lobe of power Φ, no linear band.
        const sh::Coeffs isotropic(sh::kLobeC0 * s.flux[ch] / sh::kPi, 0.0f, 0.0f, 0.0f);
        addToCells(grid, ch, isotropic, deepCells, deepWeights, deepUsed);
      }
    }
    stats.injectedFlux += glm::dvec3(s.flux);
  }
  return stats;
}

}  // namespace sslpv
