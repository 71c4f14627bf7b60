// Internal state of the mock runtime: handle objects, the global handle table, error helpers
// and the entry points each concept file implements. Not for tests (they use
// mock_runtime_test.h through the loader).
//
// Threading: every entry point runs under one global mutex (see Entry in dispatch.cpp), so the
// objects below need no locks of their own. A call gate (tests) waits before that mutex.
#pragma once

// openxr_platform.h needs the Vulkan and timespec types declared first.
#include <time.h>
#include <vulkan/vulkan.h>

#define XR_USE_GRAPHICS_API_VULKAN
#define XR_USE_TIMESPEC
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>

#include <array>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "mock_runtime_test.h"
#include "script.h"

namespace sdfg::mock {

// ---- errors and logging ------------------------------------------------------------------

// Logs "cmd: message" on stderr when SDFG_MOCK_LOG=1 and returns `result`, so every error path
// is one return line that also says why.
XrResult fail(const char* cmd, XrResult result, const char* fmt, ...)
    __attribute__((format(gnu_printf, 3, 4)));  // C99 on MinGW too

// Single statements (do/while), so they are safe under an unbraced `if`.
#define MOCK_VERIFY_NOT_NULL(cmd, arg)                                                         \
  do {                                                                                         \
    if ((arg) == nullptr) return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "(" #arg ") is null"); \
  } while (false)

#define MOCK_VERIFY_TYPE(cmd, arg, expected)                                                       \
  do {                                                                                             \
    if ((arg) == nullptr) return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "(" #arg ") is null");     \
    if ((arg)->type != (expected))                                                                 \
      return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "(" #arg "->type) is %d, expected " #expected, \
                  int((arg)->type));                                                               \
  } while (false)

// ---- handles -------------------------------------------------------------------------------

enum class Kind : uint32_t {
  instance = 1,
  session,
  space,
  actionSet,
  action,
  swapchain,
  handTracker
};

// Base of every object behind a handle. The handle value is drawn from a process-wide counter
// at registration, never the object's address: a freed object's address is soon reused by the
// next allocation, and a test of "a destroyed handle is refused" must not pass because the
// destroyed handle happens to name a new object. Valid only while registered.
struct Object {
  explicit Object(Kind k) : kind(k) {}
  virtual ~Object() = default;
  Kind kind;
  uint64_t handle = 0;  // set by registerHandle; 0 before
};

// Gives `object` a handle value no object of this process had before, and registers it.
void registerHandle(Object* object);
void unregisterHandle(const Object* object);
Object* findHandle(uint64_t handle);

template <class T, class H>
T* lookup(H handle) {
  Object* o = findHandle(reinterpret_cast<uint64_t>(handle));
  return o != nullptr && o->kind == T::kKind ? static_cast<T*>(o) : nullptr;
}

template <class H>
H toHandle(const Object* o) {
  return reinterpret_cast<H>(o->handle);
}

// ---- objects -------------------------------------------------------------------------------

struct Session;
struct ActionSet;
struct Instance;

enum class HandTrackingMode { supported, unsupported, absent };

struct Action final : Object {
  static constexpr Kind kKind = Kind::action;
  Action() : Object(kKind) {}
  ActionSet* set = nullptr;
  std::string name, localizedName;
  XrActionType type = XR_ACTION_TYPE_BOOLEAN_INPUT;
  std::vector<XrPath> subactionPaths;
  bool alive = true;  // destroyed actions stay allocated: action spaces may still use them
};

struct ActionSet final : Object {
  static constexpr Kind kKind = Kind::actionSet;
  ActionSet() : Object(kKind) {}
  Instance* instance = nullptr;
  std::string name, localizedName;
  uint32_t priority = 0;
  std::vector<Action*> actions;
  bool attached = false;  // to some session: no more actions or suggestions
  bool alive = true;
};

// One suggested binding, resolved against the profile's input list.
struct Binding {
  Action* action = nullptr;
  XrPath path = XR_NULL_PATH;
  Target hand = kLeft;     // kHead also for /user/gamepad: neither is ever read
  std::string identifier;  // "squeeze", "grip", "thumbstick", "haptic"
  std::string component;   // "value", "click", "pose", "x", "" for a parent path
};

struct Options {
  uint64_t endAfterFrames = 0;  // 0: never
  std::string profile;          // simulated controller profile
  bool capture = false;
  std::string capturePath, reportPath;
  std::string fault;  // SDFG_MOCK_FAULT: one deliberate misbehaviour, for negative tests
};

struct Instance final : Object {
  static constexpr Kind kKind = Kind::instance;
  Instance() : Object(kKind) {}
  ~Instance() override;

  bool extVulkan = false, extVulkan2 = false, extHandTracking = false, extHeadless = false,
       extMotionRange = false, extTimespec = false;
  bool extDepth = false;  // XR_KHR_composition_layer_depth: depth infos are checked and counted
  HandTrackingMode handTracking = HandTrackingMode::supported;
  bool systemFetched = false;
  bool graphicsRequirementsQueried = false;
  VkPhysicalDevice lastPhysicalDevice = VK_NULL_HANDLE;  // from xrGetVulkanGraphicsDevice*
  VkInstance lastVkInstance = VK_NULL_HANDLE;            // ... and the instance it came from

