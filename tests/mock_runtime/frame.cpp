// Frame loop: xrWaitFrame / xrBeginFrame / xrEndFrame with the spec's call-order errors,
// layer validation, optional capture of the submitted images, and the N-frame end.
#include <algorithm>
#include <cmath>

#include "entry_points.h"
#include "pose_math.h"
#include "system_constants.h"

namespace sdfg::mock {
namespace {

// Checks one swapchain sub-image of a layer: live swapchain of this session, an image released
// at least once, rect inside the image.
XrResult verifySubImage(const char* cmd, const Session& session, const XrSwapchainSubImage& sub,
                        Swapchain** out) {
  Swapchain* sc = lookup<Swapchain>(sub.swapchain);
  if (sc == nullptr || sc->session != &session)
    return fail(cmd, XR_ERROR_HANDLE_INVALID, "layer swapchain is not valid for this session");
  if (sc->lastReleased < 0)
    return fail(cmd, XR_ERROR_LAYER_INVALID, "layer swapchain has no released image");
  const XrRect2Di& r = sub.imageRect;
  if (r.offset.x < 0 || r.offset.y < 0 || r.extent.width <= 0 || r.extent.height <= 0 ||
      uint64_t(r.offset.x) + uint64_t(r.extent.width) > sc->info.width ||
      uint64_t(r.offset.y) + uint64_t(r.extent.height) > sc->info.height)
    return fail(cmd, XR_ERROR_SWAPCHAIN_RECT_INVALID, "imageRect outside the %ux%u image",
                sc->info.width, sc->info.height);
  if (sub.imageArrayIndex >= sc->info.arraySize)
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "imageArrayIndex %u >= arraySize %u",
                sub.imageArrayIndex, sc->info.arraySize);
  *out = sc;
  return XR_SUCCESS;
}

bool notNegative(float v) {
  return !std::isnan(v) && v >= 0.0f;
}

// Checks one XrCompositionLayerDepthInfoKHR (XR_KHR_composition_layer_depth): a depth swapchain
// of this session with a released image, the sub-image inside it, a depth range inside [0, 1]
// and two distinct planes, either of which may be at +infinity (reversed or infinite depth).
XrResult verifyDepthInfo(const char* cmd, const Session& session,
                         const XrCompositionLayerDepthInfoKHR& d, uint32_t view) {
  Swapchain* sc = nullptr;
  if (XrResult r = verifySubImage(cmd, session, d.subImage, &sc); r != XR_SUCCESS) return r;
  if (!isDepthFormat(sc->info.format))
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE,
                "views[%u] depth info: swapchain format %lld is no depth format", view,
                (long long)sc->info.format);
  if (!(d.minDepth >= 0.0f && d.minDepth <= 1.0f && d.maxDepth >= 0.0f && d.maxDepth <= 1.0f &&
        d.minDepth < d.maxDepth))
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE,
                "views[%u] depth info: minDepth %g, maxDepth %g (need 0 <= min < max <= 1)", view,
                double(d.minDepth), double(d.maxDepth));
  if (!notNegative(d.nearZ) || !notNegative(d.farZ) || d.nearZ == d.farZ)
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE,
                "views[%u] depth info: nearZ %g, farZ %g (need two distinct planes >= 0)", view,
                double(d.nearZ), double(d.farZ));
  return XR_SUCCESS;
}

XrResult verifyLayerSpace(const char* cmd, const Session& session, XrSpace handle) {
  const Space* space = lookup<Space>(handle);
  if (space == nullptr || space->session != &session)
    return fail(cmd, XR_ERROR_HANDLE_INVALID, "layer space is not valid for this session");
  return XR_SUCCESS;
}

// Counts a submitted frame and ends the session after the configured number.
XrResult finishFrame(Session& session, const XrFrameEndInfo& info) {
  session.frameBegun = false;
  XrMockRuntimeStatsSDFG& s = session.stats;
  ++s.framesEnded;
  s.frameIndex = s.framesEnded;
  if (info.layerCount > 0) ++s.framesWithLayers;
  s.lastLayerCount = info.layerCount;
  const uint64_t n = session.instance->options.endAfterFrames;
  if (n > 0 && s.framesEnded >= n) beginStopping(session);
  return XR_SUCCESS;
}

