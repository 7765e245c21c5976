#pragma once
// Shows finished frames in a window: a swapchain on a window's VkSurfaceKHR, each frame
// copied from host memory into the next swapchain image (staging buffer, buffer-to-image
// copy), so both backends' host images present the same way. Window-system agnostic: the
// caller creates the surface (GLFW, ...) on the device's instance.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "gpu/vk/device.h"
#include "gpu/vk/resources.h"

namespace sslpv::gpu {

/// Pixels in the layout toDisplayRgb8 produces (RGB, 8 bits, display-encoded, row 0 at
/// the top): what a window shows.
struct DisplayFrame {
  int width = 0;
  int height = 0;
  std::vector<unsigned char> rgb;
};

class SwapchainPresenter {
 public:
  /// Takes ownership of `surface` (destroyed with the presenter). `device` must have been
  /// created with DeviceOptions::swapchain and the window system's instance extensions,
  /// and must outlive the presenter. GpuError when the device's queue cannot present to
  /// the surface or no usable swapchain format exists.
  SwapchainPresenter(const VulkanDevice& device, VkSurfaceKHR surface, int width, int height);
  ~SwapchainPresenter();
  SwapchainPresenter(const SwapchainPresenter&) = delete;
  SwapchainPresenter& operator=(const SwapchainPresenter&) = delete;

  /// Copies `frame` into the next swapchain image (its top-left corner; the rest cleared
  /// to black) and presents it. `width` x `height` is the window's framebuffer size now:
  /// the swapchain is rebuilt when it changed or went out of date. `readback`, when not
  /// null, receives what the swapchain image held as presented (RGB, the frame's size
  /// clipped to the swapchain) where the surface allows reading its images back, else the
  /// frame itself. Returns false when nothing could be presented (a minimized window).
  bool present(const DisplayFrame& frame, int width, int height, DisplayFrame* readback = nullptr);

  /// The swapchain images can be copied from (what present() reads back).
  bool readsBackSwapchain() const { return transferSrc_; }

 private:
  void createSwapchain(int width, int height);
  void destroySwapchain();

  const VulkanDevice& device_;
  VkSurfaceKHR surface_ = VK_NULL_HANDLE;
  VkSurfaceFormatKHR format_{};
  bool bgr_ = false;          ///< the swapchain's bytes are B, G, R, A
  bool transferSrc_ = false;  ///< swapchain images allow TRANSFER_SRC
  VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
  VkExtent2D extent_{};
  int requestedWidth_ = 0, requestedHeight_ = 0;  ///< the window size the swapchain was made for
  bool stale_ = false;                             ///< out of date or suboptimal: rebuild before the next frame
  std::vector<VkImage> images_;
  std::vector<Semaphore> presentReady_;  ///< per image: its copy finished, present may start
  Semaphore acquired_;
  CommandPool pool_;
  VkCommandBuffer commands_ = VK_NULL_HANDLE;
  Fence done_;
  std::unique_ptr<Buffer> staging_;
  std::unique_ptr<Buffer> readback_;
};

}  // namespace sslpv::gpu
