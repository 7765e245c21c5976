#include "gpu/vk/graphics.h"

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <string>

namespace sslpv::gpu {
namespace {

bool isDepthFormat(VkFormat format) {
  switch (format) {
    case VK_FORMAT_D16_UNORM:
    case VK_FORMAT_X8_D24_UNORM_PACK32:
    case VK_FORMAT_D32_SFLOAT:
      return true;
    default:
      return false;
  }
}

VkFormatFeatureFlags featuresFor(VkImageUsageFlags usage) {
  VkFormatFeatureFlags features = 0;
  if (usage & VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT) features |= VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT;
  if (usage & VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT) features |= VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT;
  if (usage & VK_IMAGE_USAGE_STORAGE_BIT) features |= VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT;
  if (usage & VK_IMAGE_USAGE_SAMPLED_BIT) features |= VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT;
  if (usage & VK_IMAGE_USAGE_TRANSFER_SRC_BIT) features |= VK_FORMAT_FEATURE_TRANSFER_SRC_BIT;
  if (usage & VK_IMAGE_USAGE_TRANSFER_DST_BIT) features |= VK_FORMAT_FEATURE_TRANSFER_DST_BIT;
  return features;
}

ShaderModule makeShaderModule(VkDevice device, const spirv::SpirvCode& code) {
  VkShaderModuleCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
  info.codeSize = code.byteSize();
  info.pCode = code.words;
  VkShaderModule module = VK_NULL_HANDLE;
  SSLPV_VK_CHECK(vkCreateShaderModule(device, &info, nullptr, &module));
  return ShaderModule(device, module);
}

constexpr VkBufferUsageFlags kTransfer = VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;

VkBufferImageCopy wholeImage(const Image2D& image, VkDeviceSize offset) {
  VkBufferImageCopy region{};
  region.bufferOffset = offset;
  region.imageSubresource = {image.aspect(), 0, 0, 1};
  region.imageExtent = {image.width(), image.height(), 1};
  return region;
}

}  // namespace

void requireDynamicRendering(const VulkanDevice& device) {
  if (device.properties().apiVersion < VK_API_VERSION_1_3)
    throw GpuError("the raster passes need Vulkan 1.3 (dynamic rendering); the Vulkan device \"" + device.name() +
                   "\" offers " + std::to_string(VK_API_VERSION_MAJOR(device.properties().apiVersion)) + "." +
                   std::to_string(VK_API_VERSION_MINOR(device.properties().apiVersion)));
}

Image2D::Image2D(const VulkanDevice& device, std::uint32_t width, std::uint32_t height, VkFormat format,
                 VkImageUsageFlags usage)
    : width_(width), height_(height), format_(format) {
  const VkDevice vk = device.handle();
  const VkPhysicalDeviceLimits& limits = device.properties().limits;
  if (width == 0 || height == 0 || width > limits.maxImageDimension2D || height > limits.maxImageDimension2D)
    throw GpuError("Image2D: " + std::to_string(width) + "x" + std::to_string(height) +
                   " is outside the device's 2D image limits (1 to " + std::to_string(limits.maxImageDimension2D) +
                   ")");
  VkFormatProperties properties;
  vkGetPhysicalDeviceFormatProperties(device.physicalDevice(), format, &properties);
  const VkFormatFeatureFlags needed = featuresFor(usage);
  if ((properties.optimalTilingFeatures & needed) != needed)
    throw GpuError("Image2D: the Vulkan device \"" + device.name() + "\" cannot use format " +
                   std::to_string(int(format)) + " for image usage " + std::to_string(usage));
  aspect_ = isDepthFormat(format) ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;

  VkImageCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
  info.imageType = VK_IMAGE_TYPE_2D;
  info.format = format;
  info.extent = {width, height, 1};
  info.mipLevels = 1;
  info.arrayLayers = 1;
  info.samples = VK_SAMPLE_COUNT_1_BIT;
  info.tiling = VK_IMAGE_TILING_OPTIMAL;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkImage image = VK_NULL_HANDLE;
  SSLPV_VK_CHECK(vkCreateImage(vk, &info, nullptr, &image));
  image_ = ImageHandle(vk, image);

  VkMemoryRequirements requirements;
  vkGetImageMemoryRequirements(vk, image, &requirements);
  VkMemoryAllocateInfo allocate{};
  allocate.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  allocate.allocationSize = requirements.size;
  allocate.memoryTypeIndex =
      findMemoryType(device.memoryProperties(), requirements.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0);
  VkDeviceMemory memory = VK_NULL_HANDLE;
  SSLPV_VK_CHECK(vkAllocateMemory(vk, &allocate, nullptr, &memory));
  memory_ = MemoryHandle(vk, memory);
  SSLPV_VK_CHECK(vkBindImageMemory(vk, image, memory, 0));

  VkImageViewCreateInfo viewInfo{};
  viewInfo.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
  viewInfo.image = image;
  viewInfo.viewType = VK_IMAGE_VIEW_TYPE_2D;
  viewInfo.format = format;
  viewInfo.subresourceRange = {aspect_, 0, 1, 0, 1};
  VkImageView view = VK_NULL_HANDLE;
  SSLPV_VK_CHECK(vkCreateImageView(vk, &viewInfo, nullptr, &view));
  view_ = ImageViewHandle(vk, view);
}

GraphicsPipeline::GraphicsPipeline(const VulkanDevice& device, const GraphicsPipelineDesc& desc)
    : pushStages_(desc.pushConstantStages) {
  requireDynamicRendering(device);
  const VkDevice vk = device.handle();
  vertexModule_ = makeShaderModule(vk, desc.vertex);
  fragmentModule_ = makeShaderModule(vk, desc.fragment);

  const VkPushConstantRange range{desc.pushConstantStages, 0, desc.pushConstantBytes};
  VkPipelineLayoutCreateInfo layoutInfo{};
  layoutInfo.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  layoutInfo.setLayoutCount = 1;
  layoutInfo.pSetLayouts = &desc.setLayout;
  layoutInfo.pushConstantRangeCount = desc.pushConstantBytes > 0 ? 1 : 0;
  layoutInfo.pPushConstantRanges = &range;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  SSLPV_VK_CHECK(vkCreatePipelineLayout(vk, &layoutInfo, nullptr, &layout));
  layout_ = PipelineLayout(vk, layout);

  VkPipelineShaderStageCreateInfo stages[2]{};
  for (int i = 0; i < 2; ++i) {
    stages[i].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    stages[i].pName = "main";
  }
  stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
  stages[0].module = vertexModule_.get();
  stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
  stages[1].module = fragmentModule_.get();

  VkPipelineVertexInputStateCreateInfo vertexInput{};
  vertexInput.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO;
  VkPipelineInputAssemblyStateCreateInfo assembly{};
  assembly.sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO;
  assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  VkPipelineViewportStateCreateInfo viewport{};
  viewport.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO;
  viewport.viewportCount = 1;
  viewport.scissorCount = 1;
  VkPipelineRasterizationStateCreateInfo raster{};
  raster.sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO;
  raster.polygonMode = VK_POLYGON_MODE_FILL;
  raster.cullMode = desc.cullMode;
  raster.frontFace = desc.frontFace;
  raster.lineWidth = 1.0f;
  VkPipelineMultisampleStateCreateInfo multisample{};
  multisample.sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO;
  multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  VkPipelineDepthStencilStateCreateInfo depth{};
  depth.sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO;
  depth.depthTestEnable = desc.depthFormat != VK_FORMAT_UNDEFINED;
  depth.depthWriteEnable = desc.depthFormat != VK_FORMAT_UNDEFINED;
  depth.depthCompareOp = desc.depthCompare;
  VkPipelineColorBlendAttachmentState blendAttachment{};
  blendAttachment.colorWriteMask =
      VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
  const bool hasColor = desc.colorFormat != VK_FORMAT_UNDEFINED;
  VkPipelineColorBlendStateCreateInfo blend{};
  blend.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO;
  blend.attachmentCount = hasColor ? 1 : 0;
  blend.pAttachments = &blendAttachment;
  const VkDynamicState dynamicStates[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR,
                                          VK_DYNAMIC_STATE_CULL_MODE};
  VkPipelineDynamicStateCreateInfo dynamic{};
  dynamic.sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO;
  dynamic.dynamicStateCount = desc.dynamicCullMode ? 3 : 2;
  dynamic.pDynamicStates = dynamicStates;

  VkPipelineRenderingCreateInfo rendering{};
  rendering.sType = VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO;
  rendering.colorAttachmentCount = hasColor ? 1 : 0;
  rendering.pColorAttachmentFormats = &desc.colorFormat;
  rendering.depthAttachmentFormat = desc.depthFormat;

  VkGraphicsPipelineCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO;
  info.pNext = &rendering;
  info.stageCount = 2;
  info.pStages = stages;
  info.pVertexInputState = &vertexInput;
  info.pInputAssemblyState = &assembly;
  info.pViewportState = &viewport;
  info.pRasterizationState = &raster;
  info.pMultisampleState = &multisample;
  info.pDepthStencilState = &depth;
  info.pColorBlendState = &blend;
  info.pDynamicState = &dynamic;
  info.layout = layout;
  VkPipeline pipeline = VK_NULL_HANDLE;
  SSLPV_VK_CHECK(vkCreateGraphicsPipelines(vk, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline));
  pipeline_ = Pipeline(vk, pipeline);
}

void GraphicsPipeline::bind(VkCommandBuffer cmd, VkDescriptorSet set, const void* push, std::uint32_t pushBytes) const {
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline_.get());
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, layout_.get(), 0, 1, &set, 0, nullptr);
  if (pushBytes > 0) vkCmdPushConstants(cmd, layout_.get(), pushStages_, 0, pushBytes, push);
}

