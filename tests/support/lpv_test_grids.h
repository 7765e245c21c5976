#pragma once
// Hand-built LPV material grids for the propagation and injection tests.
#include "volume/lpv/lpv_grid.h"
#include "device_shared/lpv_constants.h"
#include "volume/lpv/lpv_stages.h"

namespace sslpv::test {

/// A dims³ grid of unit cells, every cell inside the medium except the outer ring.
inline MaterialGrid uniformMaterial(int dims, glm::vec3 sigmaT, glm::vec3 sigmaS, float g, double cellSize = 1.0) {
  MaterialGrid m;
  m.frame.origin = glm::dvec3(0.0);
  m.frame.cellSize = cellSize;
  m.frame.dims = glm::ivec3(dims);
  const std::size_t n = m.frame.cellCount();
  m.coverage.assign(n, 0.0f);
  for (int z = 1; z < dims - 1; ++z)
    for (int y = 1; y < dims - 1; ++y)
      for (int x = 1; x < dims - 1; ++x) m.coverage[m.frame.index(x, y, z)] = 1.0f;
  m.sigmaT.assign(n, sigmaT);
  m.sigmaS.assign(n, sigmaS);
  m.g.assign(n, g);
  return m;
}

/// Puts a cosine lobe of power `power` (all channels) pointing along `dir` into one cell.
inline void putLobe(ShGrid& grid, int x, int y, int z, glm::vec3 dir, float power) {
  const std::size_t i = grid.frame.index(x, y, z);
  const float c0 = float(SSLPV_COSINE_LOBE_C0) * power / float(SSLPV_PI);
  const float c1 = float(SSLPV_COSINE_LOBE_C1) * power / float(SSLPV_PI);
  for (int ch = 0; ch < 3; ++ch) {
    grid.plane(ch, 0)[i] += c0;
    grid.plane(ch, 1)[i] += c1 * dir.x;
    grid.plane(ch, 2)[i] += c1 * dir.y;
    grid.plane(ch, 3)[i] += c1 * dir.z;
  }
}

inline double channelPower(const ShGrid& grid, int ch) {
  double sum = 0.0;
  for (float c0 : grid.planes[ch * 4]) sum += c0;
  return sum * SSLPV_FLUX_PER_C0;
}

}  // namespace sslpv::test