bool zeroDisplayTime(const Session& session) {
  return session.instance->options.fault == "zero_display_time";
}

}  // namespace

XrResult waitFrame(XrSession handle, const XrFrameWaitInfo* info, XrFrameState* state) {
  constexpr const char* cmd = "xrWaitFrame";
  Session* session = lookup<Session>(handle);
  if (session == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "session is not valid");
  if (info != nullptr) MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_FRAME_WAIT_INFO);
  MOCK_VERIFY_TYPE(cmd, state, XR_TYPE_FRAME_STATE);
  if (!session->running) return fail(cmd, XR_ERROR_SESSION_NOT_RUNNING, "not running");
  if (session->state == XR_SESSION_STATE_READY && !session->stopping) {
    queueState(*session, XR_SESSION_STATE_SYNCHRONIZED);
    queueState(*session, XR_SESSION_STATE_VISIBLE);
    queueState(*session, XR_SESSION_STATE_FOCUSED);
  }
  // Display times strictly increase and never fall behind the clock.
  const XrTime t = std::max(now() + kFramePeriod, session->lastPredicted + kFramePeriod);
  session->lastPredicted = t;
  // Fault "zero_display_time": Monado's headless sessions predict no display time (0), and a
  // layer must still work there.
  state->predictedDisplayTime = zeroDisplayTime(*session) ? 0 : t;
  state->predictedDisplayPeriod = kFramePeriod;
  state->shouldRender =
      session->state == XR_SESSION_STATE_VISIBLE || session->state == XR_SESSION_STATE_FOCUSED;
  ++session->framesWaitedPending;
  ++session->stats.framesWaited;
  return XR_SUCCESS;
}

XrResult beginFrame(XrSession handle, const XrFrameBeginInfo* info) {
  constexpr const char* cmd = "xrBeginFrame";
  Session* session = lookup<Session>(handle);
  if (session == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "session is not valid");
  if (info != nullptr) MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_FRAME_BEGIN_INFO);
  if (!session->running) return fail(cmd, XR_ERROR_SESSION_NOT_RUNNING, "not running");
  if (session->framesWaitedPending == 0)
    return fail(cmd, XR_ERROR_CALL_ORDER_INVALID, "no xrWaitFrame before this xrBeginFrame");
  --session->framesWaitedPending;
  ++session->stats.framesBegun;
  if (session->frameBegun) return XR_FRAME_DISCARDED;  // the previous frame is dropped
  session->frameBegun = true;
  return XR_SUCCESS;
}

