#pragma once
// The dense LPV grids: a world-axis-aligned frame of cubic cells around the object,
// the material resampled into it, and the L1 SH light field (12 planes, SoA, x fastest).
#include <array>
#include <cstddef>
#include <glm/vec3.hpp>
#include <vector>

namespace sslpv {

struct Bounds;

struct GridFrame {
  glm::dvec3 origin{0.0};  ///< world position of the min corner of cell (0,0,0)
  double cellSize = 1.0;   ///< world units
  glm::ivec3 dims{0};

  std::size_t cellCount() const { return std::size_t(dims.x) * dims.y * dims.z; }
  /// x fastest, then y, then z.
  std::size_t index(int x, int y, int z) const {
    return (std::size_t(z) * dims.y + y) * dims.x + x;
  }
  bool contains(int x, int y, int z) const {
    return x >= 0 && y >= 0 && z >= 0 && x < dims.x && y < dims.y && z < dims.z;
  }
  glm::dvec3 cellMin(int x, int y, int z) const {
    return origin + cellSize * glm::dvec3(x, y, z);
  }
  glm::dvec3 cellCenter(int x, int y, int z) const {
    return origin + cellSize * (glm::dvec3(x, y, z) + 0.5);
  }
  /// The outermost layer of cells never holds light: it is where light leaves the grid.
  bool onOuterRing(int x, int y, int z) const {
    return x <= 0 || y <= 0 || z <= 0 || x >= dims.x - 1 || y >= dims.y - 1 || z >= dims.z - 1;
  }
  /// Continuous cell coordinates: cell (i,j,k) spans [i, i+1) on each axis.
  glm::dvec3 toGrid(const glm::dvec3& world) const { return (world - origin) / cellSize; }
};

/// Cells lo..hi of a frame, inclusive per axis; empty when lo > hi on any axis.
struct CellRange {
  glm::ivec3 lo{0}, hi{-1};
  bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
  std::size_t count() const {
    return empty() ? 0 : std::size_t(hi.x - lo.x + 1) * std::size_t(hi.y - lo.y + 1) * std::size_t(hi.z - lo.z + 1);
  }
  /// Grows to the smallest range holding both.
  void include(const CellRange& other);
};

/// The cells of `frame` whose box overlaps `world` (empty when none does).
CellRange cellsOverlapping(const GridFrame& frame, const Bounds& world);

/// The smallest resolution that holds the object: one cell for it and a margin cell on
/// each side (at 2 the object lay in the margin only, and every pixel came out black).
inline constexpr int kMinLpvResolution = 3;

/// Frame whose longest axis holds `resolution` cubic cells and that covers `bounds`
/// plus a margin of one cell on every side (so boundary cells always have neighbours
/// outside the object). Throws InputError below kMinLpvResolution. The renderers check
/// memory themselves (requireLpvMemory), each with its own layout.
GridFrame makeGridFrame(const Bounds& objectBounds, int resolution);

/// Peak bytes the CPU backend holds for a frame: the sum of its per-cell arrays while it
/// propagates (lpv_grid.cpp lists them).
std::size_t estimateLpvBytes(const GridFrame& frame);

/// Memory the system can give a new allocation without swapping: MemAvailable from
/// /proc/meminfo (physical memory where that is missing).
std::size_t availableMemoryBytes();

/// Throws ResourceError naming the grid, `backend` and the estimate when `bytes` exceed
/// availableMemoryBytes(): refused before allocating, rather than growing until the
/// machine runs out.
void requireLpvMemory(const GridFrame& frame, std::size_t bytes, const char* backend);

/// The material and occupancy of every LPV cell.
struct MaterialGrid {
  GridFrame frame;
  /// The object's mean chord 4 V / S (Cauchy), set by the renderers from the mesh: with
  /// σt' it gives the optical thickness the calibrated scheme corrects for (0: unknown,
  /// no correction).
  double meanChord = 0.0;
  std::vector<float> coverage;          ///< fraction of the cell inside the mesh, [0,1]
  std::vector<glm::vec3> sigmaT;        ///< box-filtered over the cell, per scene unit
  std::vector<glm::vec3> sigmaS;
  std::vector<float> g;
};

/// A cell takes part in light transport when part of it is inside the object and it is
/// not on the outer ring. Injection, propagation and shading all use this definition.
inline bool isActiveCell(const MaterialGrid& m, int x, int y, int z) {
  return !m.frame.onOuterRing(x, y, z) && m.coverage[m.frame.index(x, y, z)] > 0.0f;
}

/// L1 SH light field: coefficient plane c = channel*4 + sh (sh: 0 = Y00, 1..3 = Y1 x,y,z).
struct ShGrid {
  static constexpr int kPlanes = 12;
  GridFrame frame;
  std::array<std::vector<float>, kPlanes> planes;

  void resize(const GridFrame& f);
  void clear();
  float* plane(int channel, int sh) { return planes[channel * 4 + sh].data(); }
  const float* plane(int channel, int sh) const { return planes[channel * 4 + sh].data(); }
};

/// The power a light field holds, per channel: Σ c0 times the flux per unit of c0.
glm::dvec3 gridPower(const ShGrid& grid);

}  // namespace sslpv
