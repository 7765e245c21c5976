#pragma once
// Meshes and comparisons shared by the parity voxelizer's CPU and GPU tests
// (tests/lpv/voxelize_parity_test.cpp, tests/gpu/gpu_voxelize_test.cpp).
#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <string>
#include <vector>

#include "test_meshes.h"
#include "volume/lpv/lpv_grid.h"
#include "volume/scene/mesh.h"

namespace sslpv::test {

constexpr double kVoxelizePi = 3.14159265358979323846;

inline GridFrame cubeFrame(int n, double cellSize = 1.0, glm::dvec3 origin = glm::dvec3(0.0)) {
  GridFrame frame;
  frame.origin = origin;
  frame.cellSize = cellSize;
  frame.dims = glm::ivec3(n);
  return frame;
}

/// Rotates every vertex about `pivot` by Z, then Y, then X angles (radians).
inline TriangleMesh rotated(TriangleMesh mesh, glm::dvec3 pivot, double ax, double ay, double az) {
  for (glm::vec3& p : mesh.positions) {
    glm::dvec3 v = glm::dvec3(p) - pivot;
    v = glm::dvec3(v.x * std::cos(az) - v.y * std::sin(az), v.x * std::sin(az) + v.y * std::cos(az), v.z);
    v = glm::dvec3(v.x * std::cos(ay) + v.z * std::sin(ay), v.y, -v.x * std::sin(ay) + v.z * std::cos(ay));
    v = glm::dvec3(v.x, v.y * std::cos(ax) - v.z * std::sin(ax), v.y * std::sin(ax) + v.z * std::cos(ax));
    p = glm::vec3(v + pivot);
  }
  return mesh;
}

/// Torus around the z axis through `center`: ring radius R, tube radius r, n x m quads,
/// welded, counter-clockwise from outside.
inline TriangleMesh makeTorus(glm::dvec3 center, double R, double r, int n, int m) {
  TriangleMesh mesh;
  mesh.name = "test torus";
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      const double u = 2.0 * kVoxelizePi * i / n, v = 2.0 * kVoxelizePi * j / m;
      const double rho = R + r * std::cos(v);
      mesh.positions.emplace_back(center + glm::dvec3(rho * std::cos(u), rho * std::sin(u), r * std::sin(v)));
    }
  auto id = [&](int i, int j) { return unsigned(((i + n) % n) * m + (j + m) % m); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      mesh.triangles.emplace_back(id(i, j), id(i + 1, j), id(i + 1, j + 1));
      mesh.triangles.emplace_back(id(i, j), id(i + 1, j + 1), id(i, j + 1));
    }
  return mesh;
}

/// Octahedron |x| + |y| + |z| <= r around `center` (vertices on the axes).
inline TriangleMesh makeOctahedron(glm::dvec3 center, double r) {
  TriangleMesh mesh;
  mesh.name = "test octahedron";
  const glm::dvec3 axes[6] = {{r, 0, 0}, {-r, 0, 0}, {0, r, 0}, {0, -r, 0}, {0, 0, r}, {0, 0, -r}};
  for (const glm::dvec3& a : axes) mesh.positions.emplace_back(center + a);
  for (int sx = 0; sx < 2; ++sx)
    for (int sy = 0; sy < 2; ++sy)
      for (int sz = 0; sz < 2; ++sz) {
        const unsigned x = unsigned(sx), y = unsigned(2 + sy), z = unsigned(4 + sz);
        // Counter-clockwise from outside when the octant's sign count is even.
        if ((sx + sy + sz) % 2 == 0)
          mesh.triangles.emplace_back(x, y, z);
        else
          mesh.triangles.emplace_back(x, z, y);
      }
  return mesh;
}