  std::vector<std::string> pathStrings{""};  // index = XrPath; 0 is XR_NULL_PATH
  std::unordered_map<std::string, XrPath> pathIds;

  std::deque<XrEventDataBuffer> events;
  std::vector<std::unique_ptr<ActionSet>> actionSets;  // dead ones too, freed with the instance
  std::vector<std::unique_ptr<Action>> actions;
  std::map<XrPath, std::vector<Binding>> suggested;  // interaction profile -> bindings
  std::vector<std::unique_ptr<Session>> sessions;

  Script script;
  Options options;

  XrPath path(const std::string& s);                 // interns a well-formed path
  const std::string* pathString(XrPath path) const;  // null when unknown
};

// Runtime-owned Vulkan objects of one session; see vulkan.cpp. The deleter destroys them.
struct VulkanContext;
struct VulkanContextDeleter {
  void operator()(VulkanContext* context) const;
};
using VulkanContextPtr = std::unique_ptr<VulkanContext, VulkanContextDeleter>;

struct ActionValue {
  bool active = false;
  bool boolean = false;
  float value = 0;
  XrVector2f vector{0, 0};
  bool changed = false;
  XrTime lastChange = 0;
};
// Per action: state for /user/hand/left, /user/hand/right and for XR_NULL_PATH (both).
using ActionStates = std::array<ActionValue, 3>;

struct CapturedImage {
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> rgba;
};

struct Space final : Object {
  static constexpr Kind kKind = Kind::space;
  Space() : Object(kKind) {}
  Session* session = nullptr;
  bool isAction = false;
  XrReferenceSpaceType referenceType = XR_REFERENCE_SPACE_TYPE_LOCAL;
  Action* action = nullptr;
  XrPath subactionPath = XR_NULL_PATH;
  XrPosef offset{};
};

struct Swapchain final : Object {
  static constexpr Kind kKind = Kind::swapchain;
  Swapchain() : Object(kKind) {}
  ~Swapchain() override;
  Session* session = nullptr;
  XrSwapchainCreateInfo info{};
  uint32_t imageCount = 0;
  std::vector<VkImage> images;
  std::vector<VkDeviceMemory> memory;
  std::vector<bool> layoutReady;  // initial layout transition done
  std::deque<uint32_t> acquired;  // acquired, not yet released, oldest first
  bool waited = false;            // the oldest acquired image has been waited on
  uint32_t nextIndex = 0;
  int64_t lastReleased = -1;
  bool staticImageUsed = false;
};

struct HandTracker final : Object {
  static constexpr Kind kKind = Kind::handTracker;
  HandTracker() : Object(kKind) {}
  Session* session = nullptr;
  XrHandEXT hand = XR_HAND_LEFT_EXT;
};

struct Session final : Object {
  static constexpr Kind kKind = Kind::session;
  Session() : Object(kKind) {}
  ~Session() override;
  Instance* instance = nullptr;

  XrSessionState state = XR_SESSION_STATE_UNKNOWN;  // last state queued
  bool running = false;
  bool stopping = false;  // STOPPING queued, waiting for xrEndSession
  XrViewConfigurationType viewConfiguration = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;

  // xrWaitFrame calls not yet followed by their xrBeginFrame. More than one when the app
  // pipelines frames on two threads (the CTS's Timed_Pipelined_Frame_Submission): a real runtime
  // would block the later xrWaitFrame, this one (all calls serialized) lets it through and pairs
  // each xrBeginFrame with one of them.
  uint32_t framesWaitedPending = 0;
  bool frameBegun = false;
  bool profileChangePending = false;  // attached: INTERACTION_PROFILE_CHANGED at the next sync
  XrTime lastPredicted = 0;
  XrMockRuntimeStatsSDFG stats{};
  // XR_KHR_composition_layer_depth, in accepted frames only (xrMockRuntimeGetDepthStatsSDFG).
  uint32_t framesWithDepth = 0;  // frames with at least one depth info
  uint32_t depthInfos = 0;       // depth infos, all views and layers

  VulkanContextPtr vulkan;  // null: headless session
  std::vector<std::unique_ptr<Space>> spaces;
  std::vector<std::unique_ptr<Swapchain>> swapchains;
  std::vector<std::unique_ptr<HandTracker>> handTrackers;

  std::vector<ActionSet*> attachedSets;
  XrPath profile = XR_NULL_PATH;
  std::map<const Action*, ActionStates> actionStates;
  std::array<CapturedImage, 2> captures;

  uint64_t frame() const { return stats.framesEnded; }
  bool focused() const { return state == XR_SESSION_STATE_FOCUSED; }
};

// ---- call gates (xrMockRuntimeGateCallsSDFG) -------------------------------------------------

