#include "gpu/vk/presenter.h"

#include <algorithm>
#include <cstring>
#include <limits>

namespace sslpv::gpu {

namespace {

/// Frames arrive as display-encoded bytes and are copied, never converted: a UNORM and an
/// SRGB swapchain both present those bytes as the display encoding they are.
VkSurfaceFormatKHR chooseFormat(VkPhysicalDevice physical, VkSurfaceKHR surface, bool* bgr) {
  std::uint32_t count = 0;
  SSLPV_VK_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(physical, surface, &count, nullptr));
  std::vector<VkSurfaceFormatKHR> formats(count);
  SSLPV_VK_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(physical, surface, &count, formats.data()));
  for (VkFormat wanted : {VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_B8G8R8A8_SRGB,
                          VK_FORMAT_R8G8B8A8_SRGB})
    for (const VkSurfaceFormatKHR& f : formats)
      if (f.format == wanted) {
        *bgr = wanted == VK_FORMAT_B8G8R8A8_UNORM || wanted == VK_FORMAT_B8G8R8A8_SRGB;
        return f;
      }
  throw GpuError("the window's surface offers no 8-bit RGBA or BGRA swapchain format");
}

void barrier(VkCommandBuffer commands, VkImage image, VkImageLayout from, VkImageLayout to, VkAccessFlags srcAccess,
             VkAccessFlags dstAccess, VkPipelineStageFlags srcStage, VkPipelineStageFlags dstStage) {
  VkImageMemoryBarrier b{};
  b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
  b.srcAccessMask = srcAccess;
  b.dstAccessMask = dstAccess;
  b.oldLayout = from;
  b.newLayout = to;
  b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = image;
  b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  vkCmdPipelineBarrier(commands, srcStage, dstStage, 0, 0, nullptr, 0, nullptr, 1, &b);
}

Semaphore makeSemaphore(VkDevice device) {
  VkSemaphoreCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO;
  VkSemaphore semaphore = VK_NULL_HANDLE;
  SSLPV_VK_CHECK(vkCreateSemaphore(device, &info, nullptr, &semaphore));
  return Semaphore(device, semaphore);
}

}  // namespace

SwapchainPresenter::SwapchainPresenter(const VulkanDevice& device, VkSurfaceKHR surface, int width, int height)
    : device_(device), surface_(surface) {
  try {
    VkBool32 supported = VK_FALSE;
    SSLPV_VK_CHECK(
        vkGetPhysicalDeviceSurfaceSupportKHR(device.physicalDevice(), device.queueFamily(), surface, &supported));
    if (!supported)
      throw GpuError("Vulkan device \"" + device.name() + "\" cannot present to this window from its queue");
    format_ = chooseFormat(device.physicalDevice(), surface, &bgr_);
    const VkDevice handle = device.handle();
    acquired_ = makeSemaphore(handle);
    VkCommandPoolCreateInfo poolInfo{};
    poolInfo.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    poolInfo.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    poolInfo.queueFamilyIndex = device.queueFamily();
    VkCommandPool pool = VK_NULL_HANDLE;
    SSLPV_VK_CHECK(vkCreateCommandPool(handle, &poolInfo, nullptr, &pool));
    pool_ = CommandPool(handle, pool);
    VkCommandBufferAllocateInfo alloc{};
    alloc.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    alloc.commandPool = pool;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    SSLPV_VK_CHECK(vkAllocateCommandBuffers(handle, &alloc, &commands_));
    VkFenceCreateInfo fenceInfo{};
    fenceInfo.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    fenceInfo.flags = VK_FENCE_CREATE_SIGNALED_BIT;  // the first present() has nothing to wait for
    VkFence fence = VK_NULL_HANDLE;
    SSLPV_VK_CHECK(vkCreateFence(handle, &fenceInfo, nullptr, &fence));
    done_ = Fence(handle, fence);
    createSwapchain(width, height);
  } catch (...) {
    destroySwapchain();
    vkDestroySurfaceKHR(device_.instance(), surface_, nullptr);
    throw;
  }
}

SwapchainPresenter::~SwapchainPresenter() {
  const VkFence fence = done_.get();
  if (fence) vkWaitForFences(device_.handle(), 1, &fence, VK_TRUE, std::numeric_limits<std::uint64_t>::max());
  destroySwapchain();
  vkDestroySurfaceKHR(device_.instance(), surface_, nullptr);
}

void SwapchainPresenter::destroySwapchain() {
  if (swapchain_ != VK_NULL_HANDLE) vkDestroySwapchainKHR(device_.handle(), swapchain_, nullptr);
  swapchain_ = VK_NULL_HANDLE;
  images_.clear();
}

