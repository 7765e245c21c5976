#include "gpu/passes/gpu_shadow_map.h"

#include <algorithm>
#include <string>

#include "volume/core/error.h"

namespace sslpv::gpu {
namespace {

constexpr std::uint32_t kBindings = 7;  // see the bindings of shaders/shadow_map.{vert,comp}
constexpr VkFormat kTriangleFormat = VK_FORMAT_R32_UINT;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
constexpr VkBufferUsageFlags kStorage =
    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;

GpuShadowView viewRecord(const ShadowView& view, const Light& light, const ShadowBoundingSphere& sphere, double ior,
                         std::uint32_t firstSample, std::uint32_t lightIndex) {
  const bool perspective = view.projection == ShadowView::Projection::Perspective;
  GpuShadowView record{};
  record.origin = glm::vec4(glm::vec3(view.origin), perspective ? SSLPV_SHADOW_PERSPECTIVE : SSLPV_SHADOW_ORTHOGRAPHIC);
  record.forward = glm::vec4(glm::vec3(view.forward), perspective ? view.tanHalf : view.halfSize);
  record.right =
      glm::vec4(glm::vec3(view.right), perspective ? view.perspectiveTexelScale() : view.orthographicTexel());
  double depthParameter = 4.0 * view.halfSize;  // orthographic: rays start 2 radii before the centre
  // Perspective near clip: a millionth of the object's size. Reversed float depth
  // (near / distance) keeps its relative precision at any distance, and any larger near
  // plane would clip surfaces that a wide map sees obliquely close to the light (Embree
  // rays start at 0).
  if (perspective) depthParameter = 1e-6 * sphere.radius;
  record.up = glm::vec4(glm::vec3(view.up), depthParameter);
  const bool directional = light.type == Light::Type::Directional;
  const bool spot = light.type == Light::Type::Spot;
  record.power = glm::vec4(directional ? light.irradiance : light.intensity,
                           spot ? spotCosHalfAngle(light) : SSLPV_SHADOW_NO_CONE);
  record.coneAxis = glm::vec4(spot ? glm::vec3(light.direction) : glm::vec3(0.0f), ior);
  record.texels = glm::uvec4(std::uint32_t(view.size), firstSample, lightIndex, 0u);
  return record;
}

}  // namespace

GpuShadowMapper::GpuShadowMapper(const VulkanDevice& device, const GpuMesh& mesh, int size)
    : device_(device), mesh_(mesh), size_(size), commands_(device) {
  requireDynamicRendering(device);
  if (size < 1) throw GpuError("GpuShadowMapper: the shadow map size must be at least 1, got " + std::to_string(size));
  setLayout_ = makeStorageBufferSetLayout(device, kBindings, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_COMPUTE_BIT);
  GraphicsPipelineDesc desc;
  desc.vertex = spirv::shadow_map_vert();
  desc.fragment = spirv::shadow_map_frag();
  desc.setLayout = setLayout_.get();
  desc.pushConstantBytes = sizeof(ShadowRasterPush);
  desc.pushConstantStages = VK_SHADER_STAGE_VERTEX_BIT;
  desc.colorFormat = kTriangleFormat;
  desc.depthFormat = kDepthFormat;
  // Shadow views are not flipped vertically (texel row y runs along `up`), so triangles
  // counter-clockwise seen from outside appear clockwise in the framebuffer.
  desc.frontFace = VK_FRONT_FACE_CLOCKWISE;
  desc.dynamicCullMode = true;
  rasterPipeline_ = GraphicsPipeline(device, desc);
  resolvePipeline_ = ComputePipeline(device, spirv::shadow_map_comp(), setLayout_.get(), 0);
  sets_ = StorageBufferSets(device, setLayout_.get(), kBindings, 1);
  triangleImage_ = Image2D(device, std::uint32_t(size), std::uint32_t(size), kTriangleFormat,
                           VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
  depthImage_ = Image2D(device, std::uint32_t(size), std::uint32_t(size), kDepthFormat,
                        VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT);
  timestamps_ = TimestampQueries(device, 2);
  setLights({}, 1.0);
}

void GpuShadowMapper::setLights(const std::vector<Light>& lights, double ior) {
  const Bounds& bounds = mesh_.bounds();
  const ShadowBoundingSphere sphere = shadowBoundingSphere(bounds);
  const std::uint64_t texelsPerView = std::uint64_t(size_) * std::uint64_t(size_);
  std::vector<ShadowView> views;
  std::vector<GpuShadowLight> placed;
  std::vector<GpuShadowView> records;
  for (const Light& light : lights) {
    const std::vector<ShadowView> lightViews = planShadowViews(light, bounds, size_);
    GpuShadowLight info;
    info.firstView = std::uint32_t(views.size());
    info.viewCount = std::uint32_t(lightViews.size());
    info.culled = lightViews.empty();
    info.firstSample = std::uint32_t(views.size() * texelsPerView);
    info.sampleCount = std::uint32_t(lightViews.size() * texelsPerView);
    for (const ShadowView& view : lightViews) {
      records.push_back(viewRecord(view, light, sphere, ior, std::uint32_t(views.size() * texelsPerView),
                                   std::uint32_t(placed.size())));
      views.push_back(view);
    }
    placed.push_back(info);
  }
  const std::uint64_t samples = views.size() * texelsPerView;
  const VkDeviceSize range = device_.properties().limits.maxStorageBufferRange;
  if (samples * sizeof(GpuFluxSample) > range)
    throw ResourceError(std::to_string(views.size()) + " shadow-map views of " + std::to_string(size_) + "x" +
                        std::to_string(size_) + " texels need " +
                        std::to_string((samples * sizeof(GpuFluxSample)) >> 20) +
                        " MiB of samples, more than the Vulkan device's storage-buffer range of " +
                        std::to_string(range >> 20) + " MiB; lower the shadow-map size");
  if (views.size() > device_.properties().limits.maxComputeWorkGroupCount[2])
    throw ResourceError("too many shadow-map views for one dispatch: " + std::to_string(views.size()));

  // Buffers grow only; zero-sized buffers are invalid, so each holds at least one record.
  const VkDeviceSize recordBytes = std::max<std::size_t>(records.size(), 1) * sizeof(GpuShadowView);
  const VkDeviceSize sampleBytes = std::max<std::uint64_t>(samples, 1) * sizeof(GpuFluxSample);
  const VkDeviceSize idBytes = std::max<std::uint64_t>(samples, 1) * sizeof(std::uint32_t);
  if (viewRecords_.size() < recordBytes) {
    viewRecords_ = Buffer(device_, recordBytes, kStorage, MemoryUse::Device);
    sets_.write(0, 2, viewRecords_);
  }
  if (samples_.size() < sampleBytes) {
    samples_ = Buffer(device_, sampleBytes, kStorage, MemoryUse::Device);
    rasterIds_ = Buffer(device_, idBytes, kStorage, MemoryUse::Device);
    triangleIds_ = Buffer(device_, idBytes, kStorage, MemoryUse::Device);
    sets_.write(0, 3, triangleIds_);
    sets_.write(0, 6, rasterIds_);
    sets_.write(0, 4, samples_);
  }
  sets_.write(0, 0, mesh_.positions());
  sets_.write(0, 1, mesh_.indices());
  sets_.write(0, 5, mesh_.vertexFans());
  uploadToBuffer(device_, viewRecords_, records.data(), records.size() * sizeof(GpuShadowView));

  lightList_ = lights;
  views_ = std::move(views);
  lights_ = std::move(placed);
  sampleCount_ = std::uint32_t(samples);
}

void GpuShadowMapper::record(VkCommandBuffer cmd, TimestampQueries* timestamps, std::uint32_t firstQuery) const {
  if (timestamps) timestamps->write(cmd, firstQuery);
  // Earlier readers of the samples and ids (the previous frame's injection) are done,
  // and earlier writes of the mesh (a deformation pass, uploads) are visible.
  pipelineMemoryBarrier(
      cmd,
      VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT,
      VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT,
      VK_PIPELINE_STAGE_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
      VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT);
  const VkDescriptorSet set = sets_.set(0);
  const VkDeviceSize texelsPerView = VkDeviceSize(size_) * size_;
  for (std::uint32_t v = 0; v < views_.size(); ++v) {
    // The previous view's copy has read the triangle ids; its depth is no longer needed.
    imageBarrier(cmd, triangleImage_, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                 VK_PIPELINE_STAGE_TRANSFER_BIT, 0, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                 VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
    imageBarrier(cmd, depthImage_, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                 VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT, VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                 VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT,
                 VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT);
    VkClearColorValue noTriangle{};
    noTriangle.uint32[0] = 0;
    beginRendering(cmd, triangleImage_, noTriangle, &depthImage_, 0.0f);
    const ShadowRasterPush push{v};
    rasterPipeline_.bind(cmd, set, &push, sizeof push);
    const ShadowView& view = views_[v];
    const bool outside =
        view.projection == ShadowView::Projection::Orthographic || eyeOutside(view.origin, mesh_.bounds());
    vkCmdSetCullMode(cmd, outside ? VK_CULL_MODE_BACK_BIT : VK_CULL_MODE_NONE);
    if (mesh_.triangleCount() > 0) vkCmdDraw(cmd, 3 * mesh_.triangleCount(), 1, 0, 0);
    vkCmdEndRendering(cmd);
    imageBarrier(cmd, triangleImage_, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                 VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
                 VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
    copyImageToBuffer(cmd, triangleImage_, rasterIds_, v * texelsPerView * sizeof(std::uint32_t));
  }
  if (!views_.empty()) {
    // The resolve reads the copied raster ids and writes the triangle each ray crosses.
    pipelineMemoryBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                          VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
    resolvePipeline_.bind(cmd, set);
    const std::uint32_t groups = (std::uint32_t(size_) + SSLPV_SHADOW_RESOLVE_GROUP - 1) / SSLPV_SHADOW_RESOLVE_GROUP;
    vkCmdDispatch(cmd, groups, groups, std::uint32_t(views_.size()));
  }
  pipelineMemoryBarrier(
      cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_HOST_BIT,
      VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_HOST_READ_BIT);
  if (timestamps) timestamps->write(cmd, firstQuery + 1);
}

double GpuShadowMapper::run() {
  VkCommandBuffer cmd = commands_.begin();
  timestamps_.reset(cmd);
  record(cmd, &timestamps_, 0);
  commands_.submitAndWait();
  return timestamps_.readMilliseconds(2)[1];
}

std::vector<GpuFluxSample> GpuShadowMapper::readSamples() const {
  std::vector<GpuFluxSample> samples(sampleCount_);
  readFromBuffer(device_, samples_, samples.data(), samples.size() * sizeof(GpuFluxSample));
  return samples;
}

std::vector<ShadowMapStats> GpuShadowMapper::stats(const std::vector<GpuFluxSample>& samples) const {
  if (samples.size() != sampleCount_)
    throw GpuError("GpuShadowMapper::stats: " + std::to_string(samples.size()) + " samples, the mapper wrote " +
                   std::to_string(sampleCount_));
  std::vector<ShadowMapStats> all;
  const std::size_t texelsPerView = std::size_t(size_) * size_;
  for (std::size_t l = 0; l < lights_.size(); ++l) {
    const Light& light = lightList_[l];
    const glm::vec3 power = light.type == Light::Type::Directional ? light.irradiance : light.intensity;
    ShadowMapStats stats;
    stats.culled = lights_[l].culled;
    for (std::uint32_t v = lights_[l].firstView; v < lights_[l].firstView + lights_[l].viewCount; ++v) {
      stats.texels += texelsPerView;
      for (std::size_t i = 0; i < texelsPerView; ++i) {
        const GpuFluxSample& s = samples[v * texelsPerView + i];
        if (s.positionValid.w == 0.0f) continue;
        ++stats.hits;
        const int x = int(i % std::size_t(size_)), y = int(i / std::size_t(size_));
        stats.incidentFlux += glm::dvec3(power * float(views_[v].texelRay(x, y).weight));
        stats.transmittedFlux += glm::dvec3(glm::vec3(s.flux));
      }
    }
    all.push_back(stats);
  }
  return all;
}

}  // namespace sslpv::gpu