bool eyeOutside(const glm::dvec3& eye, const Bounds& bounds) {
  for (int a = 0; a < 3; ++a)
    if (eye[a] < bounds.min[a] || eye[a] > bounds.max[a]) return true;
  return false;
}

void pipelineMemoryBarrier(VkCommandBuffer cmd, VkPipelineStageFlags srcStages, VkAccessFlags srcAccess,
                           VkPipelineStageFlags dstStages, VkAccessFlags dstAccess) {
  VkMemoryBarrier barrier{};
  barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  barrier.srcAccessMask = srcAccess;
  barrier.dstAccessMask = dstAccess;
  vkCmdPipelineBarrier(cmd, srcStages, dstStages, 0, 1, &barrier, 0, nullptr, 0, nullptr);
}

void imageBarrier(VkCommandBuffer cmd, const Image2D& image, VkImageLayout oldLayout, VkImageLayout newLayout,
                  VkPipelineStageFlags srcStages, VkAccessFlags srcAccess, VkPipelineStageFlags dstStages,
                  VkAccessFlags dstAccess) {
  VkImageMemoryBarrier barrier{};
  barrier.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
  barrier.srcAccessMask = srcAccess;
  barrier.dstAccessMask = dstAccess;
  barrier.oldLayout = oldLayout;
  barrier.newLayout = newLayout;
  barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.image = image.handle();
  barrier.subresourceRange = {image.aspect(), 0, 1, 0, 1};
  vkCmdPipelineBarrier(cmd, srcStages, dstStages, 0, 0, nullptr, 0, nullptr, 1, &barrier);
}

