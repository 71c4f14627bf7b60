// An app's depth images brought to the CPU for the depth scene (depth/depth_fusion.h): each copy,
// of the rects the caller needs (the pixels that see a hand's box, not the whole image), is
// recorded and submitted on the app's queue right after the app's rendering and before the runtime
// takes the image, into a host-visible buffer of the layer's own, and read once its fence signals,
// a frame or more later. Nothing here waits for the GPU, except teardown (wait()).
//
// What an app guarantees at xrReleaseSwapchainImage (XR_KHR_vulkan_enable): the depth image is
// in VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL and its rendering was submitted on the
// binding's queue. The copy moves it to TRANSFER_SRC_OPTIMAL and back, so the runtime's work
// after it sees the layout it expects; the image needs the transfer-source usage, which the layer
// adds when the swapchain is created.
//
// A few copies may be in flight (kSlots); a submit that finds none free is refused and the frame
// goes without depth. The queue is the borrowed device's, externally synchronized: submit() only
// where the caller may use it. Not thread-safe: one caller at a time.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <vulkan/vulkan_core.h>

#include "base/status.h"
#include "vulkan/vk_context.h"

namespace sdfg {

// One image of an app's depth swapchain.
struct VkDepthImage {
  VkImage image = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_UNDEFINED;
  uint32_t width = 0, height = 0;
  uint32_t layers = 1;  // array layers (a slice per view in an array swapchain)
};

// A rect of one layer of a finished copy, in pixels of the image.
struct VkDepthRect {
  uint32_t layer = 0;
  int32_t x = 0, y = 0;
  uint32_t width = 0, height = 0;
};

class VkDepthCapture {
 public:
  static constexpr int kSlots = 4;

  // Errors: those of VkContext::create, or of the command objects' creation.
  static Result<std::unique_ptr<VkDepthCapture>> create(
      const VulkanDevice& device, std::function<void(const std::string&)> log = {});
  ~VkDepthCapture();  // waits for the copies in flight (at most 2 s) before freeing anything
  VkDepthCapture(const VkDepthCapture&) = delete;
  VkDepthCapture& operator=(const VkDepthCapture&) = delete;

  // Whether copies of `format`'s depth aspect can be read: D16, X8_D24, D24S8, D32, D32S8.
  static bool readableFormat(VkFormat format);

  // Records and submits the copy of `regions` of `image` (rects of its layers, inside the image;
  // a layer may appear more than once), packed into one buffer; returns its ticket (> 0) at once.
  // Errors: invalid_argument (a format readableFormat() refuses, an empty image, no region, a
  // region empty or outside the image), unsupported (every slot busy: the copies before it are not
  // finished or not yet taken), device_lost / out_of_memory / internal (the capture is unusable
  // from then on, having logged one line).
  Result<uint64_t> submit(const VkDepthImage& image, std::span<const VkDepthRect> regions);
  // Non-blocking: whether the copy `ticket` has finished (false also for an unknown ticket).
  bool finished(uint64_t ticket);
  // The stored values of `rect` of a finished copy, in [0, 1], row by row from the rect's top,
  // read every `step` pixels from `step / 2` (step 1: every pixel); the output is
  // ceil(width / step) x ceil(height / step). Empty when the ticket is not finished or the rect is
  // not inside one region the copy was made of.
  std::vector<float> read(uint64_t ticket, const VkDepthRect& rect, uint32_t step) const;
  // Whether `ticket` is a copy in flight or finished and not freed.
  bool holds(uint64_t ticket) const { return slotOf(ticket) != nullptr; }
  // The copy's slot is free again (at once when finished, else once its fence signals).
  void discard(uint64_t ticket);
  // Copies in flight or finished and not discarded.
  int held() const;
  // Waits up to `timeoutNs` for the copies of `image` in flight, then discards every copy of it
  // (the app is about to destroy it). True when none is left in flight.
  bool forget(VkImage image, uint64_t timeoutNs);
  bool failed() const { return failed_; }

 private:
  struct Slot;
  VkDepthCapture();
  Error fail(VkResult result, const char* what);
  Slot* slotOf(uint64_t ticket) const;
  void retire();  // frees discarded slots whose fences have signalled

  std::unique_ptr<VkContext> ctx_;  // first: destroyed last
  std::array<std::unique_ptr<Slot>, kSlots> slots_;
  VkOwned<VkCommandPool> pool_;
  std::function<void(const std::string&)> log_;
  uint64_t nextTicket_ = 1;
  bool failed_ = false;
};

}  // namespace sdfg
