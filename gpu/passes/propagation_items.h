#pragma once
// How GpuPropagator splits a grid's occupied part into work items (tiles of
// SSLPV_TILE_X x rows cells marching through a run of slices), and orders them for
// lavapipe's compute pool. Host-side planning only; no Vulkan calls but the device query.
#include <cstddef>
#include <vector>

#include "gpu/vk/device.h"
#include "device_shared/lpv_shared.h"
#include "volume/lpv/lpv_stages.h"

namespace sslpv::gpu {

/// Tile rows the propagator uses when none are asked for (chooseTileRows' candidates).
inline constexpr int kNarrowTileRows = 4, kWideTileRows = 8;

/// Threads that run a dispatch's workgroups on `device` (1 on a GPU: no balancing).
std::size_t workerThreads(const VulkanDevice& device);

/// 8 or 4 rows, whichever covers the factors' active cells at less measured cost.
int chooseTileRows(const GridFrame& frame, const StepFactors& factors);

struct ItemPlan {
  std::vector<LpvItem> items;    ///< balanced for `workers` threads
  int zChunk = 0;                ///< most slices an item marches through
  std::size_t coveredCells = 0;  ///< cells the items cover (the work a step does)
};

/// The work items over every tile-slice that holds an active cell: runs of occupied
/// slices per tile, split into pieces of at most `zChunk` slices (0: enough pieces for
/// `workers` threads).
ItemPlan planItems(const GridFrame& frame, const StepFactors& factors, int rows, int zChunk, std::size_t workers);

}  // namespace sslpv::gpu