void beginRendering(VkCommandBuffer cmd, const Image2D& color, const VkClearColorValue& clearColor,
                    const Image2D* depth, float clearDepth) {
  VkRenderingAttachmentInfo colorAttachment{};
  colorAttachment.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO;
  colorAttachment.imageView = color.view();
  colorAttachment.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  colorAttachment.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  colorAttachment.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  colorAttachment.clearValue.color = clearColor;
  VkRenderingAttachmentInfo depthAttachment{};
  depthAttachment.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO;
  if (depth) {
    depthAttachment.imageView = depth->view();
    depthAttachment.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
    depthAttachment.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    // Only the pass itself tests against depth.
    depthAttachment.storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    depthAttachment.clearValue.depthStencil = {clearDepth, 0};
  }
  VkRenderingInfo info{};
  info.sType = VK_STRUCTURE_TYPE_RENDERING_INFO;
  info.renderArea = {{0, 0}, color.extent()};
  info.layerCount = 1;
  info.colorAttachmentCount = 1;
  info.pColorAttachments = &colorAttachment;
  info.pDepthAttachment = depth ? &depthAttachment : nullptr;
  vkCmdBeginRendering(cmd, &info);

  const VkViewport viewport{0.0f, 0.0f, float(color.width()), float(color.height()), 0.0f, 1.0f};
  const VkRect2D scissor{{0, 0}, color.extent()};
  vkCmdSetViewport(cmd, 0, 1, &viewport);
  vkCmdSetScissor(cmd, 0, 1, &scissor);
}

