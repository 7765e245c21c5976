#pragma once
// Raster building blocks next to the compute ones of gpu/vk/compute.h: device-local 2D
// images with views, graphics pipelines for Vulkan 1.3 dynamic rendering, layout
// transitions, image/buffer copies, host uploads and readbacks, and the object's mesh
// on the device. The raster passes pull vertices from storage buffers (no vertex input
// state): a non-indexed draw of 3 vertices per triangle lets a shader know its triangle
// as gl_VertexIndex / 3 without the geometryShader feature gl_PrimitiveID would need.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

#include "gpu/vk/compute.h"
#include "gpu/vk/resources.h"
#include "shaders/spirv_library.h"
#include "volume/core/bounds.h"

namespace sslpv::gpu {

using ImageHandle = DeviceObject<VkImage, vkDestroyImage>;
using ImageViewHandle = DeviceObject<VkImageView, vkDestroyImageView>;

/// Throws GpuError unless `device` runs Vulkan 1.3 (dynamic rendering, which
/// VulkanDevice enables there).
void requireDynamicRendering(const VulkanDevice& device);

/// A device-local, optimally tiled 2D image with one mip level and layer, bound to its own
/// allocation, and a view of all of it. Colour formats get the colour aspect, depth
/// formats (D32_SFLOAT...) the depth aspect. Starts in VK_IMAGE_LAYOUT_UNDEFINED.
class Image2D {
 public:
  Image2D() = default;
  /// Throws GpuError when the device cannot use `format` for `usage` (optimal tiling).
  Image2D(const VulkanDevice& device, std::uint32_t width, std::uint32_t height, VkFormat format,
          VkImageUsageFlags usage);
  Image2D(Image2D&&) noexcept = default;
  Image2D& operator=(Image2D&& other) noexcept {
    view_ = std::move(other.view_);  // the view goes before the image, the image before its memory
    image_ = std::move(other.image_);
    memory_ = std::move(other.memory_);
    width_ = other.width_;
    height_ = other.height_;
    format_ = other.format_;
    aspect_ = other.aspect_;
    return *this;
  }

  VkImage handle() const { return image_.get(); }
  VkImageView view() const { return view_.get(); }
  VkFormat format() const { return format_; }
  VkImageAspectFlags aspect() const { return aspect_; }
  std::uint32_t width() const { return width_; }
  std::uint32_t height() const { return height_; }
  VkExtent2D extent() const { return {width_, height_}; }

 private:
  // Declared in reverse order of destruction: view, then image, then memory.
  MemoryHandle memory_;
  ImageHandle image_;
  ImageViewHandle view_;
  std::uint32_t width_ = 0, height_ = 0;
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  VkImageAspectFlags aspect_ = 0;
};

struct GraphicsPipelineDesc {
  spirv::SpirvCode vertex, fragment;
  VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;  ///< one set (required)
  std::uint32_t pushConstantBytes = 0;
  VkShaderStageFlags pushConstantStages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
  VkFormat colorFormat = VK_FORMAT_UNDEFINED;  ///< the one colour attachment; UNDEFINED: none
  VkFormat depthFormat = VK_FORMAT_UNDEFINED;  ///< UNDEFINED: no depth test
  /// Reversed depth by default (near maps to larger values, cleared to 0): float depth
  /// then keeps its precision far from the eye, and the near plane can be tiny.
  VkCompareOp depthCompare = VK_COMPARE_OP_GREATER;
  VkCullModeFlags cullMode = VK_CULL_MODE_NONE;
  VkFrontFace frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
  /// Cull mode set per draw with vkCmdSetCullMode (core in Vulkan 1.3) instead of cullMode.
  bool dynamicCullMode = false;
};

/// True when `eye` lies outside `bounds`, hence outside the closed mesh they bound: the
/// nearest surface along any ray from it then faces the eye, so culling back faces
/// changes no pixel and skips the hidden half of the triangles. From inside, the nearest
/// surface may face away (the CPU then sees it from inside), so nothing may be culled.
bool eyeOutside(const glm::dvec3& eye, const Bounds& bounds);

/// A triangle-list pipeline for dynamic rendering: vertex + fragment shaders from embedded
/// SPIR-V, no vertex input (shaders pull vertices from storage buffers), dynamic viewport
/// and scissor, no blending, one descriptor set, optional push constants.
class GraphicsPipeline {
 public:
  GraphicsPipeline() = default;
  GraphicsPipeline(const VulkanDevice& device, const GraphicsPipelineDesc& desc);

  VkPipeline pipeline() const { return pipeline_.get(); }
  VkPipelineLayout layout() const { return layout_.get(); }

  /// Binds the pipeline and `set`, and pushes `pushBytes` bytes of `push` (if any).
  void bind(VkCommandBuffer cmd, VkDescriptorSet set, const void* push = nullptr, std::uint32_t pushBytes = 0) const;

 private:
  ShaderModule vertexModule_, fragmentModule_;
  PipelineLayout layout_;
  Pipeline pipeline_;
  VkShaderStageFlags pushStages_ = 0;
};

/// A global memory barrier: `srcAccess` in `srcStages` of earlier commands are made
/// available and visible to `dstAccess` in `dstStages` of later ones.
void pipelineMemoryBarrier(VkCommandBuffer cmd, VkPipelineStageFlags srcStages, VkAccessFlags srcAccess,
                           VkPipelineStageFlags dstStages, VkAccessFlags dstAccess);

/// A layout transition of the whole of `image`, with the given execution and memory
/// dependency. oldLayout UNDEFINED discards the contents.
void imageBarrier(VkCommandBuffer cmd, const Image2D& image, VkImageLayout oldLayout, VkImageLayout newLayout,
                  VkPipelineStageFlags srcStages, VkAccessFlags srcAccess, VkPipelineStageFlags dstStages,
                  VkAccessFlags dstAccess);

/// Begins dynamic rendering over the whole of `color` (COLOR_ATTACHMENT_OPTIMAL) and,
/// unless null, `depth` (DEPTH_ATTACHMENT_OPTIMAL), both cleared; sets the viewport and
/// scissor to the full extent. Ends with vkCmdEndRendering.
void beginRendering(VkCommandBuffer cmd, const Image2D& color, const VkClearColorValue& clearColor,
                    const Image2D* depth, float clearDepth);

/// Copies all of `image` (in TRANSFER_SRC_OPTIMAL) to `buffer` at `offset`, tightly packed
/// rows, row 0 first.
void copyImageToBuffer(VkCommandBuffer cmd, const Image2D& image, const Buffer& buffer, VkDeviceSize offset = 0);
/// Copies tightly packed rows from `buffer` at `offset` into all of `image` (in
/// TRANSFER_DST_OPTIMAL).
void copyBufferToImage(VkCommandBuffer cmd, const Buffer& buffer, const Image2D& image, VkDeviceSize offset = 0);

/// Writes `bytes` of `data` into `target` at `offset`: through its mapping where it has
/// one, else through a staging buffer (submitted and waited for). The device must not be
/// using `target` meanwhile.
void uploadToBuffer(const VulkanDevice& device, const Buffer& target, const void* data, VkDeviceSize bytes,
                    VkDeviceSize offset = 0);
/// Reads `bytes` of `source` at `offset` into `data` (mapped, or staged). Earlier device
/// writes must be complete and made visible to the host (or to transfers, when staged).
void readFromBuffer(const VulkanDevice& device, const Buffer& source, void* data, VkDeviceSize bytes,
                    VkDeviceSize offset = 0);

}  // namespace sslpv::gpu
