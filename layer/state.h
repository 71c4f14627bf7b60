// Per-instance, per-session and per-object state of the layer, in handle-keyed maps behind
// mutexes. Lookups on app input return null for an unknown handle; the caller answers
// XR_ERROR_HANDLE_INVALID. Objects are shared_ptr so a call in flight keeps what it uses alive
// while another thread destroys the handle.
//
// Locks (docs/threading.md): none is ever held across a call into the runtime, into Vulkan or
// into the layer's log (whose debug-utils sink calls the runtime). A call gathers what it needs
// from the runtime first, locks only to hand it over, and publishes what other threads read.
#pragma once

#include <array>
#include <atomic>
#include <condition_variable>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <unordered_map>
#include <vector>

#include "base/published.h"
#include "config.h"
#include "depth_capture.h"
#include "dispatch.h"
#include "events.h"
#include "grasp/grasp_session.h"
#include "grasp/shown_hand.h"
#include "hand/hand_synthesis.h"
#include "hand_offset.h"
#include "sdf/deferred_mailbox.h"
#include "xr_includes.h"

namespace sdfg::layer {

inline constexpr const char* kLayerName = "XR_APILAYER_SDFG_autograsp";

template <class H>
uint64_t key(H handle) {
  if constexpr (std::is_pointer_v<H>)
    return reinterpret_cast<uint64_t>(handle);
  else
    return static_cast<uint64_t>(handle);
}

template <class H>
H fromKey(uint64_t value) {
  if constexpr (std::is_pointer_v<H>)
    return reinterpret_cast<H>(value);
  else
    return static_cast<H>(value);
}

// The handle the app sees for an engine target id: the id itself (the layer's targets are keyed
// by their handles), XR_GRASP_TARGET_DEPTH_SCENE_SDFG for either hand's depth scene.
inline XrGraspTargetSDFG appTarget(uint64_t id) {
  return GraspSession::isDepthTarget(id) ? XR_GRASP_TARGET_DEPTH_SCENE_SDFG
                                         : fromKey<XrGraspTargetSDFG>(id);
}

// Handles the layer makes itself (hand trackers it synthesizes, grasp targets): non-canonical
// x86_64 addresses, so they never equal a runtime's pointer-valued handle.
uint64_t newLayerHandle();

// Paths of one interaction profile the layer binds its input on.
struct ProfilePaths {
  XrPath profile = XR_NULL_PATH;
  XrPath squeeze[2] = {};
  XrPath grip[2] = {};
};

struct InstanceState {
  XrInstance handle = XR_NULL_HANDLE;
  PFN_xrGetInstanceProcAddr nextGipa = nullptr;
  NextDispatch next;
  Config config;

  // What the app enabled, and what the runtime offers.
  bool appAutoGrasp = false;
  bool appHandTracking = false;
  bool appMotionRange = false;
  bool appDebugUtils = false;
  bool runtimeHandTracking = false;
  // The runtime lists XR_EXT_hand_tracking but its system cannot track hands
  // (supportsHandTracking false, or it refused a tracker): the layer synthesizes the app's hands.
  std::atomic<bool> runtimeSystemLacksHands{false};
  bool runtimeMotionRange = false;
  // XR_KHR_convert_timespec_time was added below by the layer (the app did not enable it).
  bool layerAddedTimespec = false;
  // The layer answers XR_EXT_hand_tracking itself (app enabled it, the runtime lacks it).
  bool provideHandTracking = false;
  // XR_EXT_hand_tracking is enabled on the runtime (the app's, or added for grasping).
  bool downstreamHandTracking = false;
  // The app enabled XR_EXT_hand_joints_motion_range but the runtime lacks it: stripped, and its
  // struct unlinked from locate calls.
  bool stripMotionRange = false;
  // XR_EXT_hand_tracking_data_source: enabled by the app; taken by the runtime (it has hand
  // tracking and the extension), else answered by the layer (data_source.h).
  bool appDataSource = false;
  bool runtimeDataSource = false;
  // Any of the above: the layer intercepts. Otherwise it hands out the next layer's functions
  // and the app runs exactly as without it.
  bool active = false;

  // The layer's own input (squeeze value and grip pose per hand), merged into the app's.
  XrActionSet actionSet = XR_NULL_HANDLE;
  XrAction squeezeAction = XR_NULL_HANDLE;
  XrAction gripAction = XR_NULL_HANDLE;
  std::array<XrPath, 2> handPaths{};
  std::vector<ProfilePaths> profiles;     // resolved when the actions are created
  std::mutex inputMutex;                  // guards the fields below (never across a call down)
  std::set<XrPath> appSuggestedProfiles;  // profiles the app suggested bindings for

