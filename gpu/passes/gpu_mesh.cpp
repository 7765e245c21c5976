#include "gpu/passes/gpu_mesh.h"

#include <algorithm>
#include <cstddef>
#include <string>

#include "gpu/vk/graphics.h"
#include "gpu/vk/vk_check.h"

namespace sslpv::gpu {

GpuMesh::GpuMesh(const VulkanDevice& device, const TriangleMesh& mesh) {
  const std::size_t vertices = mesh.positions.size(), triangles = mesh.triangles.size();
  const VkDeviceSize positionBytes = VkDeviceSize(std::max<std::size_t>(vertices, 1)) * 4 * sizeof(float);
  const VkDeviceSize indexBytes = VkDeviceSize(std::max<std::size_t>(triangles, 1)) * 3 * sizeof(std::uint32_t);
  const VkDeviceSize range = device.properties().limits.maxStorageBufferRange;
  const VkDeviceSize fanBytes = (VkDeviceSize(vertices) + 1 + 3 * VkDeviceSize(triangles)) * sizeof(std::uint32_t);
  // Non-indexed draws of 3 vertices a triangle: gl_VertexIndex must stay in range too.
  if (positionBytes > range || indexBytes > range || fanBytes > range || triangles > std::size_t(0x7fffffff) / 3)
    throw GpuError("GpuMesh: mesh '" + mesh.name + "' (" + std::to_string(vertices) + " vertices, " +
                   std::to_string(triangles) + " triangles) exceeds the Vulkan device's storage-buffer range of " +
                   std::to_string(range >> 20) + " MiB");
  std::vector<std::uint32_t> indices(3 * triangles);
  for (std::size_t t = 0; t < triangles; ++t)
    for (int c = 0; c < 3; ++c) {
      if (mesh.triangles[t][c] >= vertices)
        throw GpuError("GpuMesh: mesh '" + mesh.name + "' triangle " + std::to_string(t) + " references vertex " +
                       std::to_string(mesh.triangles[t][c]) + " of " + std::to_string(vertices));
      indices[3 * t + c] = mesh.triangles[t][c];
    }
  constexpr VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                            VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  positions_ = Buffer(device, positionBytes, storage | VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, MemoryUse::Device);
  indices_ = Buffer(device, indexBytes, storage | VK_BUFFER_USAGE_INDEX_BUFFER_BIT, MemoryUse::Device);
  vertexCount_ = std::uint32_t(vertices);
  triangleCount_ = std::uint32_t(triangles);
  uploadToBuffer(device, indices_, indices.data(), indices.size() * sizeof(std::uint32_t));
  // Vertex fans by counting sort: offsets first (shifted past the offset table itself, so
  // one array serves the shaders), then each triangle appended to its three vertices' lists.
  std::vector<std::uint32_t> fans(vertices + 1 + 3 * triangles, 0u);
  for (const std::uint32_t v : indices) ++fans[v + 1];
  fans[0] = std::uint32_t(vertices + 1);
  for (std::size_t v = 0; v < vertices; ++v) fans[v + 1] += fans[v];
  std::vector<std::uint32_t> next(fans.begin(), fans.begin() + std::ptrdiff_t(vertices));
  for (std::size_t t = 0; t < triangles; ++t)
    for (int c = 0; c < 3; ++c) fans[next[indices[3 * t + c]]++] = std::uint32_t(t);
  vertexFans_ = Buffer(device, fanBytes, storage, MemoryUse::Device);
  uploadToBuffer(device, vertexFans_, fans.data(), fans.size() * sizeof(std::uint32_t));
  updatePositions(device, mesh.positions);
}

void GpuMesh::updatePositions(const VulkanDevice& device, const std::vector<glm::vec3>& positions) {
  if (positions.size() != vertexCount_)
    throw GpuError("GpuMesh::updatePositions: " + std::to_string(positions.size()) + " positions for a mesh of " +
                   std::to_string(vertexCount_) + " vertices");
  std::vector<float> packed(4 * positions.size());
  bounds_ = Bounds();
  for (std::size_t i = 0; i < positions.size(); ++i) {
    for (int c = 0; c < 3; ++c) packed[4 * i + c] = positions[i][c];
    packed[4 * i + 3] = 1.0f;
    bounds_.extend(glm::dvec3(positions[i]));
  }
  uploadToBuffer(device, positions_, packed.data(), packed.size() * sizeof(float));
}

}  // namespace sslpv::gpu
