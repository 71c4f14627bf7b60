// An app's depth submission (XR_KHR_composition_layer_depth) as real apps make it, for the layer
// tests of the depth scene: swapchains created through the loader (so through the layer), each
// frame's view distances turned into the stored values of a depth format and convention,
// uploaded on the app's Vulkan queue into the acquired image, and a projection layer whose views
// chain an XrCompositionLayerDepthInfoKHR. The app knows nothing of the layer.
//
// The app must be a Vulkan one (Graphics::vulkan or vulkan2) that enabled
// "XR_KHR_composition_layer_depth".
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "xr_harness.h"

namespace sdfg::test {

struct DepthSubmitOptions {
  // D16_UNORM, D24_UNORM_S8_UINT, D32_SFLOAT or D32_SFLOAT_S8_UINT
  VkFormat format = VK_FORMAT_D32_SFLOAT;
  uint32_t width = 256, height = 256;  // of each view's image
  // One swapchain with a slice per view (arraySize 2) instead of one swapchain per view.
  bool arraySwapchain = false;
  bool reversed = false;               // reversed depth: the info's nearZ > farZ (stored 1 at near)
  bool infiniteFar = false;            // the far plane at +infinity
  float nearZ = 0.05f, farZ = 100.0f;  // metres, the planes of the projection
  XrSwapchainUsageFlags usage =
      XR_SWAPCHAIN_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | XR_SWAPCHAIN_USAGE_TRANSFER_DST_BIT;
};

// The stored value (in [0, 1], before quantization) at view distance `distance` for a depth info
// with planes `infoNearZ` (stored 0) and `infoFarZ` (stored 1): 1 / distance is affine in the
// stored value, as a perspective projection makes it. +infinity for either plane or the distance
// is allowed; values beyond the planes are clamped.
float storedDepthValue(float distance, float infoNearZ, float infoFarZ);

class DepthSubmitter {
 public:
  // Creates the depth and colour swapchains and enumerates their images; ok() says whether all
  // of it worked, error() and result() why not.
  DepthSubmitter(App& app, DepthSubmitOptions options);
  // Destroys the swapchains and its own Vulkan objects: before the app's session and device go.
  ~DepthSubmitter();
  DepthSubmitter(const DepthSubmitter&) = delete;
  DepthSubmitter& operator=(const DepthSubmitter&) = delete;

  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }
  // The OpenXR result of the call that failed (XR_SUCCESS when none did, or when a Vulkan call
  // or a check of ours failed).
  XrResult result() const { return result_; }

  // Each view's metric view distances along -Z at each pixel centre, row 0 at the top, width *
  // height of them; +infinity where nothing is drawn.
  using Render =
      std::function<std::vector<float>(const XrView& view, uint32_t width, uint32_t height)>;
  // For App::frame's beforeEnd: locates the two views in app.local at app.lastTime, renders them
  // with `render`, uploads the stored values into the acquired depth image(s), releases them and
  // a colour image per view, and sets app.layers to one projection layer (space app.local)
  // whose views chain their depth info. False (error() says why) when any step failed.
  bool submit(const Render& render);
  uint64_t submitted() const { return submitted_; }

  // The structs of the last submit(), which app.layers points at: a test may break them between
  // submit() and the end of the frame (they are rebuilt by every submit()).
  XrCompositionLayerProjection& projection() { return projection_; }
  XrCompositionLayerDepthInfoKHR& depthInfo(uint32_t view) { return depthInfos_[view]; }
  const std::array<XrView, 2>& views() const { return views_; }

 private:
  struct Chain {
    XrSwapchain swapchain = XR_NULL_HANDLE;
    std::vector<VkImage> images;
  };
  bool fail(const std::string& what, XrResult r = XR_SUCCESS);
  bool createChain(int64_t format, XrSwapchainUsageFlags usage, uint32_t arraySize, Chain& out);
  bool createVulkanObjects();
  bool acquire(const Chain& chain, uint32_t& index);
  bool release(const Chain& chain);
  void writeStaging(const std::vector<float>& distances, uint32_t view);
  bool upload(const std::array<uint32_t, 2>& depthIndex,
              const std::array<uint32_t, 2>& colourIndex);

  App& app_;
  DepthSubmitOptions options_;
  std::string error_;
  XrResult result_ = XR_SUCCESS;
  uint64_t submitted_ = 0;
  std::vector<Chain> depth_, colour_;  // one per view, or one holding both slices

  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer commands_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  VkBuffer staging_ = VK_NULL_HANDLE;  // both views' depth, then a zeroed stencil plane
  VkDeviceMemory stagingMemory_ = VK_NULL_HANDLE;
  uint8_t* mapped_ = nullptr;
  VkDeviceSize depthBytes_ = 0;     // per view
  VkDeviceSize stencilOffset_ = 0;  // of the zeroed stencil bytes (combined formats)

  std::array<XrView, 2> views_{};
  std::array<XrCompositionLayerDepthInfoKHR, 2> depthInfos_{};
  std::array<XrCompositionLayerProjectionView, 2> projectionViews_{};
  XrCompositionLayerProjection projection_{XR_TYPE_COMPOSITION_LAYER_PROJECTION};
};

}  // namespace sdfg::test
