#include "gpu/passes/propagation_items.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdlib>
#include <thread>

namespace sslpv::gpu {
namespace {

// Tile rows picked automatically, and the measured cost of a covered cell with 8 rows
// relative to 4 rows on lavapipe (64^3 cube, sphere and shell, bench/gpu_propagation_bench
// --rows 4|8: 0.87-0.92; fewer halo rows per tile against more covered cells).
constexpr double kWideRowCost = 0.9;

/// Orders items for lavapipe's compute pool, which splits a dispatch STATICALLY: with T
/// threads, each takes one run of N / T consecutive workgroups, then the N % T left take
/// one each. Dealing the items, longest first, to T equal-count bins in snake order
/// balances the runs' work; each bin keeps raster order, so a thread's consecutive tiles
/// share halo rows in its cache.
std::vector<LpvItem> balanceItems(std::vector<LpvItem> items, std::size_t threads) {
  const std::size_t perBin = items.size() / threads;
  if (threads < 2 || perBin == 0) return items;
  std::vector<std::size_t> order(items.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return items[a].zEnd - items[a].zBegin > items[b].zEnd - items[b].zBegin;
  });
  std::vector<std::vector<std::size_t>> bins(threads);
  std::size_t next = 0;
  for (std::size_t round = 0; round < perBin; ++round)
    for (std::size_t k = 0; k < threads; ++k) bins[round % 2 ? threads - 1 - k : k].push_back(order[next++]);
  std::vector<LpvItem> balanced;
  balanced.reserve(items.size());
  for (std::vector<std::size_t>& bin : bins) {
    std::sort(bin.begin(), bin.end());  // raster order: items were built tile by tile
    for (std::size_t i : bin) balanced.push_back(items[i]);
  }
  for (; next < order.size(); ++next) balanced.push_back(items[order[next]]);  // the shortest
  return balanced;
}

/// Per tile of SSLPV_TILE_X x rows cells and slice: does it hold an active cell? Indexed
/// (z * tilesY + tileY) * tilesX + tileX.
std::vector<unsigned char> occupiedSlabs(const GridFrame& frame, const StepFactors& factors, int rows) {
  const glm::ivec3 d = frame.dims;
  const int tilesX = (d.x + SSLPV_TILE_X - 1) / SSLPV_TILE_X, tilesY = (d.y + rows - 1) / rows;
  std::vector<unsigned char> slab(std::size_t(tilesX) * tilesY * std::max(d.z, 0), 0);
  tbb::parallel_for(0, std::max(d.z, 0), [&](int z) {
    for (int y = 0; y < d.y; ++y) {
      if (!factors.rowActive[std::size_t(z) * d.y + y]) continue;
      for (int x = 0; x < d.x; ++x)
        if (factors.active[frame.index(x, y, z)])
          slab[(std::size_t(z) * tilesY + y / rows) * tilesX + x / SSLPV_TILE_X] = 1;
    }
  });
  return slab;
}

}  // namespace

/// Threads that run a dispatch's workgroups: lavapipe's compute pool has LP_NUM_THREADS
/// or one per core; a GPU has far more lanes than items, so 1 disables balancing.
std::size_t workerThreads(const VulkanDevice& device) {
  if (!device.runsOnCpu()) return 1;
  if (const char* env = std::getenv("LP_NUM_THREADS")) return std::max(1, std::atoi(env));
  return std::max(1u, std::thread::hardware_concurrency());
}

/// Wide tiles re-read fewer halo rows, narrow ones cover fewer empty cells around a thin
/// or curved object: the cheaper by covered cells and the measured cost ratio.
int chooseTileRows(const GridFrame& frame, const StepFactors& factors) {
  const auto covered = [&](int rows) {
    const std::vector<unsigned char> slab = occupiedSlabs(frame, factors, rows);
    return double(std::count(slab.begin(), slab.end(), 1)) * SSLPV_TILE_X * rows;
  };
  return kWideRowCost * covered(kWideTileRows) <= covered(kNarrowTileRows) ? kWideTileRows : kNarrowTileRows;
}

ItemPlan planItems(const GridFrame& frame, const StepFactors& factors, int rows, int zChunk, std::size_t workers) {
  const glm::ivec3 d = frame.dims;
  const int tilesX = (std::max(d.x, 1) + SSLPV_TILE_X - 1) / SSLPV_TILE_X, tilesY = (std::max(d.y, 1) + rows - 1) / rows;
  const std::vector<unsigned char> slab = occupiedSlabs(frame, factors, rows);
  const auto occupied = std::size_t(std::count(slab.begin(), slab.end(), 1));
  ItemPlan plan;
  // Enough items for every worker of the device, without splitting runs so finely that
  // the 2 halo slices each piece re-reads dominate.
  plan.zChunk = zChunk > 0 ? zChunk
                           : int(std::clamp<std::size_t>((occupied + 8 * workers - 1) / (8 * workers), 4,
                                                         std::size_t(std::max(d.z, 4))));
  for (int ty = 0; ty < tilesY; ++ty)
    for (int tx = 0; tx < tilesX; ++tx)
      for (int z = 0; z < d.z;) {
        if (!slab[(std::size_t(z) * tilesY + ty) * tilesX + tx]) {
          ++z;
          continue;
        }
        int end = z;
        while (end < d.z && slab[(std::size_t(end) * tilesY + ty) * tilesX + tx]) ++end;
        // Split the run into near-equal pieces of at most zChunk slices.
        const int pieces = (end - z + plan.zChunk - 1) / plan.zChunk;
        for (int p = 0; p < pieces; ++p) {
          const int begin = z + (end - z) * p / pieces, stop = z + (end - z) * (p + 1) / pieces;
          plan.items.push_back(LpvItem{std::uint32_t(tx * SSLPV_TILE_X), std::uint32_t(ty * rows),
                                       std::uint32_t(begin), std::uint32_t(stop)});
          const int width = std::min(SSLPV_TILE_X, d.x - tx * SSLPV_TILE_X), height = std::min(rows, d.y - ty * rows);
          plan.coveredCells += std::size_t(width) * height * (stop - begin);
        }
        z = end;
      }
  plan.items = balanceItems(std::move(plan.items), workers);
  return plan;
}

}  // namespace sslpv::gpu
