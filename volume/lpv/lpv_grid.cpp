#include "volume/lpv/lpv_grid.h"

#include <algorithm>
#include <cmath>
#include <glm/common.hpp>
#include <fstream>
#include <string>
#include <unistd.h>

#include "volume/core/error.h"
#include "device_shared/lpv_constants.h"
#include "volume/scene/mesh.h"
#include "volume/lpv/sh.h"

namespace sslpv {

std::size_t availableMemoryBytes() {
  std::ifstream meminfo("/proc/meminfo");
  std::string key;
  std::size_t kib = 0;
  std::string unit;
  while (meminfo >> key >> kib >> unit)
    if (key == "MemAvailable:") return kib * 1024;
  const long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || pageSize <= 0) return std::size_t(8) << 30;
  return std::size_t(pages) * std::size_t(pageSize);
}

void requireLpvMemory(const GridFrame& frame, std::size_t bytes, const char* backend) {
  const std::size_t have = availableMemoryBytes();
  if (bytes <= have) return;
  throw ResourceError("an LPV of " + std::to_string(frame.dims.x) + "x" + std::to_string(frame.dims.y) + "x" +
                      std::to_string(frame.dims.z) + " cells needs about " + std::to_string(bytes >> 20) +
                      " MiB on the " + backend + " backend, more than the " + std::to_string(have >> 20) +
                      " MiB this machine has available; lower --grid / lpv.resolution");
}

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
  if (resolution < kMinLpvResolution)
    throw InputError("--grid / lpv.resolution: must be at least " + std::to_string(kMinLpvResolution) +
                     " (a cell for the object and a margin cell on each side), got " + std::to_string(resolution));
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
  return frame;
}

std::size_t estimateLpvBytes(const GridFrame& frame) {
  // Per cell, what is held while the propagation runs (its peak; the step factors'
  // temporaries are gone by then), in bytes:
  //  - MaterialGrid: coverage 4, sigmaT 12, sigmaS 12, g 4;
  //  - StepFactors (calibrated): dc, linear, exitGain, reducedAlbedo, retention,
  //    injectionDepth, freshGain, conductance and entryCoupling 3 floats each, obliqueGain
  //    3 x SSLPV_OBLIQUE_INTERVALS floats, active 1;
  //  - ShGrids: the injected light and the accumulated light kept by the renderer, and
  //    propagate()'s working field and next step, kPlanes floats each;
  //  - the semi-iteration of --steps auto: source, current and older c0, 3 floats each.
  // Measured peak RSS less a small grid's (sphere, --steps auto): 371 B a cell at 64^3.
  constexpr std::size_t kFloat = sizeof(float);
  constexpr std::size_t material = kFloat * (1 + 3 + 3 + 1);
  constexpr std::size_t factors = kFloat * (9 * 3 + 3 * SSLPV_OBLIQUE_INTERVALS) + 1;
  constexpr std::size_t light = 4 * ShGrid::kPlanes * kFloat;
  constexpr std::size_t semiIteration = 3 * 3 * kFloat;
  return frame.cellCount() * (material + factors + light + semiIteration);
}

void ShGrid::resize(const GridFrame& f) {
  frame = f;
  for (auto& p : planes) p.assign(f.cellCount(), 0.0f);
}

void ShGrid::clear() {
  for (auto& p : planes) std::fill(p.begin(), p.end(), 0.0f);
}

glm::dvec3 gridPower(const ShGrid& grid) {
  glm::dvec3 power(0.0);
  for (int ch = 0; ch < 3; ++ch) {
    double sum = 0.0;
    for (float c0 : grid.planes[ch * 4]) sum += c0;
    power[ch] = sum * sh::kFluxPerC0;
  }
  return power;
}

}  // namespace sslpv
