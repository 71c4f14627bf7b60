// Sessions and what the layer tracks on them: system properties (hand tracking it provides),
// session create/destroy, the predicted display time, and the app's spaces.
#include <algorithm>
#include <chrono>
#include <optional>

#include "intercepts.h"
#include "log.h"
#include "rollback.h"
#include "state.h"
#include "test_fault.h"

namespace sdfg::layer {
namespace {

// How long xrDestroySpace waits for the layer's own use of the space (one xrLocateSpace of the
// runtime) to end.
constexpr std::chrono::seconds kSpaceUseWait{5};

std::shared_ptr<InstanceState> instanceOf(XrInstance handle) {
  return instances().find(key(handle));
}

// Records a space the app created on `s`, so grasp targets placed in it can be validated and
// located, and so it is forgotten with its session. On failure (out of memory) the runtime's
// space is destroyed and the exception goes on to the entry point, which returns the error.
void rememberSpace(const std::shared_ptr<SessionState>& s, XrSpace* space) {
  const InstanceState& inst = *s->instance;
  const XrSpace made = *space;
  Rollback undo([&] {
    {
      std::lock_guard lock(s->mutex);
      s->spaces.erase(key(made));
    }
    inst.next.xrDestroySpace(made);
    *space = XR_NULL_HANDLE;
  });
  {
    std::lock_guard lock(s->mutex);
    s->spaces[key(made)] = SpaceUse{};
  }
  throwIfTestFault(inst, "after_create_space");
  spaceOwners().insert(key(made), s);
  undo.dismiss();
}

// The current time in the runtime's XrTime, for a frame whose predicted display time is 0 (or
// negative): every grasp needs a time to locate hands and targets at. 0 when the chain offers
// no conversion. Calls the runtime: no lock held.
XrTime layerClockTime(const InstanceState& inst) {
  XrTime t = 0;
  timespec now{};
  if (inst.next.xrConvertTimespecTimeToTimeKHR != nullptr &&
      clock_gettime(CLOCK_MONOTONIC, &now) == 0 &&
      inst.next.xrConvertTimespecTimeToTimeKHR(inst.handle, &now, &t) == XR_SUCCESS && t > 0)
    return t;
  return 0;
}

// The runtime's xrDestroySpace for a space this layer did not see created (an anchor of an
// extension it does not know): the next function of the instance that owns it. The layer cannot
// tell which instance that is; every instance's chain below holds the same function unless their
// apps enabled different layers, and then it refuses rather than guess.
XrResult destroyUnknownSpace(XrSpace space, const char* cmd) {
  PFN_xrDestroySpace next = nullptr;
  bool ambiguous = false;
  instances().forEach([&](const std::shared_ptr<InstanceState>& inst) {
    if (inst->next.xrDestroySpace == nullptr) return;
    if (next != nullptr && next != inst->next.xrDestroySpace) ambiguous = true;
    next = inst->next.xrDestroySpace;
  });
  if (next == nullptr) return logError(XR_ERROR_HANDLE_INVALID, cmd, "(space) is not valid");
  if (ambiguous)
    return logError(XR_ERROR_HANDLE_INVALID, cmd,
                    "(space) was not created through this layer, and the instances' chains "
                    "below it differ: the layer cannot tell which one owns it");
  return next(space);
}

}  // namespace

void endSessionWork(SessionState& s) {
  std::array<XrHandTrackerEXT, 2> internal{};
  std::unique_ptr<GraspSession> grasp;
  std::shared_ptr<DeferredMailbox> gpu;
  {
    std::lock_guard lock(s.mutex);
    internal = std::exchange(s.internalTrackers, {});
    grasp = std::move(s.grasp);
    gpu = std::move(s.gpu);
    s.ownQueue = false;
    s.targets.clear();
  }
  for (auto& shown : s.shown) shown.store(nullptr);
  for (XrHandTrackerEXT t : internal) {
    if (t != XR_NULL_HANDLE && s.instance->next.xrDestroyHandTrackerEXT != nullptr)
      s.instance->next.xrDestroyHandTrackerEXT(t);
  }
  // The layer's depth copies on the app's device end before it may go (after the session).
  endDepthCapture(s);
  // The worker stops what it runs within milliseconds and is joined here, on the thread that
  // destroys the session, holding no lock another call could need.
  grasp.reset();
  // Waits for the layer's builds in flight on the app's device and frees the layer's objects
  // there, while the device surely exists (the app destroys it after the session). A device
  // call on another thread that outlasts the mailbox's bound is not waited for (the session is
  // destroyed anyway): that thread frees the objects when its call returns.
  if (gpu != nullptr && !gpu->shutdown())
    SDFG_LOG_WARN("xrDestroySession",
                  "a GPU call on another thread still runs after %lld ms; the layer's objects on "
                  "the app's device are freed when it returns",
                  static_cast<long long>(DeferredMailbox::kClaimWait.count()));
}

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
  // From here on a failure (the worker thread, the GPU path, the map) gives the session back.
  std::shared_ptr<SessionState> s;
  Rollback undo([&] {
    if (s != nullptr) endSessionWork(*s);
    state->next.xrDestroySession(*session);
    *session = XR_NULL_HANDLE;
  });
  s = std::make_shared<SessionState>();
  s->handle = *session;
  s->instance = state;
  if (const auto* vk = findInChain<const XrGraphicsBindingVulkanKHR>(
          info->next, XR_TYPE_GRAPHICS_BINDING_VULKAN_KHR)) {
    s->vulkan = true;
    s->vulkanBinding = *vk;
    s->vulkanBinding.next = nullptr;
  }
  if (depthSceneWanted(*s)) {
    s->depth = std::make_unique<SessionDepth>();
  } else if (!s->vulkan && state->appDepthLayer &&
             state->config.depthScene != Config::DepthScene::off) {
    // docs/depth.md says what OpenGL, D3D11 and D3D12 sessions would take.
    for (XrStructureType t :
         {XR_TYPE_GRAPHICS_BINDING_OPENGL_WIN32_KHR, XR_TYPE_GRAPHICS_BINDING_OPENGL_XLIB_KHR,
          XR_TYPE_GRAPHICS_BINDING_OPENGL_XCB_KHR, XR_TYPE_GRAPHICS_BINDING_OPENGL_WAYLAND_KHR,
          XR_TYPE_GRAPHICS_BINDING_D3D11_KHR, XR_TYPE_GRAPHICS_BINDING_D3D12_KHR})
      if (countInChain(info->next, t) > 0) {
        SDFG_LOG_INFO(cmd,
                      "the depth scene reads Vulkan sessions only: this session's depth is "
                      "not read");
        break;
      }
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
  throwIfTestFault(*state, "after_create_session");
  sessions().insert(key(*session), s);
  undo.dismiss();
  return r;
  SDFG_ENTRY_END(cmd)
}

XrResult XRAPI_CALL SdfgXrDestroySession(XrSession session) {
  constexpr const char* cmd = "xrDestroySession";
  SDFG_ENTRY_BEGIN
  auto s = sessions().find(key(session));
  if (s == nullptr) return logError(XR_ERROR_HANDLE_INVALID, cmd, "(session) is not valid");
  // The layer's work ends first, here and with no lock held (docs/threading.md: within tens of
  // milliseconds, plus the wait for the layer's GPU builds in flight); nothing of the layer runs
  // for this session after this call.
  endSessionWork(*s);
  const XrResult r = s->instance->next.xrDestroySession(session);
  if (XR_SUCCEEDED(r)) {
    // Children go with the session: its trackers, targets and spaces.
    trackers().eraseIf([&](const TrackerState& t) { return t.session.lock() == s; });
    targets().eraseIf([&](const TargetState& t) { return t.session.lock() == s; });
    spaceOwners().eraseIf([&](const SessionState& owner) { return &owner == s.get(); });
    swapchains().eraseIf([&](const SwapchainState& sc) { return sc.session.lock() == s; });
    sessions().erase(key(session));
    s->instance->events.dropSession(session);  // its grasp events would name a dead handle
  } else {
    SDFG_LOG_WARN(cmd,
                  "the runtime refused to destroy the session (%d); the layer no longer "
                  "grasps in it",
                  int(r));
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
      XrTime time = frameState->predictedDisplayTime;
      if (time <= 0) time = layerClockTime(*s->instance);
      bool sayNoTime = false;
      {
        std::lock_guard lock(s->mutex);
        s->predictedTime = time;
        sayNoTime = time <= 0 && !std::exchange(s->noTimeLogged, true);
      }
      if (sayNoTime)
        SDFG_LOG_WARN(cmd,
                      "the runtime predicts no display time and offers no "
                      "XR_KHR_convert_timespec_time: no grasps in this session");
      updateInputAtFrame(*s);
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
  if (XR_SUCCEEDED(r)) rememberSpace(s, space);
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
  if (XR_SUCCEEDED(r)) rememberSpace(s, space);
  return r;
  SDFG_ENTRY_END(cmd)
}

XrResult XRAPI_CALL SdfgXrDestroySpace(XrSpace space) {
  constexpr const char* cmd = "xrDestroySpace";
  SDFG_ENTRY_BEGIN
  auto s = spaceOwners().find(key(space));
  if (s == nullptr) return destroyUnknownSpace(space, cmd);
  // No new use of the space starts once it is dying; this call waits for the uses in flight (a
  // grab update on another thread locating a target placed in it: one xrLocateSpace), so the
  // layer never passes the space down after the app destroyed it. Targets placed in it stop
  // taking part until they are placed again, and a hand holding one lets go. The wait has a
  // bound: a runtime whose xrLocateSpace does not return must not hang the app's destroy too.
  std::vector<uint64_t> unplaced;
  std::optional<SpaceUse> record;
  bool waitedOut = false;
  {
    std::unique_lock lock(s->mutex);
    auto use = s->spaces.find(key(space));
    if (use != s->spaces.end()) {
      use->second.dying = true;
      waitedOut = !s->spaceReleased.wait_for(lock, kSpaceUseWait, [&] {
        auto u = s->spaces.find(key(space));
        return u == s->spaces.end() || u->second.users == 0;
      });
    }
    for (const auto& [id, t] : s->targets) {
      if (!t->placed || t->space != space) continue;
      unplaceTarget(*s, *t);
      unplaced.push_back(id);
    }
    if (s->grasp != nullptr) {
      for (Hand hand : {Hand::left, Hand::right}) {
        const HandGrasp& g = s->grasp->grasp(hand);
        if (!g.holding || std::find(unplaced.begin(), unplaced.end(), g.target) == unplaced.end())
          continue;
        const bool wasGrasping = g.holdsTarget();
        const uint64_t wasTarget = g.target;
        s->grasp->release(hand);
        noteGraspChange(*s, hand, wasGrasping, wasTarget);
      }
      publishShownHands(*s);
    }
    // Forgotten before the call down: once the runtime has destroyed the space, a space another
    // thread creates may get the same handle, and must neither find this record nor lose its own.
    if (auto u = s->spaces.find(key(space)); u != s->spaces.end()) {
      record = u->second;
      s->spaces.erase(u);
    }
  }
  spaceOwners().erase(key(space));
  if (waitedOut)
    SDFG_LOG_WARN(cmd,
                  "the layer's xrLocateSpace on this space did not return within %lld s; the "
                  "space is destroyed anyway",
                  static_cast<long long>(kSpaceUseWait.count()));
  if (!unplaced.empty())
    SDFG_LOG_INFO(cmd,
                  "%zu grasp target(s) were placed in this space; they take no part until placed "
                  "again",
                  unplaced.size());
  const XrResult r = s->instance->next.xrDestroySpace(space);
  if (XR_FAILED(r) && record) {
    // Still alive: it may be used again (its targets stay unplaced).
    record->dying = false;
    record->users = 0;
    {
      std::lock_guard lock(s->mutex);
      s->spaces.emplace(key(space), *record);
    }
    spaceOwners().insert(key(space), s);
  }
  return r;
  SDFG_ENTRY_END(cmd)
}

}  // namespace sdfg::layer