void copyImageToBuffer(VkCommandBuffer cmd, const Image2D& image, const Buffer& buffer, VkDeviceSize offset) {
  const VkBufferImageCopy region = wholeImage(image, offset);
  vkCmdCopyImageToBuffer(cmd, image.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer.handle(), 1, &region);
}

void copyBufferToImage(VkCommandBuffer cmd, const Buffer& buffer, const Image2D& image, VkDeviceSize offset) {
  const VkBufferImageCopy region = wholeImage(image, offset);
  vkCmdCopyBufferToImage(cmd, buffer.handle(), image.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
}

void uploadToBuffer(const VulkanDevice& device, const Buffer& target, const void* data, VkDeviceSize bytes,
                    VkDeviceSize offset) {
  if (offset + bytes > target.size())
    throw GpuError("uploadToBuffer: " + std::to_string(bytes) + " bytes at offset " + std::to_string(offset) +
                   " overrun a buffer of " + std::to_string(target.size()));
  if (bytes == 0) return;
  if (target.mapped()) {
    std::memcpy(static_cast<char*>(target.mapped()) + offset, data, bytes);
    return;
  }
  Buffer staging(device, bytes, kTransfer, MemoryUse::Host);
  std::memcpy(staging.mapped(), data, bytes);
  CommandContext commands(device);
  VkCommandBuffer cmd = commands.begin();
  const VkBufferCopy region{0, offset, bytes};
  vkCmdCopyBuffer(cmd, staging.handle(), target.handle(), 1, &region);
  commands.submitAndWait();
}

void readFromBuffer(const VulkanDevice& device, const Buffer& source, void* data, VkDeviceSize bytes,
                    VkDeviceSize offset) {
  if (offset + bytes > source.size())
    throw GpuError("readFromBuffer: " + std::to_string(bytes) + " bytes at offset " + std::to_string(offset) +
                   " overrun a buffer of " + std::to_string(source.size()));
  if (bytes == 0) return;
  if (source.mapped()) {
    std::memcpy(data, static_cast<const char*>(source.mapped()) + offset, bytes);
    return;
  }
  Buffer staging(device, bytes, kTransfer, MemoryUse::Host);
  CommandContext commands(device);
  VkCommandBuffer cmd = commands.begin();
  const VkBufferCopy region{offset, 0, bytes};
  vkCmdCopyBuffer(cmd, source.handle(), staging.handle(), 1, &region);
  toHostBarrier(cmd);
  commands.submitAndWait();
  std::memcpy(data, staging.mapped(), bytes);
}

}  // namespace sslpv::gpu
