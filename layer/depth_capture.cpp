// The depth scene's capture: swapchain calls, the copies at release and the frame's depth info
// at xrEndFrame (depth_capture.h says what each does and why there).
#include "depth_capture.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <thread>

#include "intercepts.h"
#include "log.h"
#include "state.h"

namespace sdfg::layer {
namespace {

// Frames whose copies are not read yet; an older one is dropped (the newest depth matters).
constexpr size_t kMaxFramesWaiting = 3;
// The longest side the layer reads of a view's depth; a larger rect is read every k-th pixel
// (the fusion's voxels are millimetres: at 40 cm a 90-degree view of 320 pixels is 2.5 mm each).
constexpr uint32_t kMaxReadSide = 320;
// Metres added to each side of a hand's fusion box before it places a copy: the box is the one of
// the last xrEndFrame, and the hand moves a frame or two before the copy's frame is fused (2 m/s
// is 2.2 cm a frame at 90 Hz).
constexpr float kBoxMargin = 0.05f;
// The copy's rect grows by this fraction of the view's longer side, for the head's turn since the
// view it was placed in (100 degrees a second is 1.1 degrees a frame: 2 % of a 90-degree view).
constexpr float kTurnMargin = 0.04f;
// How long teardown (xrDestroySwapchain, the session's end) waits for a copy in flight.
constexpr uint64_t kTeardownWaitNs = 2'000'000'000ull;

// A depth format the copy can read (vulkan/vk_depth_capture.h); none without the Vulkan path.
bool readableDepthFormat(int64_t f) {
#if SDFG_LAYER_VULKAN
  return VkDepthCapture::readableFormat(VkFormat(f));
#else
  (void)f;
  return false;
#endif
}

// The device copy object, held by one thread at a time; never waited for in a frame call.
class Claim {
 public:
  explicit Claim(SessionDepth& d) : d_(d) { held_ = !d_.busy.exchange(true); }
  // Teardown: waits (sleeping) up to `bound` for the thread that holds it.
  Claim(SessionDepth& d, std::chrono::milliseconds bound) : d_(d) {
    const auto end = std::chrono::steady_clock::now() + bound;
    while (!(held_ = !d_.busy.exchange(true)) && std::chrono::steady_clock::now() < end)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ~Claim() {
    if (held_) d_.busy.store(false);
  }
  Claim(const Claim&) = delete;
  Claim& operator=(const Claim&) = delete;
  bool held() const { return held_; }

 private:
  SessionDepth& d_;
  bool held_ = false;
};

std::shared_ptr<SessionState> sessionOf(const SwapchainState& sc) {
  return sc.session.lock();
}

// The swapchain and its session; false for a handle the layer did not see created (the runtime
// would answer XR_ERROR_HANDLE_INVALID, and the layer has no chain to pass it down).
bool findSwapchain(XrSwapchain handle, std::shared_ptr<SwapchainState>& sc,
                   std::shared_ptr<SessionState>& s) {
  sc = swapchains().find(key(handle));
  s = sc != nullptr ? sessionOf(*sc) : nullptr;
  return s != nullptr;
}

#if SDFG_LAYER_VULKAN
// The copy object on the session's device, made at the first copy (the caller holds the claim).
VkDepthCapture* deviceCapture(SessionState& s, SessionDepth& d) {
  if (d.gpuTried) return d.gpu.get();
  d.gpuTried = true;
  auto made = VkDepthCapture::create(appVulkanDevice(s), [](const std::string& line) {
    SDFG_LOG_WARN("sdfg depth", "%s", line.c_str());
  });
  if (!made) {
    SDFG_LOG_WARN("sdfg depth", "no depth scene on this session: %s", made.error().message.c_str());
    return nullptr;
  }
  d.gpu = std::move(made.value());
  return d.gpu.get();
}

// Discards the copies no frame took (the caller holds the claim).
void discardOrphans(SessionDepth& d) {
  std::vector<uint64_t> orphans;
  {
    std::lock_guard lock(d.mutex);
    orphans.swap(d.orphans);
  }
  if (d.gpu)
    for (uint64_t t : orphans) d.gpu->discard(t);
}

// The rects of `sc`'s layers worth copying (the caller holds sc.mutex): in each layer, the pixels
// whose rays meet one of `boxes` in the view last submitted from it, grown for the head's turn;
// the whole layer before any view. Empty when no box is known or none is in sight.
std::vector<VkDepthRect> regionsToCopy(const SwapchainState& sc,
                                       const std::vector<std::pair<glm::vec3, glm::vec3>>& boxes) {
  std::vector<VkDepthRect> out;
  if (boxes.empty()) return out;
  for (uint32_t layer = 0; layer < sc.layers; ++layer) {
    if (layer >= sc.seen.size() || !sc.seen[layer]) {
      out.push_back(VkDepthRect{layer, 0, 0, sc.width, sc.height});
      continue;
    }
    const SwapchainState::SeenView& seen = *sc.seen[layer];
    int64_t x0 = INT64_MAX, y0 = INT64_MAX, x1 = INT64_MIN, y1 = INT64_MIN;
    for (const auto& [lo, hi] : boxes) {
      const auto r = seen.view.cover(lo, hi);
      if (!r) continue;
      x0 = std::min<int64_t>(x0, int64_t(seen.x) + r->x);
      y0 = std::min<int64_t>(y0, int64_t(seen.y) + r->y);
      x1 = std::max<int64_t>(x1, int64_t(seen.x) + r->x + r->width);
      y1 = std::max<int64_t>(y1, int64_t(seen.y) + r->y + r->height);
    }
    if (x0 >= x1 || y0 >= y1) continue;  // no hand in sight of this layer
    const int64_t grow =
        2 + int64_t(kTurnMargin * float(std::max(seen.view.width, seen.view.height)));
    x0 = std::max<int64_t>(x0 - grow, 0);
    y0 = std::max<int64_t>(y0 - grow, 0);
    x1 = std::min<int64_t>(x1 + grow, sc.width);
    y1 = std::min<int64_t>(y1 + grow, sc.height);
    if (x0 >= x1 || y0 >= y1) continue;
    out.push_back(
        VkDepthRect{layer, int32_t(x0), int32_t(y0), uint32_t(x1 - x0), uint32_t(y1 - y0)});
  }
  return out;
}

// The part of `rect` (of `layer`) that `regions` hold; empty when none does.
VkDepthRect heldPart(const std::vector<VkDepthRect>& regions, uint32_t layer,
                     const VkDepthRect& rect) {
  for (const VkDepthRect& r : regions) {
    if (r.layer != layer) continue;
    const int64_t x0 = std::max<int64_t>(r.x, rect.x), y0 = std::max<int64_t>(r.y, rect.y);
    const int64_t x1 = std::min<int64_t>(int64_t(r.x) + r.width, int64_t(rect.x) + rect.width);
    const int64_t y1 = std::min<int64_t>(int64_t(r.y) + r.height, int64_t(rect.y) + rect.height);
    if (x0 < x1 && y0 < y1)
      return VkDepthRect{layer, int32_t(x0), int32_t(y0), uint32_t(x1 - x0), uint32_t(y1 - y0)};
  }
  return VkDepthRect{layer, 0, 0, 0, 0};
}
#endif

// Once a session: the line that says why its depth is not read.
void logOnce(bool SessionDepth::*flag, SessionDepth& d, const char* cmd, const char* what) {
  {
    std::lock_guard lock(d.mutex);
    if (d.*flag) return;
    d.*flag = true;
  }
  SDFG_LOG_WARN(cmd, "%s", what);
}

}  // namespace

bool depthSceneWanted(const SessionState& s) {
  const InstanceState& inst = *s.instance;
  if (!SDFG_LAYER_VULKAN || !s.vulkan || !inst.appDepthLayer) return false;
  switch (inst.config.depthScene) {
    case Config::DepthScene::off:
      return false;
    case Config::DepthScene::on:
      return true;
    case Config::DepthScene::automatic:
      return !inst.appAutoGrasp;
  }
  return false;
}

XrResult XRAPI_CALL SdfgXrCreateSwapchain(XrSession session, const XrSwapchainCreateInfo* info,
                                          XrSwapchain* swapchain) {
  constexpr const char* cmd = "xrCreateSwapchain";
  SDFG_ENTRY_BEGIN
  auto s = sessions().find(key(session));
  if (s == nullptr) return logError(XR_ERROR_HANDLE_INVALID, cmd, "(session) is not valid");
  const auto& next = s->instance->next.xrCreateSwapchain;
  // Anything the runtime must judge (a null or mistyped info) goes down as it is.
  if (info == nullptr || swapchain == nullptr || info->type != XR_TYPE_SWAPCHAIN_CREATE_INFO)
    return next(session, info, swapchain);
  const bool depthChain = s->depth != nullptr && readableDepthFormat(info->format) &&
                          (info->usageFlags & XR_SWAPCHAIN_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT);
  const bool copyable = depthChain && info->sampleCount == 1 && info->faceCount == 1;
  bool readable = copyable && (info->usageFlags & XR_SWAPCHAIN_USAGE_TRANSFER_SRC_BIT);
  XrResult r = XR_ERROR_RUNTIME_FAILURE;
  bool made = false;
  if (copyable && !readable) {
    XrSwapchainCreateInfo withCopy = *info;
    withCopy.usageFlags |= XR_SWAPCHAIN_USAGE_TRANSFER_SRC_BIT;
    r = next(session, &withCopy, swapchain);
    if (XR_SUCCEEDED(r)) {
      made = readable = true;
    } else {
      // Created as the app asked: the app's result is the runtime's answer to the app's info.
      logOnce(&SessionDepth::refusedLogged, *s->depth, cmd,
              "the runtime refused the transfer-source usage on a depth swapchain; its depth "
              "is not read (created exactly as the app asked)");
    }
  } else if (depthChain && info->sampleCount > 1) {
    logOnce(&SessionDepth::multisampleLogged, *s->depth, cmd,
            "a multisampled depth swapchain: its depth is not read (MSAA depth is not supported "
            "yet)");
  }
  if (!made) r = next(session, info, swapchain);
  if (XR_FAILED(r)) return r;
  try {
    auto sc = std::make_shared<SwapchainState>();
    sc->handle = key(*swapchain);
    sc->session = s;
    sc->depth = readable;
    sc->format = info->format;
    sc->width = info->width;
    sc->height = info->height;
    sc->layers = std::max(1u, info->arraySize);
    const uint64_t handle = sc->handle;
    swapchains().insert(handle, std::move(sc));
  } catch (...) {
    // The app's swapchain is fine; the layer cannot pass its calls down without it, so it goes.
    s->instance->next.xrDestroySwapchain(*swapchain);
    *swapchain = XR_NULL_HANDLE;
    throw;
  }
  return r;
  SDFG_ENTRY_END(cmd)
}

XrResult XRAPI_CALL SdfgXrDestroySwapchain(XrSwapchain swapchain) {
  constexpr const char* cmd = "xrDestroySwapchain";
  SDFG_ENTRY_BEGIN
  std::shared_ptr<SwapchainState> sc;
  std::shared_ptr<SessionState> s;
  if (!findSwapchain(swapchain, sc, s))
    return logError(XR_ERROR_HANDLE_INVALID, cmd, "(swapchain) is not valid");
#if SDFG_LAYER_VULKAN
  // The images go with the swapchain: no copy of the layer may still read them.
  if (sc->depth && s->depth != nullptr) {
    std::vector<VkImage> images;
    {
      std::lock_guard lock(sc->mutex);
      images = sc->images;
    }
    Claim claim(*s->depth, std::chrono::milliseconds(kTeardownWaitNs / 1'000'000));
    if (claim.held() && s->depth->gpu)
      for (VkImage im : images) (void)s->depth->gpu->forget(im, kTeardownWaitNs);
  }
#endif
  const XrResult r = s->instance->next.xrDestroySwapchain(swapchain);
  if (XR_SUCCEEDED(r)) swapchains().erase(key(swapchain));
  return r;
  SDFG_ENTRY_END(cmd)
}

XrResult XRAPI_CALL SdfgXrEnumerateSwapchainImages(XrSwapchain swapchain, uint32_t capacity,
                                                   uint32_t* countOutput,
                                                   XrSwapchainImageBaseHeader* images) {
  constexpr const char* cmd = "xrEnumerateSwapchainImages";
  SDFG_ENTRY_BEGIN
  std::shared_ptr<SwapchainState> sc;
  std::shared_ptr<SessionState> s;
  if (!findSwapchain(swapchain, sc, s))
    return logError(XR_ERROR_HANDLE_INVALID, cmd, "(swapchain) is not valid");
  const XrResult r =
      s->instance->next.xrEnumerateSwapchainImages(swapchain, capacity, countOutput, images);
  if (XR_SUCCEEDED(r) && sc->depth && capacity > 0 && images != nullptr && countOutput != nullptr &&
      images->type == XR_TYPE_SWAPCHAIN_IMAGE_VULKAN_KHR) {
    const auto* vk = reinterpret_cast<const XrSwapchainImageVulkanKHR*>(images);
    std::vector<VkImage> list;
    for (uint32_t i = 0; i < std::min(*countOutput, capacity); ++i) list.push_back(vk[i].image);
    std::lock_guard lock(sc->mutex);
    sc->images = std::move(list);
  }
  return r;
  SDFG_ENTRY_END(cmd)
}

XrResult XRAPI_CALL SdfgXrAcquireSwapchainImage(XrSwapchain swapchain,
                                                const XrSwapchainImageAcquireInfo* info,
                                                uint32_t* index) {
  constexpr const char* cmd = "xrAcquireSwapchainImage";
  SDFG_ENTRY_BEGIN
  std::shared_ptr<SwapchainState> sc;
  std::shared_ptr<SessionState> s;
  if (!findSwapchain(swapchain, sc, s))
    return logError(XR_ERROR_HANDLE_INVALID, cmd, "(swapchain) is not valid");
  const XrResult r = s->instance->next.xrAcquireSwapchainImage(swapchain, info, index);
  if (XR_SUCCEEDED(r) && sc->depth && index != nullptr) {
    std::lock_guard lock(sc->mutex);
    sc->acquired.push_back(*index);
  }
  return r;
  SDFG_ENTRY_END(cmd)
}

XrResult XRAPI_CALL SdfgXrReleaseSwapchainImage(XrSwapchain swapchain,
                                                const XrSwapchainImageReleaseInfo* info) {
  constexpr const char* cmd = "xrReleaseSwapchainImage";
  SDFG_ENTRY_BEGIN
  std::shared_ptr<SwapchainState> sc;
  std::shared_ptr<SessionState> s;
  if (!findSwapchain(swapchain, sc, s))
    return logError(XR_ERROR_HANDLE_INVALID, cmd, "(swapchain) is not valid");
  uint64_t copy = 0;
#if SDFG_LAYER_VULKAN
  std::vector<VkDepthRect> regions;
  if (sc->depth && s->depth != nullptr) {
    SessionDepth& d = *s->depth;
    try {
      VkDepthImage image;
      std::vector<std::pair<glm::vec3, glm::vec3>> boxes;
      {
        std::lock_guard lock(d.mutex);
        boxes = d.boxes;
      }
      {
        std::lock_guard lock(sc->mutex);
        // The release gives back the oldest image acquired (and waited for, or the runtime
        // refuses).
        if (!sc->acquired.empty() && sc->acquired.front() < sc->images.size())
          image.image = sc->images[sc->acquired.front()];
        regions = regionsToCopy(*sc, boxes);
      }
      image.format = VkFormat(sc->format);
      image.width = sc->width;
      image.height = sc->height;
      image.layers = sc->layers;
      Claim claim(d);
      if (image.image != VK_NULL_HANDLE && !regions.empty() && claim.held()) {
        discardOrphans(d);
        if (VkDepthCapture* gpu = deviceCapture(*s, d)) {
          auto made = gpu->submit(image, regions);
          if (made) copy = made.value();
        }
      }
    } catch (...) {
      // Out of memory in the layer: this frame goes without depth.
      copy = 0;
    }
  }
#endif
  const XrResult r = s->instance->next.xrReleaseSwapchainImage(swapchain, info);
  if (sc->depth) {
    uint64_t replaced = 0;
    {
      std::lock_guard lock(sc->mutex);
      if (XR_SUCCEEDED(r) && !sc->acquired.empty()) sc->acquired.pop_front();
      // Even without a copy: the frame must not read an older image's with this one's view.
      replaced = std::exchange(sc->lastCopy, copy);
#if SDFG_LAYER_VULKAN
      sc->lastRegions = copy != 0 ? std::move(regions) : std::vector<VkDepthRect>{};
#endif
    }
    if (replaced != 0 && s->depth != nullptr) {
      std::lock_guard lock(s->depth->mutex);
      s->depth->orphans.push_back(replaced);
    }
  }
  return r;
  SDFG_ENTRY_END(cmd)
}

void captureDepthAtEndFrame(SessionState& s, const XrFrameEndInfo* info) {
#if SDFG_LAYER_VULKAN
  constexpr const char* cmd = "xrEndFrame";
  if (s.depth == nullptr || info == nullptr || info->type != XR_TYPE_FRAME_END_INFO) return;
  SessionDepth& d = *s.depth;
  try {
    // 1. This frame's depth: the first projection layer whose views all carry depth info.
    const XrCompositionLayerProjection* projection = nullptr;
    if (info->layers != nullptr && info->layerCount <= 64) {
      for (uint32_t i = 0; i < info->layerCount && projection == nullptr; ++i) {
        const auto* l = info->layers[i];
        if (l == nullptr || l->type != XR_TYPE_COMPOSITION_LAYER_PROJECTION) continue;
        const auto* p = reinterpret_cast<const XrCompositionLayerProjection*>(l);
        if (p->views == nullptr || p->viewCount == 0 || p->viewCount > 16) continue;
        bool all = true;
        for (uint32_t v = 0; v < p->viewCount; ++v)
          all = all && findInChain<const XrCompositionLayerDepthInfoKHR>(
                           p->views[v].next, XR_TYPE_COMPOSITION_LAYER_DEPTH_INFO_KHR) != nullptr;
        if (all) projection = p;
      }
    }
    XrSpace local = XR_NULL_HANDLE;
    std::vector<std::pair<glm::vec3, glm::vec3>> boxes;
    {
      std::lock_guard lock(s.mutex);
      local = s.localSpace;
      if (s.grasp != nullptr)
        for (const auto& box : s.grasp->depthBoxes())
          if (box)
            boxes.emplace_back(box->lo - glm::vec3(kBoxMargin), box->hi + glm::vec3(kBoxMargin));
    }
    {
      std::lock_guard lock(d.mutex);
      d.boxes = std::move(boxes);
    }
    if (projection != nullptr && local != XR_NULL_HANDLE) {
      // Each view: its swapchain, its whole rect as a DepthView (in the layer's space until
      // located below), and the part of the rect its copy holds (none: out of the hands' sight,
      // or every slot was busy).
      struct Entry {
        std::shared_ptr<SwapchainState> sc;
        uint32_t layer = 0;
        XrOffset2Di offset{};
        DepthView view;
        uint64_t copy = 0;
        VkDepthRect held;
      };
      std::vector<Entry> entries;
      bool bad = false, unknown = false;
      for (uint32_t v = 0; v < projection->viewCount && !bad && !unknown; ++v) {
        const XrCompositionLayerProjectionView& pv = projection->views[v];
        const auto* di = findInChain<const XrCompositionLayerDepthInfoKHR>(
            pv.next, XR_TYPE_COMPOSITION_LAYER_DEPTH_INFO_KHR);
        auto sc = swapchains().find(key(di->subImage.swapchain));
        if (sc == nullptr || !sc->depth || sessionOf(*sc).get() != &s) {
          unknown = true;
          break;
        }
        const XrRect2Di& rect = di->subImage.imageRect;
        if (rect.offset.x < 0 || rect.offset.y < 0 || rect.extent.width <= 0 ||
            rect.extent.height <= 0 || int64_t(rect.offset.x) + rect.extent.width > sc->width ||
            int64_t(rect.offset.y) + rect.extent.height > sc->height ||
            di->subImage.imageArrayIndex >= sc->layers) {
          bad = true;
          break;
        }
        Entry e;
        e.layer = di->subImage.imageArrayIndex;
        e.offset = rect.offset;
        e.view.worldFromView = toPose(pv.pose);
        e.view.fov = {pv.fov.angleLeft, pv.fov.angleRight, pv.fov.angleUp, pv.fov.angleDown};
        e.view.width = uint32_t(rect.extent.width);
        e.view.height = uint32_t(rect.extent.height);
        e.view.minDepth = di->minDepth;
        e.view.maxDepth = di->maxDepth;
        e.view.nearZ = di->nearZ;
        e.view.farZ = di->farZ;
        if (e.view.validate()) {
          bad = true;
          break;
        }
        {
          std::lock_guard lock(sc->mutex);
          e.copy = sc->lastCopy;
          if (e.copy != 0)
            e.held = heldPart(
                sc->lastRegions, e.layer,
                VkDepthRect{e.layer, rect.offset.x, rect.offset.y, e.view.width, e.view.height});
        }
        e.sc = std::move(sc);
        entries.push_back(std::move(e));
      }
      if (bad)
        logOnce(&SessionDepth::badInfoLogged, d, cmd,
                "depth info that cannot be right (a rect outside the image, an array index past "
                "its layers, a depth range or planes a depth image cannot have): that frame's "
                "depth is skipped");
      if (unknown)
        logOnce(&SessionDepth::unknownLogged, d, cmd,
                "depth info names a swapchain the layer cannot read (not a depth swapchain of "
                "this session, or one whose transfer-source usage was refused): no depth scene "
                "from it");
      // 2. Where the views are: the layer's space in the layer's LOCAL at the display time.
      XrSpaceLocation loc{XR_TYPE_SPACE_LOCATION};
      const XrSpaceLocationFlags need =
          XR_SPACE_LOCATION_POSITION_VALID_BIT | XR_SPACE_LOCATION_ORIENTATION_VALID_BIT;
      if (!bad && !unknown && entries.size() == projection->viewCount &&
          XR_SUCCEEDED(
              s.instance->next.xrLocateSpace(projection->space, local, info->displayTime, &loc)) &&
          (loc.locationFlags & need) == need && isFinitePose(loc.pose)) {
        const Pose localFromSpace = toPose(loc.pose);
        DepthFrame frame;
        frame.time = double(info->displayTime) * 1e-9;
        for (Entry& e : entries) {
          e.view.worldFromView = localFromSpace * e.view.worldFromView;
          {
            // The view places the next copy of its layer; the frame holds this one now (a
            // swapchain the views share is taken once).
            std::lock_guard lock(e.sc->mutex);
            if (e.sc->seen.size() < e.sc->layers) e.sc->seen.resize(e.sc->layers);
            e.sc->seen[e.layer] = SwapchainState::SeenView{e.view, e.offset.x, e.offset.y};
            e.sc->lastCopy = 0;
            e.sc->lastRegions.clear();
          }
          if (e.copy == 0 || e.held.width == 0) continue;
          // The held part of the rect, read every step-th pixel so that its longer side is
          // kMaxReadSide at most.
          const uint32_t side = std::max(e.held.width, e.held.height);
          const uint32_t step = (side + kMaxReadSide - 1) / kMaxReadSide;
          DepthView view = e.view.crop(DepthPixelRect{uint32_t(e.held.x - e.offset.x),
                                                      uint32_t(e.held.y - e.offset.y), e.held.width,
                                                      e.held.height});
          view.width = (e.held.width + step - 1) / step;
          view.height = (e.held.height + step - 1) / step;
          frame.views.push_back(view);
          frame.copies.push_back(e.copy);
          frame.rects.push_back(e.held);
          frame.steps.push_back(step);
        }
        std::lock_guard lock(d.mutex);
        // A copy no view reads (its part of the rects out of the hands' sight) is done with.
        for (const Entry& e : entries)
          if (e.copy != 0 &&
              std::find(frame.copies.begin(), frame.copies.end(), e.copy) == frame.copies.end() &&
              std::find(d.orphans.begin(), d.orphans.end(), e.copy) == d.orphans.end())
            d.orphans.push_back(e.copy);
        if (!frame.views.empty()) {
          d.frames.push_back(std::move(frame));
          while (d.frames.size() > kMaxFramesWaiting) {
            for (uint64_t t : d.frames.front().copies) d.orphans.push_back(t);
            d.frames.pop_front();
          }
        }
      }
    }

    // 3. Frames whose copies have finished, oldest first, to the engine.
    Claim claim(d);
    if (!claim.held() || d.gpu == nullptr) return;
    discardOrphans(d);
    for (;;) {
      // Only xrEndFrame adds and takes frames, and the app makes one frame call at a time; the
      // lock is for the fence checks, which run with it released.
      std::vector<uint64_t> front;
      {
        std::lock_guard lock(d.mutex);
        if (d.frames.empty()) break;
        front = d.frames.front().copies;
      }
      bool ready = true, lost = d.gpu->failed();
      for (uint64_t t : front) {
        ready = ready && d.gpu->finished(t);
        // A copy the capture no longer holds (its swapchain was destroyed) never finishes.
        lost = lost || !d.gpu->holds(t);
      }
      DepthFrame frame;
      {
        std::lock_guard lock(d.mutex);
        if (d.frames.empty() || d.frames.front().copies != front) break;
        if (lost) {
          for (uint64_t t : front) d.orphans.push_back(t);
          d.frames.pop_front();
          continue;
        }
        if (!ready) break;
        frame = std::move(d.frames.front());
        d.frames.pop_front();
      }
      std::vector<std::vector<float>> values;
      for (size_t v = 0; v < frame.views.size(); ++v)
        values.push_back(d.gpu->read(frame.copies[v], frame.rects[v], frame.steps[v]));
      std::vector<uint64_t> copies = frame.copies;
      std::sort(copies.begin(), copies.end());
      copies.erase(std::unique(copies.begin(), copies.end()), copies.end());
      for (uint64_t t : copies) d.gpu->discard(t);
      Status st = Status::ok;
      {
        std::lock_guard lock(s.mutex);
        if (s.grasp == nullptr) return;
        if (!s.grasp->depthSceneEnabled()) st = s.grasp->enableDepthScene();
        if (st == Status::ok)
          st = s.grasp->submitDepth(std::move(frame.views), std::move(values), frame.time);
      }
      if (st == Status::ok) {
        std::lock_guard lock(d.mutex);
        ++d.framesSubmitted;
      } else {
        logOnce(&SessionDepth::failedLogged, d, cmd,
                "the depth scene refused a frame of depth; later frames are tried as they come");
      }
    }
  } catch (...) {
    // Out of memory in the layer: the frame goes without depth, the app's call goes on.
  }
#else
  (void)s;
  (void)info;
#endif
}

void endDepthCapture(SessionState& s) {
  if (s.depth == nullptr) return;
#if SDFG_LAYER_VULKAN
  Claim claim(*s.depth, std::chrono::milliseconds(kTeardownWaitNs / 1'000'000));
  if (claim.held()) s.depth->gpu.reset();  // waits for its copies in flight (2 s at most)
#endif
}

}  // namespace sdfg::layer