  // XR_KHR_vulkan_enable2: what the app's xrCreateVulkanInstanceKHR / xrCreateVulkanDeviceKHR
  // passed, and the queue the layer added to a device (see vulkan.cpp).
  bool appVulkan2 = false;
  // XR_KHR_composition_layer_depth: the app may chain its depth on projection views, which the
  // depth scene reads (depth_capture.h).
  bool appDepthLayer = false;
  struct ExtraQueue {
    uint32_t family = 0;
    uint32_t index = 0;
  };
  std::mutex vulkanMutex;                                              // guards the fields below
  std::unordered_map<uint64_t, PFN_vkGetInstanceProcAddr> vulkanGipa;  // by VkInstance
  VkInstance lastVulkanInstance = VK_NULL_HANDLE;
  std::unordered_map<uint64_t, ExtraQueue> extraQueues;  // by VkDevice

  // XR_SDFG_auto_grasp version 2: the layer's events waiting for xrPollEvent (events.cpp).
  EventQueue events;
};

struct TargetState;

// A reference or action space the app created on a session, as the layer tracks it.
struct SpaceUse {
  int users = 0;       // the layer's calls that pass it down right now (xrLocateSpace)
  bool dying = false;  // xrDestroySpace is under way: no new use may start
  int targets = 0;     // targets placed in it: located once per frame while there are any
};

struct SessionState {
  XrSession handle = XR_NULL_HANDLE;
  std::shared_ptr<InstanceState> instance;
  bool vulkan = false;  // created with a Vulkan binding
  XrGraphicsBindingVulkanKHR vulkanBinding{};

  // Guards everything below but `shown`. Held for copies and the engine's bookkeeping
  // (microseconds), never across a call into the runtime, Vulkan or the log.
  std::mutex mutex;
  // The spaces the app created on this session. xrDestroySpace marks one dying and waits on
  // `spaceReleased` until no call of the layer uses it any more, then passes the destroy down:
  // the layer never hands a destroyed space to the runtime.
  std::map<uint64_t, SpaceUse> spaces;
  std::condition_variable spaceReleased;
  bool attached = false;  // the layer's action set is attached (with the app's, or alone)
  // attach_alone: the app attached no action sets by a frame with synthesized trackers, so the
  // layer attached its set alone (input.cpp) and syncs it in xrWaitFrame; tried once.
  bool selfAttached = false;
  bool selfAttaching = false;  // a thread is attaching it now (without the lock)
  bool selfAttachFailed = false;
  bool waitingForAttachLogged = false;  // said once: synthesized hands wait for the app's attach
  bool syncRefusedLogged = false;       // said once: a sync with the layer's set was refused
  bool appAttached = false;     // the app's own sets are attached (with or without the layer's)
  int synthesizedTrackers = 0;  // live synthesized trackers the app made on this session
  // The runtime refused the layer's own hand tracker for a hand: remembered, never retried.
  std::array<bool, 2> internalTrackerRefused{};
  std::array<bool, 2> internalTrackerCreating{};  // a thread is asking the runtime for one now
  // Said once: the runtime's display time is unusable and the layer cannot convert one.
  bool noTimeLogged = false;
  std::array<XrSpace, 2> gripSpaces{};
  XrSpace localSpace = XR_NULL_HANDLE;
  // From the last xrWaitFrame; where the runtime predicts no time (0, as Monado's headless
  // sessions), the current time through XR_KHR_convert_timespec_time.
  XrTime predictedTime = 0;
  std::array<float, 2> squeeze{};
  std::array<XrHandTrackerEXT, 2> internalTrackers{};  // the layer's own, on the runtime
  std::unique_ptr<GraspSession> grasp;
  // The Vulkan backend behind its mailbox (null: CPU only): the engine records builds on it
  // under `mutex`, pumpGpu() does the device calls with no lock held. Whether it has a queue of
  // its own.
  std::shared_ptr<DeferredMailbox> gpu;
  bool ownQueue = false;
  // Array targets build on the device too (config gpu, device type); see makeVulkanBackend().
  bool gpuForArrayTargets = false;
  GraspSettings settings;
  std::unordered_map<uint64_t, std::shared_ptr<TargetState>> targets;
  HandOffsets offsets;  // the hands' offsets off their tracked poses (hand_offset.h)

  // The depth scene's capture (depth_capture.h); null when the session cannot have one.
  std::unique_ptr<SessionDepth> depth;

