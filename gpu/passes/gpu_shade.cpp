#include "gpu/passes/gpu_shade.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <string>
#include <vector>

#include "gpu/passes/gpu_inject.h"
#include "device_shared/lpv_constants.h"
#include "volume/scene/shadow_view.h"
#include "volume/scene/camera_rays.h"

namespace sslpv::gpu {
namespace {

constexpr std::uint32_t kBindings = 12;  // see the bindings of shaders/shade.{vert,comp}
constexpr std::size_t kExitLawValues =
    std::size_t(SSLPV_EXIT_LAW_ALBEDO_INTERVALS + 1) * std::size_t(SSLPV_EXIT_LAW_MU_INTERVALS + 1);
constexpr VkFormat kTriangleFormat = VK_FORMAT_R32_UINT;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;

void requireBytes(const Buffer& buffer, VkDeviceSize bytes, const char* what) {
  if (buffer.size() < bytes)
    throw GpuError(std::string("GpuShader: the ") + what + " buffer holds " + std::to_string(buffer.size()) +
                   " bytes, " + std::to_string(bytes) + " needed");
}

/// The camera of shadeImage (volume/cpu/shade.cpp), in push-constant form.
GpuShadePush shadePush(const Camera& camera, const Bounds& bounds, const GridFrame& frame, double ior,
                       std::uint32_t singleScatteringViews) {
  const CameraRays pixelRays(camera);
  // A millionth of the object's size: reversed float depth (near / distance) keeps its
  // relative precision at any distance, and the CPU's camera rays start at 0.
  const double nearClip = 1e-6 * shadowBoundingSphere(bounds).radius;
  const double cellSize = frame.cellSize;
  GpuShadePush push{};
  push.eye = glm::vec4(glm::vec3(camera.position), nearClip);
  push.forward = glm::vec4(glm::vec3(pixelRays.forward), pixelRays.tanHalfX);
  push.right = glm::vec4(glm::vec3(pixelRays.right), pixelRays.tanHalfY);
  push.up = glm::vec4(glm::vec3(pixelRays.up), ior);
  // (1/(Aπ)) turns a cell's hemisphere-integrated intensity into radiance; leaving the
  // medium, radiance drops by 1/η² (radiance / n² is invariant across the boundary).
  push.viewport = glm::vec4(camera.width, camera.height, 1.0 / (cellSize * cellSize * SSLPV_PI) / (ior * ior), 0.0f);
  push.gridOrigin = glm::vec4(glm::vec3(frame.origin), cellSize);
  push.gridDims = glm::ivec4(frame.dims, int(singleScatteringViews));
  return push;
}

}  // namespace

Buffer uploadLightField(const VulkanDevice& device, const ShGrid& grid) {
  const std::size_t cells = grid.frame.cellCount();
  for (const std::vector<float>& plane : grid.planes)
    if (plane.size() != cells) throw GpuError("uploadLightField: the grid's planes do not match its frame");
  std::vector<float> packed(std::max<std::size_t>(cells, 1) * ShGrid::kPlanes, 0.0f);
  for (std::size_t i = 0; i < cells; ++i)
    for (int k = 0; k < ShGrid::kPlanes; ++k)
      packed[i * ShGrid::kPlanes + k] = grid.planes[k][i];  // k = channel*4 + sh
  Buffer buffer(
      device, packed.size() * sizeof(float),
      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
      MemoryUse::Device);
  uploadToBuffer(device, buffer, packed.data(), packed.size() * sizeof(float));
  return buffer;
}

Buffer uploadExitFactors(const VulkanDevice& device, const StepFactors& factors, const GridFrame& frame) {
  const std::size_t cells = frame.cellCount();
  for (const std::vector<float>& gain : factors.exitGain)
    if (gain.size() != cells) throw GpuError("uploadExitFactors: the step factors do not match the grid frame");
  const bool exitLaw = !factors.reducedAlbedo[0].empty();
  if (exitLaw)
    for (const std::vector<float>& albedo : factors.reducedAlbedo)
      if (albedo.size() != cells) throw GpuError("uploadExitFactors: the reduced albedos do not match the grid frame");
  std::vector<float> packed(std::max<std::size_t>(cells, 1) * 8, 0.0f);
  for (std::size_t i = 0; i < cells; ++i) {
    for (int ch = 0; ch < 3; ++ch) {
      packed[i * 8 + ch] = factors.exitGain[ch][i];
      if (exitLaw) packed[i * 8 + 4 + ch] = factors.reducedAlbedo[ch][i];
    }
    packed[i * 8 + 7] = exitLaw ? 1.0f : 0.0f;
  }
  Buffer buffer(device, packed.size() * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                MemoryUse::Device);
  uploadToBuffer(device, buffer, packed.data(), packed.size() * sizeof(float));
  return buffer;
}

Buffer uploadReducedMedium(const VulkanDevice& device, const MaterialGrid& material) {
  const std::size_t cells = material.frame.cellCount();
  if (material.sigmaT.size() != cells || material.sigmaS.size() != cells || material.g.size() != cells)
    throw GpuError("uploadReducedMedium: the material does not match its grid frame");
  std::vector<glm::vec4> packed(std::max<std::size_t>(cells, 1) * 2, glm::vec4(0.0f));
  for (std::size_t i = 0; i < cells; ++i) {
    const glm::dvec3 sigmaT(material.sigmaT[i]), sigmaS(material.sigmaS[i]);
    const double g = material.g[i];
    packed[2 * i] = glm::vec4(glm::vec3(sigmaT - g * sigmaS), 0.0f);
    packed[2 * i + 1] = glm::vec4(glm::vec3((1.0 - g) * sigmaS), 0.0f);
  }
  Buffer buffer(device, packed.size() * sizeof(glm::vec4),
                VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUse::Device);
  uploadToBuffer(device, buffer, packed.data(), packed.size() * sizeof(glm::vec4));
  return buffer;
}

Buffer uploadExitLaw(const VulkanDevice& device, const ExitLawTable& table) {
  if (table.shape.size() != kExitLawValues) throw GpuError("uploadExitLaw: the table has the wrong size");
  Buffer buffer(device, table.shape.size() * sizeof(float),
                VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUse::Device);
  uploadToBuffer(device, buffer, table.shape.data(), table.shape.size() * sizeof(float));
  return buffer;
}

GpuShader::GpuShader(const VulkanDevice& device, const GpuMesh& mesh, int width, int height)
    : device_(device), mesh_(mesh), width_(width), height_(height), commands_(device) {
  requireDynamicRendering(device);
  if (width < 1 || height < 1)
    throw GpuError("GpuShader: image size " + std::to_string(width) + "x" + std::to_string(height) + " is empty");
  setLayout_ = makeStorageBufferSetLayout(device, kBindings, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_COMPUTE_BIT);
  GraphicsPipelineDesc desc;
  desc.vertex = spirv::shade_vert();
  desc.fragment = spirv::shade_frag();
  desc.setLayout = setLayout_.get();
  desc.pushConstantBytes = sizeof(GpuShadePush);
  desc.pushConstantStages = VK_SHADER_STAGE_VERTEX_BIT;
  desc.colorFormat = kTriangleFormat;
  desc.depthFormat = kDepthFormat;
  // The shading projection keeps the image upright, so triangles counter-clockwise seen
  // from outside stay counter-clockwise in the framebuffer.
  desc.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
  desc.dynamicCullMode = true;
  rasterPipeline_ = GraphicsPipeline(device, desc);
  shadePipeline_ = ComputePipeline(device, spirv::shade_comp(), setLayout_.get(), sizeof(GpuShadePush));
  sets_ = StorageBufferSets(device, setLayout_.get(), kBindings, 1);
  triangleImage_ = Image2D(device, std::uint32_t(width), std::uint32_t(height), kTriangleFormat,
                           VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
  depthImage_ = Image2D(device, std::uint32_t(width), std::uint32_t(height), kDepthFormat,
                        VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT);
  const VkDeviceSize pixels = VkDeviceSize(width) * VkDeviceSize(height);
  constexpr VkBufferUsageFlags storage =
      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  triangleIds_ = Buffer(device, pixels * sizeof(std::uint32_t), storage, MemoryUse::Device);
  radiance_ = Buffer(device, pixels * 4 * sizeof(float), storage, MemoryUse::Device);
  sets_.write(0, 4, triangleIds_);
  sets_.write(0, 5, radiance_);
  timestamps_ = TimestampQueries(device, 2);
}

void GpuShader::record(VkCommandBuffer cmd, const Camera& camera, const Buffer& accumulated, const Buffer& cellCoverage,
                       const Buffer& exitFactors, const Buffer& exitLaw, const GridFrame& frame, double ior,
                       TimestampQueries* timestamps, std::uint32_t firstQuery, const GpuSingleScattering* single) {
  if (camera.width != width_ || camera.height != height_)
    throw GpuError("GpuShader: the camera is " + std::to_string(camera.width) + "x" + std::to_string(camera.height) +
                   ", the shader renders " + std::to_string(width_) + "x" + std::to_string(height_));
  if (frame.cellCount() == 0) throw GpuError("GpuShader: the grid frame has no cells");
  if (frame.cellCount() > std::size_t(0xffffffffu) / 3) throw GpuError("GpuShader: the grid has too many cells");
  requireBytes(accumulated, lightFieldBytes(frame), "accumulated light field");
  requireBytes(cellCoverage, VkDeviceSize(frame.cellCount()) * sizeof(float), "cell coverage");
  requireBytes(exitFactors, VkDeviceSize(frame.cellCount()) * 8 * sizeof(float), "exit factors");
  requireBytes(exitLaw, VkDeviceSize(kExitLawValues * sizeof(float)), "exit law");
  // Rewritten every recording, hence one recording in flight per shader (see the class).
  sets_.write(0, 0, mesh_.positions());
  sets_.write(0, 1, mesh_.indices());
  sets_.write(0, 2, accumulated);
  sets_.write(0, 3, cellCoverage);
  sets_.write(0, 6, mesh_.vertexFans());
  sets_.write(0, 7, exitFactors);
  sets_.write(0, 8, exitLaw);
  // Without the term its bindings still need buffers; the shader reads none of them.
  const bool withSingle = single != nullptr && single->viewCount > 0;
  if (withSingle) {
    if (!single->medium || !single->views || !single->samples)
      throw GpuError("GpuShader: the single-scattering inputs are incomplete");
    requireBytes(*single->medium, VkDeviceSize(frame.cellCount()) * 2 * 4 * sizeof(float), "reduced medium");
  }
  sets_.write(0, 9, withSingle ? *single->medium : exitFactors);
  sets_.write(0, 10, withSingle ? *single->views : exitFactors);
  sets_.write(0, 11, withSingle ? *single->samples : exitFactors);
  const GpuShadePush push = shadePush(camera, mesh_.bounds(), frame, ior, withSingle ? single->viewCount : 0u);

  if (timestamps) timestamps->write(cmd, firstQuery);
  // Earlier writes of the inputs (propagation, mesh updates) become visible, and earlier
  // readers of the outputs (the previous frame's copies) are done.
  pipelineMemoryBarrier(
      cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
      VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT,
      VK_PIPELINE_STAGE_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
      VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT);
  imageBarrier(cmd, triangleImage_, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
               VK_PIPELINE_STAGE_TRANSFER_BIT, 0, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
               VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
  imageBarrier(cmd, depthImage_, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
               VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT, VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
               VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT,
               VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT);
  VkClearColorValue background{};
  background.uint32[0] = 0;
  beginRendering(cmd, triangleImage_, background, &depthImage_, 0.0f);
  rasterPipeline_.bind(cmd, sets_.set(0), &push, sizeof push);
  vkCmdSetCullMode(cmd, eyeOutside(camera.position, mesh_.bounds()) ? VK_CULL_MODE_BACK_BIT : VK_CULL_MODE_NONE);
  if (mesh_.triangleCount() > 0) vkCmdDraw(cmd, 3 * mesh_.triangleCount(), 1, 0, 0);
  vkCmdEndRendering(cmd);
  imageBarrier(cmd, triangleImage_, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
               VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
               VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
  copyImageToBuffer(cmd, triangleImage_, triangleIds_);
  // The resolve reads the copied ids and writes back the triangle each ray crosses.
  pipelineMemoryBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                        VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
  shadePipeline_.bind(cmd, sets_.set(0), &push, sizeof push);
  vkCmdDispatch(cmd, (std::uint32_t(width_) + SSLPV_SHADE_GROUP_X - 1) / SSLPV_SHADE_GROUP_X,
                (std::uint32_t(height_) + SSLPV_SHADE_GROUP_Y - 1) / SSLPV_SHADE_GROUP_Y, 1);
  pipelineMemoryBarrier(
      cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_HOST_BIT,
      VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_HOST_READ_BIT);
  if (timestamps) timestamps->write(cmd, firstQuery + 1);
}

Image GpuShader::shade(const Camera& camera, const Buffer& accumulated, const Buffer& cellCoverage,
                       const Buffer& exitFactors, const Buffer& exitLaw, const GridFrame& frame, double ior,
                       const GpuSingleScattering* single) {
  VkCommandBuffer cmd = commands_.begin();
  timestamps_.reset(cmd);
  record(cmd, camera, accumulated, cellCoverage, exitFactors, exitLaw, frame, ior, &timestamps_, 0, single);
  commands_.submitAndWait();
  lastShadeMs_ = timestamps_.readMilliseconds(2)[1];

  Image image(width_, height_);
  std::vector<float> rgba(image.pixels.size() * 4);
  readFromBuffer(device_, radiance_, rgba.data(), rgba.size() * sizeof(float));
  for (std::size_t i = 0; i < image.pixels.size(); ++i)
    image.pixels[i] = glm::vec3(rgba[4 * i], rgba[4 * i + 1], rgba[4 * i + 2]);
  return image;
}

std::vector<std::uint32_t> GpuShader::readTriangles() const {
  std::vector<std::uint32_t> ids(std::size_t(width_) * std::size_t(height_));
  readFromBuffer(device_, triangleIds_, ids.data(), ids.size() * sizeof(std::uint32_t));
  return ids;
}

}  // namespace sslpv::gpu
