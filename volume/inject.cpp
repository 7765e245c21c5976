// Injection: refracted flux enters the LPV as clamped-cosine L1 lobes (DESIGN.md).
#include <cmath>

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

InjectionStats injectSamples(const std::vector<SurfaceFluxSample>& samples, const MaterialGrid& material,
                             ShGrid& grid) {
  InjectionStats stats;
  const double halfCell = 0.5 * material.frame.cellSize;
  // Serial on purpose: samples of neighbouring texels write the same cells, and a 256²
  // map injects in about a millisecond.
  for (const SurfaceFluxSample& s : samples) {
    std::size_t cells[8];
    float weights[8];
    const glm::dvec3 p(s.position), n(s.normal);
    int used = activeTrilinearWeights(material, p - halfCell * n, cells, weights);
    // Thin features: look a full cell deeper before giving up on the sample.
    if (used == 0) used = activeTrilinearWeights(material, p - 2.0 * halfCell * n, cells, weights);
    if (used == 0) {
      stats.droppedFlux += glm::dvec3(s.flux);
      continue;
    }
    for (int ch = 0; ch < 3; ++ch) {
      // A Lambertian emitter of power Φ has intensity (Φ/π) max(0, cos).
      const sh::Coeffs lobe = sh::cosineLobe(s.direction, s.flux[ch] / sh::kPi);
      float* c0 = grid.plane(ch, 0);
      float* cx = grid.plane(ch, 1);
      float* cy = grid.plane(ch, 2);
      float* cz = grid.plane(ch, 3);
      for (int i = 0; i < used; ++i) {
        c0[cells[i]] += weights[i] * lobe.x;
        cx[cells[i]] += weights[i] * lobe.y;
        cy[cells[i]] += weights[i] * lobe.z;
        cz[cells[i]] += weights[i] * lobe.w;
      }
    }
    stats.injectedFlux += glm::dvec3(s.flux);
  }
  return stats;
}

}  // namespace sslpv