  // What each hand shows as of the last grab update (left, right): xrLocateHandJointsEXT draws
  // it without taking `mutex`, so a render thread never waits for the main thread's update.
  std::array<Published<ShownHand>, 2> shown;
};

struct TrackerState {
  uint64_t handle = 0;  // what the app holds
  std::weak_ptr<SessionState> session;
  Hand hand = Hand::left;
  XrHandTrackerEXT runtimeHandle = XR_NULL_HANDLE;  // null: synthesized by the layer
  // XR_EXT_hand_tracking_data_source sources the app accepts (data_source.h); both by default.
  bool allowUnobstructed = true;
  bool allowController = true;
};

struct TargetState {
  uint64_t handle = 0;
  std::weak_ptr<SessionState> session;
  // Its placement (guarded by the session's mutex). `placed` is false once the app destroyed
  // `space`: the target takes no part (it is never located, a hand holding it lets go) until
  // xrSetGraspTargetPlacementSDFG places it again; xrGetGraspTargetStateSDFG says so.
  XrSpace space = XR_NULL_HANDLE;
  XrPosef pose{};
  bool placed = true;
  bool shape = false;  // an analytic shape (version 3): no vertices to update
  uint32_t vertexCount = 0;
  uint32_t indexCount = 0;
  bool deviceBuffers = false;  // the mesh is the app's Vulkan buffers
};

// A handle-keyed map behind a mutex. No value is destroyed while the mutex is held: the last
// reference to a session may end its worker, which must not happen under a lock every call
// takes.
template <class T>
class HandleMap {
 public:
  void insert(uint64_t handle, std::shared_ptr<T> value) {
    std::lock_guard lock(mutex_);
    map_[handle].swap(value);  // a value it replaces goes with `value`, after the unlock
  }
  std::shared_ptr<T> find(uint64_t handle) const {
    std::lock_guard lock(mutex_);
    auto it = map_.find(handle);
    return it == map_.end() ? nullptr : it->second;
  }
  std::shared_ptr<T> erase(uint64_t handle) {
    std::lock_guard lock(mutex_);
    auto it = map_.find(handle);
    if (it == map_.end()) return nullptr;
    auto value = std::move(it->second);
    map_.erase(it);
    return value;
  }
  // Any entry (the 1.0.20 loader allows one instance at a time).
  std::shared_ptr<T> any() const {
    std::lock_guard lock(mutex_);
    return map_.empty() ? nullptr : map_.begin()->second;
  }
  template <class F>
  void forEach(F f) const {
    std::lock_guard lock(mutex_);
    for (const auto& kv : map_) f(kv.second);
  }
  template <class Pred>
  void eraseIf(Pred pred) {
    std::vector<std::shared_ptr<T>> erased;  // released after the unlock
    std::lock_guard lock(mutex_);
    for (auto it = map_.begin(); it != map_.end();) {
      if (pred(*it->second)) {
        erased.push_back(std::move(it->second));
        it = map_.erase(it);
      } else {
        ++it;
      }
    }
  }