// One command's gate: every call passes it before the global lock; it can hold calls or delay
// them. Inactive (one atomic load per call) until a test first sets it.
class CallGate {
 public:
  void pass();
  void set(bool hold, uint32_t delayMicroseconds);
  void stats(uint32_t& waiting, uint64_t& passed) const;
  // SDFG_MOCK_FAULT=fail:<command>[,<command>...]: every call of the command returns `result`
  // without doing anything (XR_SUCCESS: as normal).
  void setFailure(XrResult result) { failure_.store(result, std::memory_order_release); }
  XrResult failure() const { return failure_.load(std::memory_order_acquire); }

 private:
  std::atomic<XrResult> failure_{XR_SUCCESS};
  std::atomic<bool> active_{false};
  mutable std::mutex mutex_;
  std::condition_variable opened_;
  bool held_ = false;
  uint32_t delayMicroseconds_ = 0;
  uint32_t waiting_ = 0;
  uint64_t passed_ = 0;
};

// The gate of a command by name (xrGetActionStateFloat...); null for an unknown name.
CallGate* findGate(const char* command);
// Sets every command's failure from an SDFG_MOCK_FAULT value ("fail:xrLocateSpace,..."; any other
// value clears them all). False when it names a command the runtime does not have.
bool setCallFailures(const std::string& fault);

// ---- shared helpers ------------------------------------------------------------------------

XrTime now();
void queueEvent(Instance& instance, const XrEventDataBuffer& event);
void queueState(Session& session, XrSessionState state);
void beginStopping(Session& session);   // queues the states down to STOPPING
void destroySession(Session* session);  // children first; unregisters everything
void destroySwapchain(Swapchain* swapchain);
void writeSessionFiles(Session& session);

// Two-call idiom for arrays: writes count, copies when capacity suffices.
template <class T>
XrResult twoCall(const char* cmd, uint32_t capacity, uint32_t* countOutput, T* out, const T* values,
                 uint32_t count) {
  MOCK_VERIFY_NOT_NULL(cmd, countOutput);
  *countOutput = count;
  if (capacity == 0) return XR_SUCCESS;
  if (capacity < count)
    return fail(cmd, XR_ERROR_SIZE_INSUFFICIENT, "capacity %u < %u", capacity, count);
  MOCK_VERIFY_NOT_NULL(cmd, out);
  for (uint32_t i = 0; i < count; ++i) out[i] = values[i];
  return XR_SUCCESS;
}
XrResult twoCallString(const char* cmd, uint32_t capacity, uint32_t* countOutput, char* buffer,
                       const std::string& value);

// Location of a space in LOCAL at the session's current frame; nullopt when untracked.
std::optional<XrPosef> spacePoseInLocal(const Session& session, const Space& space);
XrPosef headPose(const Session& session);
// Controller pose source ("grip" or "aim") of one hand; nullopt when tracking is lost.
std::optional<XrPosef> controllerPose(const Session& session, Target hand,
                                      const std::string& which);
bool handTracked(const Session& session, Target hand);

// Interaction profiles (interaction_profiles.cpp).
bool isKnownProfile(const std::string& profilePath);
// A profile with hand paths, which the simulated controllers can take.
bool isSimulatedProfile(const std::string& profilePath);
// Resolves a binding path for a profile; false when the profile has no such input or output.
bool resolveBinding(const std::string& profilePath, const std::string& bindingPath, Binding& out);
// Current value of a bound source from the script.
float readScalar(const Session& session, const Binding& binding, XrActionType type);
std::string profileLocalizedName(const std::string& profilePath);

// Action state helpers used by spaces.
bool actionActive(const Session& session, const Action* action, XrPath subactionPath);
const Binding* poseBinding(const Session& session, const Action* action, XrPath subactionPath);
int subactionSlot(const Instance& instance, XrPath path);  // 0, 1, 2 (null), -1 other/unknown

// Vulkan (vulkan.cpp).
XrResult createVulkanContext(const char* cmd, Instance& instance,
                             const XrGraphicsBindingVulkanKHR& binding, VulkanContextPtr& out);
void destroyVulkanContext(VulkanContext* context);
// The formats a Vulkan session offers, preferred first: fixed colour formats, then the depth
// formats its physical device can attach (found at session creation).
const std::vector<int64_t>& vulkanSwapchainFormats(const Session& session);
inline bool isDepthFormat(int64_t f) {
  return f == VK_FORMAT_D32_SFLOAT || f == VK_FORMAT_D16_UNORM ||
         f == VK_FORMAT_D24_UNORM_S8_UINT || f == VK_FORMAT_D32_SFLOAT_S8_UINT;
}
XrResult createVulkanImages(const char* cmd, Swapchain& swapchain);
void destroyVulkanImages(Swapchain& swapchain);
XrResult prepareVulkanImage(const char* cmd, Swapchain& swapchain, uint32_t index);
bool captureVulkanImage(Session& session, Swapchain& swapchain, uint32_t index, uint32_t layer,
                        CapturedImage& out);

}  // namespace sdfg::mock
