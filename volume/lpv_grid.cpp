#include "volume/lpv_grid.h"

#include <algorithm>
#include <cmath>
#include <glm/common.hpp>
#include <string>
#include <unistd.h>

#include "volume/error.h"
#include "volume/mesh.h"

namespace sslpv {

namespace {
// The CPU backend refuses grids beyond this share of physical memory, with a clear
// message, rather than dying in the allocator.
std::size_t physicalMemoryBytes() {
  long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || pageSize <= 0) return std::size_t(8) << 30;
  return std::size_t(pages) * std::size_t(pageSize);
}
}  // namespace

void CellRange::include(const CellRange& other) {
  if (other.empty()) return;
  if (empty()) {
    *this = other;
    return;
  }
  lo = glm::min(lo, other.lo);
  hi = glm::max(hi, other.hi);
}

CellRange cellsOverlapping(const GridFrame& frame, const Bounds& world) {
  CellRange cells;
  if (world.empty()) return cells;
  const glm::dvec3 gMin = frame.toGrid(world.min), gMax = frame.toGrid(world.max);
  for (int a = 0; a < 3; ++a) {
    const int lo = int(std::clamp(std::floor(gMin[a]), 0.0, double(frame.dims[a])));
    const int end = int(std::clamp(std::floor(gMax[a]) + 1.0, 0.0, double(frame.dims[a])));
    if (lo >= end) return CellRange{};
    cells.lo[a] = lo;
    cells.hi[a] = end - 1;
  }
  return cells;
}

GridFrame makeGridFrame(const Bounds& objectBounds, int resolution) {
  if (resolution < 2) throw InputError("LPV resolution must be at least 2, got " + std::to_string(resolution));
  if (objectBounds.empty()) throw InputError("the object has no extent");
  const glm::dvec3 extent = objectBounds.extent();
  const double longest = std::max({extent.x, extent.y, extent.z});
  if (!(longest > 0.0) || !std::isfinite(longest)) throw InputError("the object has zero or non-finite extent");
  // `resolution` cells span the longest axis including one margin cell on each side.
  const int interior = std::max(resolution - 2, 1);
  GridFrame frame;
  frame.cellSize = longest / interior;
  glm::dvec3 center = 0.5 * (objectBounds.min + objectBounds.max);
  for (int a = 0; a < 3; ++a) {
    int cells = std::max(1, int(std::ceil(extent[a] / frame.cellSize - 1e-9))) + 2;
    frame.dims[a] = std::min(cells, resolution);
    frame.origin[a] = center[a] - 0.5 * frame.dims[a] * frame.cellSize;
  }
  const std::size_t need = estimateLpvBytes(frame);
  const std::size_t have = physicalMemoryBytes();
  if (need > have / 10 * 8)
    throw ResourceError("an LPV of " + std::to_string(frame.dims.x) + "x" + std::to_string(frame.dims.y) + "x" +
                        std::to_string(frame.dims.z) + " cells needs " + std::to_string(need >> 20) +
                        " MiB, more than 80% of this machine's " + std::to_string(have >> 20) +
                        " MiB; lower the resolution");
  return frame;
}

std::size_t estimateLpvBytes(const GridFrame& frame) {
  // material: coverage + sigmaT + sigmaS + g + two 3-channel step factors; light: three SH grids.
  const std::size_t perCell = sizeof(float) * (1 + 3 + 3 + 1 + 6) + 3 * ShGrid::kPlanes * sizeof(float);
  return frame.cellCount() * perCell;
}

void ShGrid::resize(const GridFrame& f) {
  frame = f;
  for (auto& p : planes) p.assign(f.cellCount(), 0.0f);
}

void ShGrid::clear() {
  for (auto& p : planes) std::fill(p.begin(), p.end(), 0.0f);
}

}  // namespace sslpv