void SwapchainPresenter::createSwapchain(int width, int height) {
  VkSurfaceCapabilitiesKHR caps{};
  SSLPV_VK_CHECK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(device_.physicalDevice(), surface_, &caps));
  if (!(caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT))
    throw GpuError("the window's swapchain images cannot be copied into (no TRANSFER_DST usage)");
  transferSrc_ = caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  // 0xFFFFFFFF: the surface takes the swapchain's size, which follows the window's.
  extent_ = caps.currentExtent;
  if (extent_.width == std::numeric_limits<std::uint32_t>::max()) {
    extent_.width = std::clamp(std::uint32_t(width), caps.minImageExtent.width, caps.maxImageExtent.width);
    extent_.height = std::clamp(std::uint32_t(height), caps.minImageExtent.height, caps.maxImageExtent.height);
  }
  std::uint32_t imageCount = caps.minImageCount + 1;
  if (caps.maxImageCount > 0) imageCount = std::min(imageCount, caps.maxImageCount);

  VkSwapchainCreateInfoKHR info{};
  info.sType = VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR;
  info.surface = surface_;
  info.minImageCount = imageCount;
  info.imageFormat = format_.format;
  info.imageColorSpace = format_.colorSpace;
  info.imageExtent = extent_;
  info.imageArrayLayers = 1;
  info.imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | (transferSrc_ ? VK_IMAGE_USAGE_TRANSFER_SRC_BIT : 0);
  info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
  info.preTransform = caps.currentTransform;
  info.compositeAlpha = (caps.supportedCompositeAlpha & VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR)
                            ? VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR
                            : VkCompositeAlphaFlagBitsKHR(caps.supportedCompositeAlpha & -caps.supportedCompositeAlpha);
  info.presentMode = VK_PRESENT_MODE_FIFO_KHR;  // the one mode every surface supports
  info.clipped = VK_TRUE;
  info.oldSwapchain = swapchain_;
  requestedWidth_ = width;
  requestedHeight_ = height;
  stale_ = false;
  VkSwapchainKHR created = VK_NULL_HANDLE;
  SSLPV_VK_CHECK(vkCreateSwapchainKHR(device_.handle(), &info, nullptr, &created));
  destroySwapchain();
  swapchain_ = created;

  std::uint32_t count = 0;
  SSLPV_VK_CHECK(vkGetSwapchainImagesKHR(device_.handle(), swapchain_, &count, nullptr));
  images_.resize(count);
  SSLPV_VK_CHECK(vkGetSwapchainImagesKHR(device_.handle(), swapchain_, &count, images_.data()));
  // Kept across rebuilds, only added to: a semaphore may still be waited on by the last
  // present to the old swapchain.
  while (presentReady_.size() < count) presentReady_.push_back(makeSemaphore(device_.handle()));
}