/// A closed block whose top is a height field sampled at the cell-centre columns
/// (x + 0.5, y + 0.5) for x, y in [lo, hi] (unit cells, origin 0), bottom flat at
/// `bottom`, quads split along alternating diagonals: every vertex and every grid edge lies
/// on a column line, where only a consistent tie rule counts each crossing once.
inline TriangleMesh makeHeightBlock(int lo, int hi, double bottom, double (*height)(int, int)) {
  TriangleMesh mesh;
  mesh.name = "test height block";
  const int n = hi - lo + 1;
  auto top = [&](int i, int j) { return unsigned(i * n + j); };
  auto low = [&](int i, int j) { return unsigned(n * n + i * n + j); };
  for (int layer = 0; layer < 2; ++layer)
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        mesh.positions.emplace_back(lo + i + 0.5, lo + j + 0.5, layer == 0 ? height(lo + i, lo + j) : bottom);
  auto quad = [&](unsigned a, unsigned b, unsigned c, unsigned d, bool flip) {  // a b c d around
    if (flip) {
      mesh.triangles.emplace_back(a, b, c);
      mesh.triangles.emplace_back(a, c, d);
    } else {
      mesh.triangles.emplace_back(a, b, d);
      mesh.triangles.emplace_back(b, c, d);
    }
  };
  for (int i = 0; i + 1 < n; ++i)
    for (int j = 0; j + 1 < n; ++j) {
      const bool flip = (i + j) % 2 == 0;
      quad(top(i, j), top(i + 1, j), top(i + 1, j + 1), top(i, j + 1), flip);
      quad(low(i, j), low(i, j + 1), low(i + 1, j + 1), low(i + 1, j), flip);
    }
  for (int k = 0; k + 1 < n; ++k) {
    quad(top(k, 0), low(k, 0), low(k + 1, 0), top(k + 1, 0), false);
    quad(top(k + 1, n - 1), low(k + 1, n - 1), low(k, n - 1), top(k, n - 1), false);
    quad(top(0, k + 1), low(0, k + 1), low(0, k), top(0, k), false);
    quad(top(n - 1, k), low(n - 1, k), low(n - 1, k + 1), top(n - 1, k + 1), false);
  }
  return mesh;
}

inline double rollingHeight(int x, int y) { return 6.3 + 2.0 * std::sin(0.7 * x) * std::cos(0.9 * y) + 0.25 * (x % 3); }

inline double sumCoverage(const std::vector<float>& coverage) {
  double s = 0.0;
  for (float c : coverage) s += c;
  return s;
}

/// Per-cell differences between two coverage grids over the cells where either is
/// fractional (the band): mean and max |a - b|, and the cells whose active flag
/// (coverage > 0) differs anywhere in the grid.
struct CoverageDifference {
  double meanBand = 0.0, maxAbs = 0.0;
  double maxMismatchCoverage = 0.0;  ///< largest coverage of a cell whose active flag differs
  std::size_t bandCells = 0, activeMismatch = 0, worstCell = 0;
  std::string describe() const {
    return "mean |diff| over " + std::to_string(bandCells) + " band cells " + std::to_string(meanBand) +
           ", max " + std::to_string(maxAbs) + " (cell " + std::to_string(worstCell) + "), active flag differs in " +
           std::to_string(activeMismatch) + " cells (holding at most " + std::to_string(maxMismatchCoverage) + ")";
  }
};

inline CoverageDifference compareCoverage(const std::vector<float>& a, const std::vector<float>& b) {
  CoverageDifference d;
  double sum = 0.0;
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) {
    const double diff = std::fabs(double(a[i]) - double(b[i]));
    if (diff > d.maxAbs) d.maxAbs = diff, d.worstCell = i;
    if ((a[i] > 0.0f) != (b[i] > 0.0f)) {
      ++d.activeMismatch;
      d.maxMismatchCoverage = std::max(d.maxMismatchCoverage, double(std::max(a[i], b[i])));
    }
    const bool band = (a[i] > 0.0f && a[i] < 1.0f) || (b[i] > 0.0f && b[i] < 1.0f);
    if (band) {
      sum += diff;
      ++d.bandCells;
    }
  }
  d.meanBand = d.bandCells ? sum / double(d.bandCells) : 0.0;
  return d;
}

}  // namespace sslpv::test
