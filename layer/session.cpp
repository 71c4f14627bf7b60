// Sessions and what the layer tracks on them: system properties (hand tracking it provides),
// session create/destroy, the predicted display time, and the app's spaces.
#include <algorithm>

#include "intercepts.h"
#include "log.h"
#include "state.h"

namespace sdfg::layer {
namespace {

std::shared_ptr<InstanceState> instanceOf(XrInstance handle) {
  return instances().find(key(handle));
}

// Records a space the app created on `s`, so grasp targets placed in it can be validated and
// located, and so it is forgotten with its session.
void rememberSpace(const std::shared_ptr<SessionState>& s, XrSpace space) {
  std::lock_guard lock(s->mutex);
  s->spaces.insert(key(space));
  spaceOwners().insert(key(space), s);
}

// The current time in the runtime's XrTime, for a frame whose predicted display time is 0 (or
// negative): every grasp needs a time to locate hands and targets at. 0 when the chain offers
// no conversion; then the layer says once that this session cannot grasp.
XrTime layerClockTime(SessionState& s, const char* cmd) {
  InstanceState& inst = *s.instance;
  XrTime t = 0;
  timespec now{};
  if (inst.next.xrConvertTimespecTimeToTimeKHR != nullptr &&
      clock_gettime(CLOCK_MONOTONIC, &now) == 0 &&
      inst.next.xrConvertTimespecTimeToTimeKHR(inst.handle, &now, &t) == XR_SUCCESS && t > 0)
    return t;
  if (!s.noTimeLogged) {
    s.noTimeLogged = true;
    SDFG_LOG_WARN(cmd,
                  "the runtime predicts no display time and offers no "
                  "XR_KHR_convert_timespec_time: no grasps in this session");
  }
  return 0;
}

}  // namespace

XrResult XRAPI_CALL SdfgXrGetSystemProperties(XrInstance instance, XrSystemId systemId,
                                              XrSystemProperties* properties) {
  constexpr const char* cmd = "xrGetSystemProperties";
  SDFG_ENTRY_BEGIN
  auto state = instanceOf(instance);
  if (state == nullptr) return logError(XR_ERROR_HANDLE_INVALID, cmd, "(instance) is not valid");
  if (!state->provideHandTracking || properties == nullptr) {
    const XrResult r = state->next.xrGetSystemProperties(instance, systemId, properties);
    if (XR_FAILED(r) || properties == nullptr || !state->appHandTracking) return r;
    // The runtime lists the extension, but its system may have no hands (controllers only): the
    // layer synthesizes them and says so, once per instance.
    auto* hand = findInChain<XrSystemHandTrackingPropertiesEXT>(
        properties->next, XR_TYPE_SYSTEM_HAND_TRACKING_PROPERTIES_EXT);
    if (hand != nullptr && !hand->supportsHandTracking && state->config.synthesis) {
      hand->supportsHandTracking = XR_TRUE;
      if (!state->runtimeSystemLacksHands.exchange(true))
        SDFG_LOG_WARN(cmd,
                      "the runtime's system cannot track hands; the layer synthesizes "
                      "them from the controllers' grip pose and squeeze");
    }
    return r;
  }
  // The runtime does not know XR_EXT_hand_tracking: unlink its struct for the call down (core
  // validation below would report it), then link it back and answer it.
  auto* chain = reinterpret_cast<XrBaseOutStructure*>(properties);
  XrBaseOutStructure* prev = chain;
  XrSystemHandTrackingPropertiesEXT* hand = nullptr;
  for (XrBaseOutStructure* p = chain->next; p != nullptr; prev = p, p = p->next) {
    if (p->type == XR_TYPE_SYSTEM_HAND_TRACKING_PROPERTIES_EXT) {
      hand = reinterpret_cast<XrSystemHandTrackingPropertiesEXT*>(p);
      prev->next = p->next;
      break;
    }
  }
  const XrResult r = state->next.xrGetSystemProperties(instance, systemId, properties);
  if (hand != nullptr) {
    hand->next = prev->next;
    prev->next = reinterpret_cast<XrBaseOutStructure*>(hand);
    // Joints come from the controllers' grip pose and squeeze; with synthesis switched off
    // there is nothing to drive them.
    if (XR_SUCCEEDED(r)) hand->supportsHandTracking = state->config.synthesis ? XR_TRUE : XR_FALSE;
  }
  return r;
  SDFG_ENTRY_END(cmd)
}

XrResult XRAPI_CALL SdfgXrCreateSession(XrInstance instance, const XrSessionCreateInfo* info,
                                        XrSession* session) {
  constexpr const char* cmd = "xrCreateSession";
  SDFG_ENTRY_BEGIN
  auto state = instanceOf(instance);
  if (state == nullptr) return logError(XR_ERROR_HANDLE_INVALID, cmd, "(instance) is not valid");
  const XrResult r = state->next.xrCreateSession(instance, info, session);
  if (XR_FAILED(r)) return r;
  auto s = std::make_shared<SessionState>();
  s->handle = *session;
  s->instance = state;
  if (const auto* vk = findInChain<const XrGraphicsBindingVulkanKHR>(
          info->next, XR_TYPE_GRAPHICS_BINDING_VULKAN_KHR)) {
    s->vulkan = true;
    s->vulkanBinding = *vk;
    s->vulkanBinding.next = nullptr;
  }
  s->settings = settingsFromConfig(state->config);
  s->offsets.blendTime = state->config.offsetBlendTime;
  // Vulkan sessions build on the app's device (vulkan.cpp); the CPU builder is the fallback and
  // the path of every other session.
  std::unique_ptr<DeferredSdfBackend> gpu;
  if (s->vulkan && state->appAutoGrasp) gpu = makeVulkanBackend(*s);
  // The band is fixed in metres from the configured box: a finer grid chosen later through
  // xrSetGraspOptionsSDFG keeps it, so its nodes are exact over more spacings (slower, as safe).
  CpuSdfOptions cpuOptions;
  const glm::vec3 spacing = s->settings.box.spacing();
  cpuOptions.exactBand =
      state->config.sdfFarBand * std::max(spacing.x, std::max(spacing.y, spacing.z));
  // CPU builds, target set-ups and solves run on the session's worker thread, never inside the
  // app's calls; its builder uses that one thread (an app on a 2-core machine keeps the other).
  s->grasp = std::make_unique<GraspSession>(makeCpuSdfBackend(1, cpuOptions), std::move(gpu));
  s->grasp->setDeferredForMeshTargets(s->gpuForArrayTargets);
  if (Status st = s->grasp->configure(s->settings); st != Status::ok) {
    SDFG_LOG_WARN(cmd, "configured solver '%s' is not usable (%s); using 'paper'",
                  s->settings.solver.c_str(), toString(st));
    s->settings.solver = "paper";
    (void)s->grasp->configure(s->settings);
  }
  sessions().insert(key(*session), std::move(s));
  return r;
  SDFG_ENTRY_END(cmd)
}

XrResult XRAPI_CALL SdfgXrDestroySession(XrSession session) {
  constexpr const char* cmd = "xrDestroySession";
  SDFG_ENTRY_BEGIN
  auto s = sessions().find(key(session));
  if (s == nullptr) return logError(XR_ERROR_HANDLE_INVALID, cmd, "(session) is not valid");
  {
    std::lock_guard lock(s->mutex);
    destroyInternalTrackers(*s);
    // GPU work first: waits for builds in flight and frees the layer's objects on the app's
    // device while it surely exists (the app destroys it after the session).
    dropGpuWork(*s);
  }
  const XrResult r = s->instance->next.xrDestroySession(session);
  if (XR_SUCCEEDED(r)) {
    // Children go with the session: its trackers, targets and spaces.
    trackers().eraseIf([&](const TrackerState& t) { return t.session.lock() == s; });
    targets().eraseIf([&](const TargetState& t) { return t.session.lock() == s; });
    spaceOwners().eraseIf([&](const SessionState& owner) { return &owner == s.get(); });
    std::lock_guard lock(s->mutex);
    s->targets.clear();
    s->grasp.reset();
    sessions().erase(key(session));
    s->instance->events.dropSession(session);  // its grasp events would name a dead handle
  }
  return r;
  SDFG_ENTRY_END(cmd)
}

XrResult XRAPI_CALL SdfgXrWaitFrame(XrSession session, const XrFrameWaitInfo* info,
                                    XrFrameState* frameState) {
  constexpr const char* cmd = "xrWaitFrame";
  SDFG_ENTRY_BEGIN
  auto s = sessions().find(key(session));
  if (s == nullptr) return logError(XR_ERROR_HANDLE_INVALID, cmd, "(session) is not valid");
  const XrResult r = s->instance->next.xrWaitFrame(session, info, frameState);
  if (XR_SUCCEEDED(r) && frameState != nullptr) {
    // The layer's own work never changes the app's result.
    try {
      std::lock_guard lock(s->mutex);
      s->predictedTime = frameState->predictedDisplayTime;
      if (s->predictedTime <= 0) s->predictedTime = layerClockTime(*s, cmd);
      selfAttachIfNeeded(*s);
      if (s->selfAttached) syncOwnActions(*s);
    } catch (...) {
      SDFG_LOG_WARN(cmd, "frame update failed; hands pass through this frame");
    }
  }
  return r;
  SDFG_ENTRY_END(cmd)
}

XrResult XRAPI_CALL SdfgXrCreateReferenceSpace(XrSession session,
                                               const XrReferenceSpaceCreateInfo* info,
                                               XrSpace* space) {
  constexpr const char* cmd = "xrCreateReferenceSpace";
  SDFG_ENTRY_BEGIN
  auto s = sessions().find(key(session));
  if (s == nullptr) return logError(XR_ERROR_HANDLE_INVALID, cmd, "(session) is not valid");
  const XrResult r = s->instance->next.xrCreateReferenceSpace(session, info, space);
  if (XR_SUCCEEDED(r)) rememberSpace(s, *space);
  return r;
  SDFG_ENTRY_END(cmd)
}

XrResult XRAPI_CALL SdfgXrCreateActionSpace(XrSession session, const XrActionSpaceCreateInfo* info,
                                            XrSpace* space) {
  constexpr const char* cmd = "xrCreateActionSpace";
  SDFG_ENTRY_BEGIN
  auto s = sessions().find(key(session));
  if (s == nullptr) return logError(XR_ERROR_HANDLE_INVALID, cmd, "(session) is not valid");
  const XrResult r = s->instance->next.xrCreateActionSpace(session, info, space);
  if (XR_SUCCEEDED(r)) rememberSpace(s, *space);
  return r;
  SDFG_ENTRY_END(cmd)
}

XrResult XRAPI_CALL SdfgXrDestroySpace(XrSpace space) {
  constexpr const char* cmd = "xrDestroySpace";
  SDFG_ENTRY_BEGIN
  auto s = spaceOwners().find(key(space));
  if (s == nullptr) {
    // A space this layer did not see created (an anchor of another extension): pass it down.
    auto any = instances().any();
    if (any == nullptr) return logError(XR_ERROR_HANDLE_INVALID, cmd, "(space) is not valid");
    return any->next.xrDestroySpace(space);
  }
  const XrResult r = s->instance->next.xrDestroySpace(space);
  if (XR_SUCCEEDED(r)) {
    std::lock_guard lock(s->mutex);
    s->spaces.erase(key(space));
    spaceOwners().erase(key(space));
  }
  return r;
  SDFG_ENTRY_END(cmd)
}

}  // namespace sdfg::layer