bool SwapchainPresenter::present(const DisplayFrame& frame, int width, int height, DisplayFrame* readback) {
  if (width <= 0 || height <= 0) return false;
  const VkDevice handle = device_.handle();
  const VkFence fence = done_.get();
  // One frame in flight: the command buffer, staging buffer and acquire semaphore are reused.
  SSLPV_VK_CHECK(vkWaitForFences(handle, 1, &fence, VK_TRUE, std::numeric_limits<std::uint64_t>::max()));
  if (stale_ || width != requestedWidth_ || height != requestedHeight_) createSwapchain(width, height);
  if (extent_.width == 0 || extent_.height == 0) return false;

  std::uint32_t index = 0;
  VkResult acquired = vkAcquireNextImageKHR(handle, swapchain_, std::numeric_limits<std::uint64_t>::max(),
                                            acquired_.get(), VK_NULL_HANDLE, &index);
  if (acquired == VK_ERROR_OUT_OF_DATE_KHR) {
    createSwapchain(width, height);
    acquired = vkAcquireNextImageKHR(handle, swapchain_, std::numeric_limits<std::uint64_t>::max(), acquired_.get(),
                                     VK_NULL_HANDLE, &index);
  }
  if (acquired == VK_ERROR_OUT_OF_DATE_KHR) return false;
  if (acquired != VK_SUBOPTIMAL_KHR) SSLPV_VK_CHECK(acquired);

  // Staging in the swapchain's byte order, so the copy is a plain buffer-to-image copy.
  const int copyW = std::min(frame.width, int(extent_.width));
  const int copyH = std::min(frame.height, int(extent_.height));
  const VkDeviceSize bytes = VkDeviceSize(std::max(copyW, 1)) * std::max(copyH, 1) * 4;
  if (!staging_ || staging_->size() < bytes)
    staging_ = std::make_unique<Buffer>(device_, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryUse::Host);
  const bool readSwapchain = readback && transferSrc_;
  if (readSwapchain && (!readback_ || readback_->size() < bytes))
    readback_ = std::make_unique<Buffer>(device_, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUse::Host);
  auto* out = staging_->mappedAs<unsigned char>();
  for (int y = 0; y < copyH; ++y)
    for (int x = 0; x < copyW; ++x) {
      const unsigned char* p = &frame.rgb[(std::size_t(y) * frame.width + x) * 3];
      unsigned char* q = out + (std::size_t(y) * copyW + x) * 4;
      q[0] = bgr_ ? p[2] : p[0];
      q[1] = p[1];
      q[2] = bgr_ ? p[0] : p[2];
      q[3] = 255;
    }

  const VkImage image = images_[index];
  SSLPV_VK_CHECK(vkResetCommandBuffer(commands_, 0));
  VkCommandBufferBeginInfo begin{};
  begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  SSLPV_VK_CHECK(vkBeginCommandBuffer(commands_, &begin));
  barrier(commands_, image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0,
          VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
  const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  const VkImageSubresourceLayers layers{VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  if (copyW < int(extent_.width) || copyH < int(extent_.height)) {
    const VkClearColorValue black{{0.0f, 0.0f, 0.0f, 1.0f}};
    vkCmdClearColorImage(commands_, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &black, 1, &range);
    barrier(commands_, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
            VK_ACCESS_TRANSFER_WRITE_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
            VK_PIPELINE_STAGE_TRANSFER_BIT);
  }
  VkBufferImageCopy region{};
  region.imageSubresource = layers;
  region.imageExtent = {std::uint32_t(std::max(copyW, 0)), std::uint32_t(std::max(copyH, 0)), 1};
  if (copyW > 0 && copyH > 0)
    vkCmdCopyBufferToImage(commands_, staging_->handle(), image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
  VkImageLayout layout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  VkAccessFlags access = VK_ACCESS_TRANSFER_WRITE_BIT;
  if (readSwapchain && copyW > 0 && copyH > 0) {
    barrier(commands_, image, layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, access, VK_ACCESS_TRANSFER_READ_BIT,
            VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
    vkCmdCopyImageToBuffer(commands_, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback_->handle(), 1, &region);
    layout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    access = VK_ACCESS_TRANSFER_READ_BIT;
  }
  barrier(commands_, image, layout, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, access, 0, VK_PIPELINE_STAGE_TRANSFER_BIT,
          VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT);
  SSLPV_VK_CHECK(vkEndCommandBuffer(commands_));

  const VkSemaphore wait = acquired_.get();
  const VkSemaphore signal = presentReady_[index].get();
  const VkPipelineStageFlags waitStage = VK_PIPELINE_STAGE_TRANSFER_BIT;
  VkSubmitInfo submit{};
  submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  submit.waitSemaphoreCount = 1;
  submit.pWaitSemaphores = &wait;
  submit.pWaitDstStageMask = &waitStage;
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &commands_;
  submit.signalSemaphoreCount = 1;
  submit.pSignalSemaphores = &signal;
  SSLPV_VK_CHECK(vkResetFences(handle, 1, &fence));
  device_.submit(submit, fence);

  VkPresentInfoKHR info{};
  info.sType = VK_STRUCTURE_TYPE_PRESENT_INFO_KHR;
  info.waitSemaphoreCount = 1;
  info.pWaitSemaphores = &signal;
  info.swapchainCount = 1;
  info.pSwapchains = &swapchain_;
  info.pImageIndices = &index;
  const VkResult presented = device_.present(info);
  if (presented == VK_ERROR_OUT_OF_DATE_KHR || presented == VK_SUBOPTIMAL_KHR) {
    stale_ = true;  // rebuilt at the next present()
  } else {
    SSLPV_VK_CHECK(presented);
  }

  if (readback) {
    readback->width = copyW;
    readback->height = copyH;
    readback->rgb.assign(std::size_t(std::max(copyW, 0)) * std::max(copyH, 0) * 3, 0);
    if (readSwapchain) {
      SSLPV_VK_CHECK(vkWaitForFences(handle, 1, &fence, VK_TRUE, std::numeric_limits<std::uint64_t>::max()));
      const auto* in = readback_->mappedAs<const unsigned char>();
      for (std::size_t i = 0; i < std::size_t(copyW) * copyH; ++i) {
        readback->rgb[i * 3 + 0] = in[i * 4 + (bgr_ ? 2 : 0)];
        readback->rgb[i * 3 + 1] = in[i * 4 + 1];
        readback->rgb[i * 3 + 2] = in[i * 4 + (bgr_ ? 0 : 2)];
      }
    } else {
      for (int y = 0; y < copyH; ++y)
        std::memcpy(&readback->rgb[std::size_t(y) * copyW * 3], &frame.rgb[std::size_t(y) * frame.width * 3],
                    std::size_t(copyW) * 3);
    }
  }
  return true;
}

}  // namespace sslpv::gpu
