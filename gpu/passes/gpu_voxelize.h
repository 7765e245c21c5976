#pragma once
// Per-frame voxelization of a (deforming) triangle mesh into the LPV occupancy grid on the
// GPU: the twin of sslpv::voxelizeParityDetailed() (volume/lpv/voxelize_parity.h), which it
// matches bit for bit where the device rounds as IEEE float without fused multiply-adds.
//
// Two kernels: per triangle, the packed nearest distance + direction to every cell
// centre within sqrt(3)/2 cells (atomic minimum) and a crossing bit per z column its xy
// projection covers (atomic xor, exact fixed-point edge rule); then per cell, inside by
// the parity of the crossings below and coverage by the plane-cube rule.
#include <cstdint>
#include <vector>

#include "gpu/vk/compute.h"
#include "gpu/vk/device.h"
#include "device_shared/voxelize_shared.h"
#include "volume/lpv/lpv_grid.h"
#include "volume/scene/mesh.h"

namespace sslpv::gpu {

/// GPU milliseconds of the last recording, from timestamps (0 where there are none).
struct GpuVoxelizeTimings {
  double clearMs = 0.0;      ///< filling the per-cell and per-column buffers
  double trianglesMs = 0.0;  ///< the per-triangle kernel (distances and crossings)
  double coverageMs = 0.0;   ///< the per-cell kernel
  double totalMs() const { return clearMs + trianglesMs + coverageMs; }
};

/// A mesh as the voxelizer reads it: std430 vec4 world positions (w unused) and three
/// uint indices per triangle. Host-visible where the device allows, so a deformation
/// writes the positions in place.
class VoxelizerMesh {
 public:
  /// Throws InputError when a triangle indexes past the vertices.
  VoxelizerMesh(const VulkanDevice& device, const TriangleMesh& mesh);

  /// New positions for the same vertices (a deformed frame). Must not be called while a
  /// recording that reads them is still executing.
  void setPositions(const std::vector<glm::vec3>& positions);

  const Buffer& positions() const { return positions_; }
  const Buffer& indices() const { return indices_; }
  std::uint32_t vertexCount() const { return vertexCount_; }
  std::uint32_t triangleCount() const { return triangleCount_; }

 private:
  void write(const Buffer& target, const void* data, VkDeviceSize bytes);

  const VulkanDevice& device_;
  std::uint32_t vertexCount_ = 0, triangleCount_ = 0;
  Buffer positions_, indices_;
};

/// Voxelizes into one GridFrame's coverage grid.
class GpuVoxelizer {
 public:
  /// Allocates the per-cell and per-column buffers of `frame` on `device` (which must
  /// outlive the voxelizer). Throws ResourceError when the grid exceeds the device's
  /// storage-buffer range.
  GpuVoxelizer(const VulkanDevice& device, const GridFrame& frame);

  /// Records the voxelization of `triangleCount` triangles (`indices`: 3 uint each, into
  /// `positions`: vec4 world positions) into coverage(), after a barrier against earlier
  /// transfer and compute writes of the inputs; ends with a compute-to-compute barrier, so
  /// later compute passes may read coverage(). The descriptor set is rewritten when the
  /// input buffers change: a recording with other buffers must not be submitted while an
  /// earlier one is still executing.
  void record(VkCommandBuffer cmd, const Buffer& positions, const Buffer& indices, std::uint32_t triangleCount);

  /// Records, submits and waits; returns the GPU timings.
  GpuVoxelizeTimings run(const Buffer& positions, const Buffer& indices, std::uint32_t triangleCount);
  GpuVoxelizeTimings run(const VoxelizerMesh& mesh) {
    return run(mesh.positions(), mesh.indices(), mesh.triangleCount());
  }
  /// Timings of the last recording, once it has executed.
  GpuVoxelizeTimings readTimings() const;

  /// Coverage per cell, float, GridFrame::index order (x fastest), [0, 1].
  const Buffer& coverage() const { return coverage_; }
  /// Host copies of the results (after the recording has executed).
  std::vector<float> readCoverage();
  std::vector<std::uint32_t> readNearest();  ///< packed words (see voxelize_shared.h)
  std::vector<std::uint32_t> readParity();   ///< wordsPerColumn() words per (x, y) column

  const GridFrame& frame() const { return frame_; }
  int wordsPerColumn() const { return int(push_.wordsPerColumn); }

 private:
  template <typename T>
  std::vector<T> read(const Buffer& source);

  const VulkanDevice& device_;
  GridFrame frame_;
  vox::VoxelizePush push_{};
  std::uint32_t coverageGroups_[2] = {1, 1};
  std::uint32_t maxTriangleGroups_ = 1;

  DescriptorSetLayout setLayout_;
  ComputePipeline trianglePipeline_, coveragePipeline_;
  Buffer nearest_, parity_, coverage_;
  StorageBufferSets sets_;
  VkBuffer boundPositions_ = VK_NULL_HANDLE, boundIndices_ = VK_NULL_HANDLE;
  CommandContext commands_;
  TimestampQueries timestamps_;
};

}  // namespace sslpv::gpu