 private:
  mutable std::mutex mutex_;
  std::unordered_map<uint64_t, std::shared_ptr<T>> map_;
};

HandleMap<InstanceState>& instances();
HandleMap<SessionState>& sessions();
HandleMap<TrackerState>& trackers();
HandleMap<TargetState>& targets();
// Space -> owning session, for spaces the app created through this layer.
HandleMap<SessionState>& spaceOwners();
// The app's swapchains (depth_capture.h).
HandleMap<SwapchainState>& swapchains();

// Maps a core Status to the XrResult the extension returns.
XrResult toXrResult(Status status);

// Pose conversions between OpenXR and the core.
Pose toPose(const XrPosef& p);
XrPosef toXr(const Pose& p);
bool isUnitQuaternion(const XrQuaternionf& q);
bool isFinitePose(const XrPosef& p);

// The 32-bit value of an enum field in the app's memory, read as an integer. Loading an enum
// object that holds a value outside its type's range (hand = -1) is undefined behaviour, and an
// out-of-range value is exactly what the checks look for: they compare this instead.
template <class E>
int32_t rawEnum(const E& field) {
  static_assert(std::is_enum_v<E> && sizeof(E) == sizeof(int32_t));
  int32_t value;
  std::memcpy(&value, &field, sizeof value);
  return value;
}

// The longest `next` chain the layer walks. Real chains hold a handful of structs; a longer one
// is a cycle (a struct whose `next` points back into the chain) or garbage, and following it
// would hang the app's thread.
inline constexpr size_t kMaxChainLength = 32;

// The number of structs on `chain`, or -1 when it has more than kMaxChainLength (a cycle or an
// absurd length; the extension answers XR_ERROR_VALIDATION_FAILURE).
inline int chainLength(const void* chain) {
  int n = 0;
  for (auto* p = static_cast<const XrBaseInStructure*>(chain); p != nullptr; p = p->next) {
    if (++n > int(kMaxChainLength)) return -1;
  }
  return n;
}

// How many structs of `type` a chain holds (at most kMaxChainLength are looked at).
inline int countInChain(const void* chain, XrStructureType type) {
  int n = 0;
  size_t walked = 0;
  for (auto* p = static_cast<const XrBaseInStructure*>(chain);
       p != nullptr && walked < kMaxChainLength; p = p->next, ++walked) {
    if (rawEnum(p->type) == int32_t(type)) ++n;
  }
  return n;
}

// Finds a struct of `type` in a `next` chain, looking at kMaxChainLength structs at most, so a
// cyclic chain cannot hang the call (beyond that the struct counts as absent).
template <class T, class Base>
T* findInChain(Base* chain, XrStructureType type) {
  size_t walked = 0;
  for (auto* p = reinterpret_cast<XrBaseOutStructure*>(
           const_cast<void*>(static_cast<const void*>(chain)));
       p != nullptr && walked < kMaxChainLength; p = p->next, ++walked) {
    if (rawEnum(p->type) == int32_t(type)) return reinterpret_cast<T*>(p);
  }
  return nullptr;
}

// Grasp settings from the config (solver name resolved: "default" -> "ours" when built in,
// else "paper").
GraspSettings settingsFromConfig(const Config& config);
std::string resolveSolverName(const std::string& name);

// grasp_frame.cpp: the layer's grab update for both hands: after a sync of its action set (the
// app's xrSyncActions, or xrWaitFrame for a session the layer attached alone), or in xrWaitFrame
// without actions while its set is not attached. Gathers the squeeze (when the set is attached)
// and the hand and target poses from the runtime with no lock held, then hands them to the engine
// under the session's lock and publishes what each hand shows. Takes no lock on entry.
void syncGrasps(SessionState& session, const char* cmd);
// Publishes what each hand shows now (the caller holds session.mutex): after each grab update,
// and when a call lets a hand go at once (its target or the target's space destroyed).
void publishShownHands(SessionState& session);
// input.cpp, from xrWaitFrame: makes the layer's LOCAL space (every session, at its first frame),
// attaches the layer's set alone where attach_alone allows it, and runs the frame's grab update
// where no app sync will (a set the layer attached alone, or none attached). Takes no lock on
// entry.
void updateInputAtFrame(SessionState& session);

// vulkan.cpp: the Vulkan SDF backend for a session created with a Vulkan binding (null when the
// layer is built without it, the config says gpu = false, or the device cannot be used; the
// reason is logged): the engine's side of its mailbox. Sets session.gpu and session.ownQueue.
std::unique_ptr<DeferredSdfBackend> makeVulkanBackend(SessionState& session);
#if SDFG_LAYER_VULKAN
// vulkan.cpp: the session's Vulkan binding as the engine borrows it, with the app's loader entry
// point (enable2: what the app passed for its instance; enable: the loader in the process; null
// when there is none).
VulkanDevice appVulkanDevice(SessionState& session);
#endif
// Does the session's GPU calls (DeferredMailbox::pump): `inFrame` inside xrBeginFrame /
// xrEndFrame (the app's queue is free), else only builds for the layer's own queue. Takes no
// lock on entry, and none across the device calls; a pump running on another thread is not
// waited for.
void pumpGpu(SessionState& session, bool inFrame);

// session.cpp: ends the layer's work on a session, on the calling thread and with no lock held:
// its trackers on the runtime, its worker (stopped and joined: docs/threading.md gives the
// bound), its GPU path (waits for the layer's builds in flight, then frees its objects on the
// app's device). Calls after it find no engine and pass through.
void endSessionWork(SessionState& session);

}  // namespace sdfg::layer

// The catch-all every entry point wraps its body in: no exception crosses the C ABI.
#define SDFG_ENTRY_BEGIN try {
#define SDFG_ENTRY_END(cmd)                                                             \
  }                                                                                     \
  catch (const std::bad_alloc&) {                                                       \
    return ::sdfg::layer::logError(XR_ERROR_OUT_OF_MEMORY, cmd, "out of memory");       \
  }                                                                                     \
  catch (const std::exception& e) {                                                     \
    return ::sdfg::layer::logError(XR_ERROR_RUNTIME_FAILURE, cmd, "%s", e.what());      \
  }                                                                                     \
  catch (...) {                                                                         \
    return ::sdfg::layer::logError(XR_ERROR_RUNTIME_FAILURE, cmd, "unknown exception"); \
  }
