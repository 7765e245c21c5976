// Box-filters the material field over each LPV cell (docs/design.md §4).
#include "volume/lpv/resample.h"

#include <tbb/blocked_range3d.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <algorithm>

namespace sslpv {
namespace {

/// Box-filters the field over the cells [lo, hi) of `material` (arrays already sized).
void resampleCells(const MaterialField& field, MaterialGrid& material, const glm::ivec3& lo, const glm::ivec3& hi) {
  const GridFrame frame = material.frame;
  if (field.homogeneous()) {
    const MaterialSample& base = field.base();
    for (int z = lo.z; z < hi.z; ++z)
      for (int y = lo.y; y < hi.y; ++y)
        for (int x = lo.x; x < hi.x; ++x) {
          const std::size_t index = frame.index(x, y, z);
          material.sigmaT[index] = base.sigmaT;
          material.sigmaS[index] = base.sigmaS;
          material.g[index] = base.g;
        }
    return;
  }
  // Blocks of cells rather than whole z-slabs: the voxels under an 8x8x8 block of cells
  // stay in cache while it is filled, where a slab walks through the whole grid before
  // returning to the same leaves for the next slab.
  constexpr int kBlock = 8;
  const tbb::blocked_range3d<int> blocks(lo.z, hi.z, kBlock, lo.y, hi.y, kBlock, lo.x, hi.x, kBlock);
  // A deformed object's grid spans all its poses (SceneObject::gridBounds), so most of its
  // cells lie outside the current pose, and each sample costs the deformers' inverse. No
  // lookup ever reads a cell none of whose 3x3x3 neighbourhood is covered (the stages
  // read cells holding the object and trilinear stencils around points inside it), so
  // those get the base material.
  const bool skipUnreachable = field.deformed() && material.coverage.size() == frame.cellCount();
  const auto reachable = [&](int x, int y, int z) {
    for (int dz = std::max(z - 1, 0); dz <= std::min(z + 1, frame.dims.z - 1); ++dz)
      for (int dy = std::max(y - 1, 0); dy <= std::min(y + 1, frame.dims.y - 1); ++dy)
        for (int dx = std::max(x - 1, 0); dx <= std::min(x + 1, frame.dims.x - 1); ++dx)
          if (material.coverage[frame.index(dx, dy, dz)] > 0.0f) return true;
    return false;
  };
  tbb::parallel_for(
      blocks,
      [&](const tbb::blocked_range3d<int>& block) {
        const MaterialField::Sampler sampler = field.sampler();
        for (int z = block.pages().begin(); z < block.pages().end(); ++z)
          for (int y = block.rows().begin(); y < block.rows().end(); ++y)
            for (int x = block.cols().begin(); x < block.cols().end(); ++x) {
              const glm::dvec3 cellMin = frame.cellMin(x, y, z);
              const MaterialSample cell = skipUnreachable && !reachable(x, y, z)
                                              ? field.base()
                                              : sampler.boxAverage(cellMin, cellMin + frame.cellSize);
              const std::size_t index = frame.index(x, y, z);
              material.sigmaT[index] = cell.sigmaT;
              material.sigmaS[index] = cell.sigmaS;
              material.g[index] = cell.g;
            }
      },
      tbb::simple_partitioner());
}

}  // namespace

void resampleMaterial(const MaterialField& field, MaterialGrid& material) {
  const std::size_t cells = material.frame.cellCount();
  material.sigmaT.resize(cells);
  material.sigmaS.resize(cells);
  material.g.resize(cells);
  resampleCells(field, material, glm::ivec3(0), material.frame.dims);
}

CellRange resampleMaterialRegion(const MaterialField& field, MaterialGrid& material, const Bounds& worldRegion) {
  const GridFrame& frame = material.frame;
  if (material.sigmaT.size() != frame.cellCount() || material.sigmaS.size() != frame.cellCount() ||
      material.g.size() != frame.cellCount()) {
    resampleMaterial(field, material);
    return CellRange{glm::ivec3(0), frame.dims - 1};
  }
  // Every cell whose box overlaps the region: its box average may have changed.
  const CellRange cells = cellsOverlapping(frame, worldRegion);
  if (!cells.empty()) resampleCells(field, material, cells.lo, cells.hi + 1);
  return cells;
}

}  // namespace sslpv
