#pragma once
// The object's mesh on the device, read by the shadow-map, shading and voxelization passes.
#include <cstdint>
#include <glm/vec3.hpp>
#include <vector>

#include "gpu/vk/device.h"
#include "gpu/vk/resources.h"
#include "volume/core/bounds.h"
#include "volume/scene/mesh.h"

namespace sslpv::gpu {

/// The object's triangle mesh on the device, for the raster passes (vertex pulling) and
/// any compute pass that needs the surface:
/// - positions: std430 vec4 per vertex (xyz world position, w = 1);
/// - indices: std430 uint, 3 per triangle, counter-clockwise seen from outside;
/// - vertexFans: std430 uint, the triangles around each vertex in CSR form: vertexCount + 1
///   offsets into this same array (entries [fans[v], fans[v + 1]) are the triangles using
///   vertex v, ascending), then the lists. The resolve passes look there for the
///   neighbour an exact ray crosses when it misses the rasterized triangle
///   (shaders/ray_triangle_pick.glsl); meshes are welded (volume/scene/mesh.cpp), so shared
///   vertices connect the surface.
/// The position and index buffers also carry vertex/index-buffer usage for classic draws.
class GpuMesh {
 public:
  /// Uploads `mesh` (which need not outlive the GpuMesh). Throws GpuError when an index
  /// is out of range or a buffer exceeds the device's storage-buffer range.
  GpuMesh(const VulkanDevice& device, const TriangleMesh& mesh);

  const Buffer& positions() const { return positions_; }
  const Buffer& indices() const { return indices_; }
  const Buffer& vertexFans() const { return vertexFans_; }
  std::uint32_t vertexCount() const { return vertexCount_; }
  std::uint32_t triangleCount() const { return triangleCount_; }
  /// Bounds of the uploaded positions (as TriangleMesh::bounds()).
  const Bounds& bounds() const { return bounds_; }

  /// Replaces the vertex positions (a deformation with the same topology, so the vertex
  /// fans stay valid). The device must not be using the mesh meanwhile.
  void updatePositions(const VulkanDevice& device, const std::vector<glm::vec3>& positions);

 private:
  Buffer positions_, indices_, vertexFans_;
  std::uint32_t vertexCount_ = 0, triangleCount_ = 0;
  Bounds bounds_;
};

}  // namespace sslpv::gpu
