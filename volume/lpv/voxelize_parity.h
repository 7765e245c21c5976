#pragma once
// Voxelization by nearest-triangle distance and column parity: the CPU twin of the GPU
// voxelizer (gpu/passes/gpu_voxelize.h), which re-voxelizes a deforming mesh every frame.
//
// Per cell centre: the exact distance to the nearest triangle within sqrt(3)/2 cells and
// the distance field's gradient direction there (from that triangle), and inside/outside
// by the parity of the mesh crossings below it along its z column. Coverage is the exact
// plane-cube fraction of that plane (the rule of volume/lpv/voxelize.cpp's voxelizeCoverage,
// which gets distance and gradient from an OpenVDB level set and central differences).
// All arithmetic that decides a value is in device_shared/voxelize_shared.h, shared with the
// GPU kernels; the twin only replaces their atomics with std::atomic.
#include <cstdint>
#include <glm/vec3.hpp>
#include <vector>

#include "volume/lpv/lpv_grid.h"
#include "volume/scene/mesh.h"

namespace sslpv {

/// The intermediate buffers of the parity voxelizer, laid out as on the GPU.
struct ParityVoxelization {
  GridFrame frame;
  /// Per cell (GridFrame::index order): the minimum over triangles within
  /// SSLPV_VOX_WHOLE_CELL of the centre of vox_pack(distance, direction), or
  /// SSLPV_VOX_EMPTY when none is that close.
  std::vector<std::uint32_t> nearest;
  /// Per (x, y) column (x fastest), wordsPerColumn words: bit z toggled once per mesh
  /// crossing whose first cell centre above it is z (crossings below the grid at z = 0).
  std::vector<std::uint32_t> parity;
  int wordsPerColumn = 0;
  std::vector<float> coverage;  ///< per cell, [0, 1]
};

/// Parity words per column of a frame: ceil(dims.z / 32).
int parityWordsPerColumn(const GridFrame& frame);

/// Voxelizes triangles (indices into `positions`, world space; closed and consistently
/// wound for a meaningful inside, though winding itself is not used) into `frame`.
/// Indices past the end of `positions` throw InputError.
ParityVoxelization voxelizeParityDetailed(const std::vector<glm::vec3>& positions,
                                          const std::vector<glm::uvec3>& triangles, const GridFrame& frame);

/// Coverage only (see voxelizeCoverage for the contract; same meaning, other algorithm).
std::vector<float> voxelizeCoverageParity(const TriangleMesh& mesh, const GridFrame& frame);

/// Inside flag of cell (x, y, z) from the parity words: an odd number of crossings below.
bool parityInside(const ParityVoxelization& v, int x, int y, int z);

}  // namespace sslpv
