#include "volume/lpv/voxelize_parity.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>

#include "device_shared/voxelize_shared.h"
#include "volume/core/error.h"

// The shared functions are compiled without fused multiply-adds (see the header); the same
// setting here lets them inline into the loops below.
#pragma GCC optimize("fp-contract=off")

namespace sslpv {
namespace {


struct Atomics {
  std::vector<std::atomic<std::uint32_t>> nearest;
  std::vector<std::atomic<std::uint32_t>> parity;
};

void atomicMin(std::atomic<std::uint32_t>& slot, std::uint32_t value) {
  std::uint32_t current = slot.load(std::memory_order_relaxed);
  while (value < current && !slot.compare_exchange_weak(current, value, std::memory_order_relaxed)) {
  }
}

int clampToInt(float v, int lo, int hi) {
  if (!(v > float(lo))) return lo;  // also NaN
  if (v >= float(hi)) return hi;
  return int(v);
}

/// Scatters the packed distance of triangle abc (grid coordinates) to every cell centre
/// within SSLPV_VOX_WHOLE_CELL: the triangle's box, and per column along the normal's
/// dominant axis only the slab the plane allows (at most ~3 cells of it).
void scatterDistance(const vox::vec3& a, const vox::vec3& b, const vox::vec3& c, const glm::ivec3& dims,
                     Atomics& out) {
  const glm::vec3 ga(a.x, a.y, a.z), gb(b.x, b.y, b.z), gc(c.x, c.y, c.z);
  // Candidates are enumerated with a margin over the exact distance test, so that float
  // rounding in the enumeration never drops a cell the test would keep: absolute near the
  // grid, relative for far-away vertices (as the GPU's enumerationReach()).
  const glm::vec3 m = glm::max(glm::max(glm::abs(ga), glm::abs(gb)), glm::abs(gc));
  const float reach = SSLPV_VOX_WHOLE_CELL + 1e-3f + 1e-6f * std::max({m.x, m.y, m.z});
  const glm::vec3 lo = glm::min(glm::min(ga, gb), gc) - reach, hi = glm::max(glm::max(ga, gb), gc) + reach;
  glm::ivec3 kLo, kHi;
  for (int i = 0; i < 3; ++i) {
    kLo[i] = clampToInt(std::ceil(lo[i] - 0.5f), 0, dims[i]);
    kHi[i] = clampToInt(std::floor(hi[i] - 0.5f), -1, dims[i] - 1);
    if (kLo[i] > kHi[i]) return;
  }
  const vox::vec3 vn = vox::vox_cross(b - a, c - a);
  const glm::vec3 n(vn.x, vn.y, vn.z), an = glm::abs(n);
  const int w = an.z >= an.x && an.z >= an.y ? 2 : (an.y >= an.x ? 1 : 0);
  const int u = (w + 1) % 3, v = (w + 2) % 3;
  const float length = glm::length(n);
  const bool slab = an[w] > 0.0f && std::isfinite(length) && length > 0.0f;
  const float halfWidth = slab ? reach * (length / an[w]) : 0.0f;
  vox::VoxTriangle triangle;
  vox::vox_setupTriangle(a, b, c, triangle);
  glm::ivec3 cell;
  for (cell[u] = kLo[u]; cell[u] <= kHi[u]; ++cell[u])
    for (cell[v] = kLo[v]; cell[v] <= kHi[v]; ++cell[v]) {
      int wLo = kLo[w], wHi = kHi[w];
      if (slab) {
        const float cu = float(cell[u]) + 0.5f, cv = float(cell[v]) + 0.5f;
        const float w0 = ga[w] - (n[u] * (cu - ga[u]) + n[v] * (cv - ga[v])) / n[w];
        wLo = std::max(wLo, clampToInt(std::ceil(w0 - halfWidth - 0.5f), -1, dims[w]));
        wHi = std::min(wHi, clampToInt(std::floor(w0 + halfWidth - 0.5f), -1, dims[w]));
      }
      for (cell[w] = wLo; cell[w] <= wHi; ++cell[w]) {
        const vox::vec3 p(float(cell.x) + 0.5f, float(cell.y) + 0.5f, float(cell.z) + 0.5f);
        float dist;
        vox::vec3 dir;
        vox::vox_pointTriangle(p, triangle, dist, dir);
        if (!(dist < SSLPV_VOX_WHOLE_CELL)) continue;
        const std::size_t index = (std::size_t(cell.z) * dims.y + cell.y) * dims.x + cell.x;
        atomicMin(out.nearest[index], vox::vox_pack(dist, dir));
      }
    }
}

/// Sign of the edge function of p->q at column c, exact in 64-bit integers, computed in
/// one canonical direction of the edge and with a tie rule that acts as if c were moved
/// by (eps, eps^2): both triangles sharing an edge see the same value with opposite
/// signs, so a column through the edge (or a vertex) is counted by exactly one of them.
/// 0 only for a degenerate edge. The GLSL twin is edgeSign() in voxelize_triangles.comp.
int edgeSign(glm::ivec2 p, glm::ivec2 q, glm::ivec2 c) {
  const bool swapped = p.x > q.x || (p.x == q.x && p.y > q.y);
  const glm::ivec2 s = swapped ? q : p, e = swapped ? p : q;
  if (s == e) return 0;
  const std::int64_t lhs = std::int64_t(e.x - s.x) * std::int64_t(c.y - s.y);
  const std::int64_t rhs = std::int64_t(e.y - s.y) * std::int64_t(c.x - s.x);
  int sign;
  if (lhs != rhs)
    sign = lhs > rhs ? 1 : -1;
  else
    sign = s.y != e.y ? (s.y > e.y ? 1 : -1) : 1;
  return swapped ? -sign : sign;
}

int floorDiv4096(int v) { return v >> 12; }
int ceilDiv4096(int v) { return -((-v) >> 12); }

/// Toggles the crossing bit of every column whose centre line passes through triangle
/// abc's xy projection.
void scatterParity(const vox::vec3& a, const vox::vec3& b, const vox::vec3& c, const glm::ivec3& dims,
                   int wordsPerColumn, Atomics& out) {
  // A triangle wholly above the grid's top centre toggles nothing inside it.
  if (std::floor(std::min({a.z, b.z, c.z}) + 0.5f) >= float(dims.z)) return;
  const glm::ivec2 pa(vox::vox_fixed(a.x), vox::vox_fixed(a.y));
  const glm::ivec2 pb(vox::vox_fixed(b.x), vox::vox_fixed(b.y));
  const glm::ivec2 pc(vox::vox_fixed(c.x), vox::vox_fixed(c.y));
  const int xLo = std::max(0, ceilDiv4096(std::min({pa.x, pb.x, pc.x})));
  const int xHi = std::min(dims.x - 1, floorDiv4096(std::max({pa.x, pb.x, pc.x})));
  const int yLo = std::max(0, ceilDiv4096(std::min({pa.y, pb.y, pc.y})));
  const int yHi = std::min(dims.y - 1, floorDiv4096(std::max({pa.y, pb.y, pc.y})));
  for (int y = yLo; y <= yHi; ++y)
    for (int x = xLo; x <= xHi; ++x) {
      const glm::ivec2 column(x * 4096, y * 4096);
      const int s0 = edgeSign(pa, pb, column), s1 = edgeSign(pb, pc, column), s2 = edgeSign(pc, pa, column);
      if (s0 == 0 || s0 != s1 || s1 != s2) continue;
      const int z = std::max(0, vox::vox_crossingCell(a, b, c, float(x) + 0.5f, float(y) + 0.5f));
      if (z >= dims.z) continue;
      const std::size_t word = (std::size_t(y) * dims.x + x) * wordsPerColumn + std::size_t(z >> 5);
      out.parity[word].fetch_xor(1u << (z & 31), std::memory_order_relaxed);
    }
}

}  // namespace

int parityWordsPerColumn(const GridFrame& frame) { return std::max(1, (frame.dims.z + 31) / 32); }

bool parityInside(const ParityVoxelization& v, int x, int y, int z) {
  const std::uint32_t* column =
      v.parity.data() + (std::size_t(y) * v.frame.dims.x + x) * std::size_t(v.wordsPerColumn);
  int ones = 0;
  for (int w = 0; w < (z >> 5); ++w) ones += __builtin_popcount(column[w]);
  const std::uint32_t mask = (2u << (z & 31)) - 1u;  // bits 0..z&31; 2u << 31 wraps to 0
  ones += __builtin_popcount(column[z >> 5] & mask);
  return (ones & 1) != 0;
}

ParityVoxelization voxelizeParityDetailed(const std::vector<glm::vec3>& positions,
                                          const std::vector<glm::uvec3>& triangles, const GridFrame& frame) {
  for (const glm::uvec3& t : triangles)
    if (t.x >= positions.size() || t.y >= positions.size() || t.z >= positions.size())
      throw InputError("voxelizeParity: a triangle indexes past the " + std::to_string(positions.size()) +
                       " vertices");
  ParityVoxelization result;
  result.frame = frame;
  result.wordsPerColumn = parityWordsPerColumn(frame);
  const std::size_t cells = frame.cellCount();
  const std::size_t columns = std::size_t(std::max(0, frame.dims.x)) * std::max(0, frame.dims.y);
  Atomics atomics{std::vector<std::atomic<std::uint32_t>>(cells),
                  std::vector<std::atomic<std::uint32_t>>(columns * result.wordsPerColumn)};
  for (auto& n : atomics.nearest) n.store(SSLPV_VOX_EMPTY, std::memory_order_relaxed);
  for (auto& p : atomics.parity) p.store(0u, std::memory_order_relaxed);

  if (cells > 0 && frame.cellSize > 0.0) {
    const vox::vec3 origin(float(frame.origin.x), float(frame.origin.y), float(frame.origin.z));
    const float inverseCellSize = float(1.0 / frame.cellSize);
    const auto toGrid = [&](const glm::vec3& p) {
      return vox::vox_toGrid(vox::vec3(p.x, p.y, p.z), origin, inverseCellSize);
    };
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, triangles.size(), 256),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        for (std::size_t t = range.begin(); t != range.end(); ++t) {
                          const glm::uvec3& tri = triangles[t];
                          const vox::vec3 a = toGrid(positions[tri.x]), b = toGrid(positions[tri.y]),
                                          c = toGrid(positions[tri.z]);
                          scatterDistance(a, b, c, frame.dims, atomics);
                          scatterParity(a, b, c, frame.dims, result.wordsPerColumn, atomics);
                        }
                      });
  }

  result.nearest.resize(cells);
  result.parity.resize(atomics.parity.size());
  for (std::size_t i = 0; i < cells; ++i) result.nearest[i] = atomics.nearest[i].load(std::memory_order_relaxed);
  for (std::size_t i = 0; i < result.parity.size(); ++i)
    result.parity[i] = atomics.parity[i].load(std::memory_order_relaxed);
  result.coverage.assign(cells, 0.0f);
  if (cells == 0) return result;
  tbb::parallel_for(0, frame.dims.z, [&](int z) {
    for (int y = 0; y < frame.dims.y; ++y)
      for (int x = 0; x < frame.dims.x; ++x) {
        const std::size_t i = frame.index(x, y, z);
        result.coverage[i] = vox::vox_cellCoverage(result.nearest[i], parityInside(result, x, y, z));
      }
  });
  return result;
}

std::vector<float> voxelizeCoverageParity(const TriangleMesh& mesh, const GridFrame& frame) {
  return voxelizeParityDetailed(mesh.positions, mesh.triangles, frame).coverage;
}

}  // namespace sslpv
