#include "gpu/passes/gpu_voxelize.h"

#include <algorithm>
#include <cstring>
#include <string>

#include "volume/core/error.h"
#include "volume/lpv/voxelize_parity.h"

namespace sslpv::gpu {
namespace {

constexpr std::uint32_t kBindings = 5;  // positions, indices, nearest, parity, coverage
constexpr VkBufferUsageFlags kStorage =
    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;

std::string dimsText(const GridFrame& frame) {
  return std::to_string(frame.dims.x) + "x" + std::to_string(frame.dims.y) + "x" + std::to_string(frame.dims.z);
}

}  // namespace

VoxelizerMesh::VoxelizerMesh(const VulkanDevice& device, const TriangleMesh& mesh) : device_(device) {
  for (const glm::uvec3& t : mesh.triangles)
    if (t.x >= mesh.positions.size() || t.y >= mesh.positions.size() || t.z >= mesh.positions.size())
      throw InputError("mesh \"" + mesh.name + "\": a triangle indexes past its " +
                       std::to_string(mesh.positions.size()) + " vertices");
  vertexCount_ = std::uint32_t(mesh.positions.size());
  triangleCount_ = std::uint32_t(mesh.triangles.size());
  // Buffers cannot be empty: an empty mesh keeps one unused element.
  const MemoryUse use = device.unifiedMemory() ? MemoryUse::Device : MemoryUse::Host;
  positions_ = Buffer(device, std::max<VkDeviceSize>(vertexCount_, 1) * 4 * sizeof(float), kStorage, use);
  indices_ = Buffer(device, std::max<VkDeviceSize>(triangleCount_, 1) * 3 * sizeof(std::uint32_t), kStorage, use);
  if (triangleCount_ > 0) write(indices_, mesh.triangles.data(), VkDeviceSize(triangleCount_) * sizeof(glm::uvec3));
  setPositions(mesh.positions);
}

void VoxelizerMesh::setPositions(const std::vector<glm::vec3>& positions) {
  if (positions.size() != vertexCount_)
    throw GpuError("VoxelizerMesh::setPositions: " + std::to_string(positions.size()) + " positions for " +
                   std::to_string(vertexCount_) + " vertices");
  std::vector<float> padded(std::size_t(vertexCount_) * 4, 0.0f);
  for (std::size_t i = 0; i < positions.size(); ++i) std::memcpy(&padded[i * 4], &positions[i], sizeof(glm::vec3));
  if (!padded.empty()) write(positions_, padded.data(), padded.size() * sizeof(float));
}

void VoxelizerMesh::write(const Buffer& target, const void* data, VkDeviceSize bytes) {
  if (target.mapped()) {
    std::memcpy(target.mapped(), data, std::size_t(bytes));
    return;
  }
  // Device memory the host cannot map (discrete GPUs): through a staging copy.
  const Buffer staging(device_, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryUse::Host);
  std::memcpy(staging.mapped(), data, std::size_t(bytes));
  CommandContext commands(device_);
  VkCommandBuffer cmd = commands.begin();
  const VkBufferCopy region{0, 0, bytes};
  vkCmdCopyBuffer(cmd, staging.handle(), target.handle(), 1, &region);
  commands.submitAndWait();
}

GpuVoxelizer::GpuVoxelizer(const VulkanDevice& device, const GridFrame& frame)
    : device_(device), frame_(frame), commands_(device) {
  if (frame.dims.x < 0 || frame.dims.y < 0 || frame.dims.z < 0)
    throw GpuError("GpuVoxelizer: negative grid dimensions " + dimsText(frame));
  const VkPhysicalDeviceLimits& limits = device.properties().limits;
  const std::size_t cells = frame.cellCount();
  const int words = parityWordsPerColumn(frame);
  const VkDeviceSize cellBytes = std::max<VkDeviceSize>(cells, 1) * sizeof(float);
  const VkDeviceSize parityBytes =
      std::max<VkDeviceSize>(VkDeviceSize(frame.dims.x) * frame.dims.y * words, 1) * sizeof(std::uint32_t);
  if (cellBytes > limits.maxStorageBufferRange || parityBytes > limits.maxStorageBufferRange)
    throw ResourceError("LPV grid " + dimsText(frame) + " needs " + std::to_string(cellBytes >> 20) +
                        " MiB of coverage, more than the Vulkan device's storage-buffer range of " +
                        std::to_string(limits.maxStorageBufferRange >> 20) + " MiB");

  push_.originX = float(frame.origin.x);
  push_.originY = float(frame.origin.y);
  push_.originZ = float(frame.origin.z);
  push_.inverseCellSize = frame.cellSize > 0.0 ? float(1.0 / frame.cellSize) : 0.0f;
  push_.dimsX = frame.dims.x;
  push_.dimsY = frame.dims.y;
  push_.dimsZ = frame.dims.z;
  push_.wordsPerColumn = words;

  const std::uint64_t cellGroups = (std::uint64_t(cells) + SSLPV_VOX_CELL_GROUP - 1) / SSLPV_VOX_CELL_GROUP;
  coverageGroups_[0] = std::uint32_t(std::clamp<std::uint64_t>(cellGroups, 1, limits.maxComputeWorkGroupCount[0]));
  coverageGroups_[1] = std::uint32_t((cellGroups + coverageGroups_[0] - 1) / coverageGroups_[0]);
  if (coverageGroups_[1] > limits.maxComputeWorkGroupCount[1])
    throw ResourceError("LPV grid " + dimsText(frame) + " needs more workgroups than the Vulkan device dispatches");
  maxTriangleGroups_ = limits.maxComputeWorkGroupCount[0];

  setLayout_ = makeStorageBufferSetLayout(device, kBindings);
  trianglePipeline_ =
      ComputePipeline(device, spirv::voxelize_triangles_comp(), setLayout_.get(), sizeof(vox::VoxelizePush));
  coveragePipeline_ =
      ComputePipeline(device, spirv::voxelize_coverage_comp(), setLayout_.get(), sizeof(vox::VoxelizePush));
  nearest_ = Buffer(device, cellBytes, kStorage, MemoryUse::Device);
  parity_ = Buffer(device, parityBytes, kStorage, MemoryUse::Device);
  coverage_ = Buffer(device, cellBytes, kStorage, MemoryUse::Device);
  sets_ = StorageBufferSets(device, setLayout_.get(), kBindings, 1);
  sets_.write(0, 2, nearest_);
  sets_.write(0, 3, parity_);
  sets_.write(0, 4, coverage_);
  // Start, after the clears, after the triangle kernel, after the cell kernel.
  timestamps_ = TimestampQueries(device, 4);
}

void GpuVoxelizer::record(VkCommandBuffer cmd, const Buffer& positions, const Buffer& indices,
                          std::uint32_t triangleCount) {
  if (VkDeviceSize(triangleCount) * 3 * sizeof(std::uint32_t) > indices.size())
    throw GpuError("GpuVoxelizer::record: " + std::to_string(triangleCount) + " triangles need " +
                   std::to_string(VkDeviceSize(triangleCount) * 12) + " bytes of indices, the buffer has " +
                   std::to_string(indices.size()));
  if (positions.size() < 4 * sizeof(float)) throw GpuError("GpuVoxelizer::record: the position buffer is empty");
  if (positions.handle() != boundPositions_ || indices.handle() != boundIndices_) {
    sets_.write(0, 0, positions);
    sets_.write(0, 1, indices);
    boundPositions_ = positions.handle();
    boundIndices_ = indices.handle();
  }
  vox::VoxelizePush push = push_;
  push.triangleCount = triangleCount;
  const std::uint32_t triangleGroups = std::uint32_t(std::clamp<std::uint64_t>(
      (std::uint64_t(triangleCount) + SSLPV_VOX_TRIANGLE_GROUP - 1) / SSLPV_VOX_TRIANGLE_GROUP, 1, maxTriangleGroups_));
  push.threadCount = triangleGroups * SSLPV_VOX_TRIANGLE_GROUP;

  timestamps_.reset(cmd);
  timestamps_.write(cmd, 0);
  deviceWritesBarrier(cmd);  // the positions' writer, and earlier readers of our buffers
  vkCmdFillBuffer(cmd, nearest_.handle(), 0, VK_WHOLE_SIZE, SSLPV_VOX_EMPTY);
  vkCmdFillBuffer(cmd, parity_.handle(), 0, VK_WHOLE_SIZE, 0u);
  deviceWritesBarrier(cmd);
  timestamps_.write(cmd, 1);
  // A frame without a positive cell size covers nothing (as the twin and voxelizeCoverage).
  if (triangleCount > 0 && frame_.cellCount() > 0 && frame_.cellSize > 0.0) {
    trianglePipeline_.bind(cmd, sets_.set(0), &push, sizeof(push));
    vkCmdDispatch(cmd, triangleGroups, 1, 1);
  }
  computeToComputeBarrier(cmd);
  timestamps_.write(cmd, 2);
  if (frame_.cellCount() > 0) {
    coveragePipeline_.bind(cmd, sets_.set(0), &push, sizeof(push));
    vkCmdDispatch(cmd, coverageGroups_[0], coverageGroups_[1], 1);
  }
  computeToComputeBarrier(cmd);
  timestamps_.write(cmd, 3);
}

GpuVoxelizeTimings GpuVoxelizer::run(const Buffer& positions, const Buffer& indices, std::uint32_t triangleCount) {
  VkCommandBuffer cmd = commands_.begin();
  record(cmd, positions, indices, triangleCount);
  toHostBarrier(cmd);
  commands_.submitAndWait();
  return readTimings();
}

GpuVoxelizeTimings GpuVoxelizer::readTimings() const {
  const std::vector<double> ms = timestamps_.readMilliseconds(4);
  GpuVoxelizeTimings t;
  t.clearMs = ms[1] - ms[0];
  t.trianglesMs = ms[2] - ms[1];
  t.coverageMs = ms[3] - ms[2];
  return t;
}

template <typename T>
std::vector<T> GpuVoxelizer::read(const Buffer& source) {
  std::vector<T> out(std::size_t(source.size() / sizeof(T)));
  if (source.mapped()) {
    std::memcpy(out.data(), source.mapped(), out.size() * sizeof(T));
  } else {
    const Buffer staging(device_, source.size(), VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUse::Host);
    VkCommandBuffer cmd = commands_.begin();
    deviceWritesBarrier(cmd);
    const VkBufferCopy region{0, 0, source.size()};
    vkCmdCopyBuffer(cmd, source.handle(), staging.handle(), 1, &region);
    toHostBarrier(cmd);
    commands_.submitAndWait();
    std::memcpy(out.data(), staging.mapped(), out.size() * sizeof(T));
  }
  return out;
}

std::vector<float> GpuVoxelizer::readCoverage() {
  std::vector<float> out = read<float>(coverage_);
  out.resize(frame_.cellCount());  // an empty grid keeps one unused element
  return out;
}

std::vector<std::uint32_t> GpuVoxelizer::readNearest() {
  std::vector<std::uint32_t> out = read<std::uint32_t>(nearest_);
  out.resize(frame_.cellCount());
  return out;
}

std::vector<std::uint32_t> GpuVoxelizer::readParity() {
  std::vector<std::uint32_t> out = read<std::uint32_t>(parity_);
  out.resize(std::size_t(frame_.dims.x) * frame_.dims.y * std::size_t(wordsPerColumn()));
  return out;
}

}  // namespace sslpv::gpu