XrResult endFrame(XrSession handle, const XrFrameEndInfo* info) {
  constexpr const char* cmd = "xrEndFrame";
  Session* session = lookup<Session>(handle);
  if (session == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "session is not valid");
  MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_FRAME_END_INFO);
  if (!session->running) return fail(cmd, XR_ERROR_SESSION_NOT_RUNNING, "not running");
  if (!session->frameBegun)
    return fail(cmd, XR_ERROR_CALL_ORDER_INVALID, "no xrBeginFrame before this xrEndFrame");
  if (info->displayTime < 0 || (info->displayTime == 0 && !zeroDisplayTime(*session)))
    return fail(cmd, XR_ERROR_TIME_INVALID, "displayTime %lld", (long long)info->displayTime);
  // Every mode but OPAQUE, known or not, is one this system lacks (the CTS passes MAX_ENUM).
  if (info->environmentBlendMode != XR_ENVIRONMENT_BLEND_MODE_OPAQUE)
    return fail(cmd, XR_ERROR_ENVIRONMENT_BLEND_MODE_UNSUPPORTED, "environmentBlendMode %d",
                int(info->environmentBlendMode));
  // A headless session (XR_MND_headless) has no swapchains and composes nothing: its layers are
  // ignored, as Monado does (the CTS submits a projection of zero views there).
  if (!session->vulkan) return finishFrame(*session, *info);
  if (info->layerCount > kMaxLayerCount)
    return fail(cmd, XR_ERROR_LAYER_LIMIT_EXCEEDED, "layerCount %u > %u", info->layerCount,
                kMaxLayerCount);
  if (info->layerCount > 0) MOCK_VERIFY_NOT_NULL(cmd, info->layers);

  const XrCompositionLayerProjection* firstProjection = nullptr;
  uint32_t depthInfos = 0;  // counted once the whole frame is accepted
  for (uint32_t i = 0; i < info->layerCount; ++i) {
    const XrCompositionLayerBaseHeader* layer = info->layers[i];
    if (layer == nullptr) return fail(cmd, XR_ERROR_LAYER_INVALID, "layers[%u] is null", i);
    if (XrResult r = verifyLayerSpace(cmd, *session, layer->space); r != XR_SUCCESS) return r;
    Swapchain* sc = nullptr;
    if (layer->type == XR_TYPE_COMPOSITION_LAYER_PROJECTION) {
      const auto* p = reinterpret_cast<const XrCompositionLayerProjection*>(layer);
      if (p->viewCount != kViewCount)
        return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "projection viewCount %u, expected 2",
                    p->viewCount);
      MOCK_VERIFY_NOT_NULL(cmd, p->views);
      for (uint32_t v = 0; v < p->viewCount; ++v) {
        if (p->views[v].type != XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW)
          return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "(views[%u].type) is wrong", v);
        if (!isUnitQuaternion(p->views[v].pose.orientation) || !isFinite(p->views[v].pose.position))
          return fail(cmd, XR_ERROR_POSE_INVALID, "views[%u].pose", v);
        if (XrResult r = verifySubImage(cmd, *session, p->views[v].subImage, &sc); r != XR_SUCCESS)
          return r;
        // Without the extension the struct is not the app's to chain, and a runtime skips
        // what it does not know.
        if (!session->instance->extDepth) continue;
        for (auto* n = static_cast<const XrBaseInStructure*>(p->views[v].next); n != nullptr;
             n = n->next) {
          if (n->type != XR_TYPE_COMPOSITION_LAYER_DEPTH_INFO_KHR) continue;
          const auto& d = *reinterpret_cast<const XrCompositionLayerDepthInfoKHR*>(n);
          if (XrResult r = verifyDepthInfo(cmd, *session, d, v); r != XR_SUCCESS) return r;
          ++depthInfos;
        }
      }
      if (firstProjection == nullptr) firstProjection = p;
    } else if (layer->type == XR_TYPE_COMPOSITION_LAYER_QUAD) {
      const auto* q = reinterpret_cast<const XrCompositionLayerQuad*>(layer);
      if (!isUnitQuaternion(q->pose.orientation) || !isFinite(q->pose.position))
        return fail(cmd, XR_ERROR_POSE_INVALID, "quad pose");
      if (XrResult r = verifySubImage(cmd, *session, q->subImage, &sc); r != XR_SUCCESS) return r;
    } else {
      return fail(cmd, XR_ERROR_LAYER_INVALID, "layers[%u] has type %d", i, int(layer->type));
    }
  }

  if (firstProjection != nullptr && session->instance->options.capture && session->vulkan) {
    bool captured = true;
    for (uint32_t v = 0; v < kViewCount; ++v) {
      const XrSwapchainSubImage& sub = firstProjection->views[v].subImage;
      Swapchain* sc = lookup<Swapchain>(sub.swapchain);
      captured = captureVulkanImage(*session, *sc, uint32_t(sc->lastReleased), sub.imageArrayIndex,
                                    session->captures[v]) &&
                 captured;
    }
    if (captured) ++session->stats.framesCaptured;
  }

  if (depthInfos > 0) ++session->framesWithDepth;
  session->depthInfos += depthInfos;
  return finishFrame(*session, *info);
}

}  // namespace sdfg::mock
