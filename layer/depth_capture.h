// The depth scene's capture (docs/depth.md): what a Vulkan app submits with
// XR_KHR_composition_layer_depth, brought to the session's grasp engine as DepthViews and stored
// values, for apps that never heard of the layer.
//
// - xrCreateSwapchain: a depth swapchain (a depth format, depth-stencil usage, one sample) gets
//   the transfer-source usage added; where the runtime refuses it, the swapchain is created
//   exactly as the app asked and the log says once that its depth is not read.
// - xrEnumerateSwapchainImages / xrAcquireSwapchainImage: the images and which one is acquired.
// - xrReleaseSwapchainImage: before the call goes down (the image is still the app's, in the
//   depth-attachment layout, and the queue is the runtime's to use during the call), one copy on
//   the app's queue (vulkan/vk_depth_capture.h) of the pixels that can see a hand's fusion box, as
//   the view last submitted from each layer saw them (grown for the motion of a frame), or of the
//   whole layer before any view; nothing when no hand is known or none is in sight. Nothing
//   waits for it.
// - xrEndFrame: each projection view's depth info names a released image; with the view's pose
//   (its layer's space located in the layer's LOCAL space at the display time), field of view,
//   rect and depth range it becomes a DepthView. Copies a frame or more old that have finished are
//   read and handed to GraspSession::submitDepth.
// Bad depth info is skipped for the frame with one log line a session; the app's calls go down as
// the app made them (only the added usage differs), and their results come back unchanged.
//
// Locks: a swapchain's and a session's depth bookkeeping under their own mutexes, never held
// across a call; the device copy object is claimed without waiting (a frame call that finds it in
// use on another thread skips its copy) and waited for only by teardown.
#pragma once

#include <atomic>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

#include "depth/depth_view.h"
#include "xr_includes.h"

#if SDFG_LAYER_VULKAN
#include "vulkan/vk_depth_capture.h"
#endif

namespace sdfg::layer {

struct SessionState;

// A swapchain the app created on a session, as the capture tracks it (every swapchain, so the
// layer can pass its calls down; only depth ones are copied).
struct SwapchainState {
  uint64_t handle = 0;
  std::weak_ptr<SessionState> session;
  bool depth = false;  // a depth swapchain the layer can copy (usage added or the app's own)
  int64_t format = 0;  // the VkFormat
  uint32_t width = 0, height = 0, layers = 1;
  std::mutex mutex;  // guards the fields below; never held across a call
  std::vector<VkImage> images;
  std::deque<uint32_t> acquired;  // acquired and not released, oldest first
  uint64_t lastCopy = 0;  // ticket of the copy of the image released last, not yet framed (0: none)
#if SDFG_LAYER_VULKAN
  std::vector<VkDepthRect> lastRegions;  // what that copy holds
#endif
  // Per layer: the view last submitted from it (world, the whole rect) and the rect's offset in
  // the image, which place the next copy.
  struct SeenView {
    DepthView view;
    int32_t x = 0, y = 0;
  };
  std::vector<std::optional<SeenView>> seen;
};

// What the layer reads of one frame's depth, waiting for its copies.
struct DepthFrame {
  std::vector<DepthView> views;
  std::vector<uint64_t> copies;  // per view: the copy ticket
#if SDFG_LAYER_VULKAN
  std::vector<VkDepthRect> rects;  // per view: the rect and layer in that copy
#endif
  std::vector<uint32_t> steps;  // per view: read every step-th pixel
  double time = 0.0;
};

// A session's depth capture (SessionState::depth): made for Vulkan sessions whose app may submit
// depth and whose config allows it.
struct SessionDepth {
  // The device copy object, claimed by one thread at a time (tryClaim); made at the first copy.
  std::atomic<bool> busy{false};
#if SDFG_LAYER_VULKAN
  std::unique_ptr<VkDepthCapture> gpu;
#endif
  bool gpuTried = false;  // made or failed once (guarded by the claim)

  std::mutex mutex;               // guards the fields below; never held across a call
  std::deque<DepthFrame> frames;  // oldest first, at most kMaxFramesWaiting
  std::vector<uint64_t> orphans;  // copies no frame took: discarded at the next claim
  uint64_t framesSubmitted = 0;   // handed to the engine
  // The hands' fusion boxes (world) at the last xrEndFrame, grown by the motion a frame or two
  // may bring; empty while no hand is known (nothing would be fused).
  std::vector<std::pair<glm::vec3, glm::vec3>> boxes;
  bool refusedLogged = false, multisampleLogged = false, badInfoLogged = false,
       unknownLogged = false, failedLogged = false;
};

// Whether `s`'s app gets the depth scene: a Vulkan session, config depth_scene not off (auto:
// the app does not use XR_SDFG_auto_grasp), the app enabled XR_KHR_composition_layer_depth.
bool depthSceneWanted(const SessionState& s);
// xrEndFrame, before the call goes down: reads `info`'s depth and hands finished copies to the
// engine. Takes no lock on entry; never throws; changes nothing the runtime receives.
void captureDepthAtEndFrame(SessionState& s, const XrFrameEndInfo* info);
// Session end (endSessionWork): waits for the copies in flight and frees the device objects.
void endDepthCapture(SessionState& s);

}  // namespace sdfg::layer
