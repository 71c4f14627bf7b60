// The runtime's only exported symbol (loader negotiation), xrGetInstanceProcAddr, the handle
// table and the error helper. Every command goes through Entry: one global lock and a
// catch-all, so no exception crosses the C ABI.
#include <chrono>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <string>
#include <string_view>
#include <thread>

#include "entry_points.h"

namespace sdfg::mock {
namespace {

std::mutex& globalMutex() {
  static std::mutex m;
  return m;
}

std::unordered_map<uint64_t, Object*>& handleTable() {
  static std::unordered_map<uint64_t, Object*> table;
  return table;
}

template <auto Impl>
struct Entry;

template <class... A, XrResult (*Impl)(A...)>
struct Entry<Impl> {
  static CallGate& gate() {
    static CallGate g;
    return g;
  }
  static XrResult XRAPI_CALL call(A... args) noexcept {
    try {
      if (const XrResult failure = gate().failure(); failure != XR_SUCCESS) return failure;
      gate().pass();  // before the lock: a held call does not hold up the other commands
      std::lock_guard<std::mutex> lock(globalMutex());
      return Impl(args...);
    } catch (const std::bad_alloc&) {
      return XR_ERROR_OUT_OF_MEMORY;
    } catch (...) {
      return XR_ERROR_RUNTIME_FAILURE;
    }
  }
};

// What must be enabled on the instance for a command to be handed out.
enum class Needs { global, core, vulkan, vulkan2, handTracking, timespec, test };

struct Command {
  const char* name;
  PFN_xrVoidFunction function;
  Needs needs;
  CallGate* gate;
};

XrResult getInstanceProcAddr(XrInstance instance, const char* name, PFN_xrVoidFunction* function);

#define MOCK_COMMAND(xrName, impl, needs)                                                \
  Command {                                                                              \
#xrName, reinterpret_cast < PFN_xrVoidFunction>(&Entry <&impl>::call), Needs::needs, \
        &Entry < &impl> ::gate()                                                         \
  }

const std::vector<Command>& commands() {
  static const std::vector<Command> table = {
      MOCK_COMMAND(xrGetInstanceProcAddr, getInstanceProcAddr, global),
      MOCK_COMMAND(xrEnumerateInstanceExtensionProperties, enumerateInstanceExtensionProperties,
                   global),
      MOCK_COMMAND(xrEnumerateApiLayerProperties, enumerateApiLayerProperties, global),
      MOCK_COMMAND(xrCreateInstance, createInstance, global),
      MOCK_COMMAND(xrDestroyInstance, destroyInstance, core),
      MOCK_COMMAND(xrGetInstanceProperties, getInstanceProperties, core),
      MOCK_COMMAND(xrPollEvent, pollEvent, core),
      MOCK_COMMAND(xrResultToString, resultToString, core),
      MOCK_COMMAND(xrStructureTypeToString, structureTypeToString, core),
      MOCK_COMMAND(xrStringToPath, stringToPath, core),
      MOCK_COMMAND(xrPathToString, pathToString, core),
      MOCK_COMMAND(xrGetSystem, getSystem, core),
      MOCK_COMMAND(xrGetSystemProperties, getSystemProperties, core),
      MOCK_COMMAND(xrEnumerateViewConfigurations, enumerateViewConfigurations, core),
      MOCK_COMMAND(xrGetViewConfigurationProperties, getViewConfigurationProperties, core),
      MOCK_COMMAND(xrEnumerateViewConfigurationViews, enumerateViewConfigurationViews, core),
      MOCK_COMMAND(xrEnumerateEnvironmentBlendModes, enumerateEnvironmentBlendModes, core),
      MOCK_COMMAND(xrCreateSession, createSession, core),
      MOCK_COMMAND(xrDestroySession, destroySessionEntry, core),
      MOCK_COMMAND(xrBeginSession, beginSession, core),
      MOCK_COMMAND(xrEndSession, endSession, core),
      MOCK_COMMAND(xrRequestExitSession, requestExitSession, core),
      MOCK_COMMAND(xrWaitFrame, waitFrame, core),
      MOCK_COMMAND(xrBeginFrame, beginFrame, core),
      MOCK_COMMAND(xrEndFrame, endFrame, core),
      MOCK_COMMAND(xrEnumerateReferenceSpaces, enumerateReferenceSpaces, core),
      MOCK_COMMAND(xrCreateReferenceSpace, createReferenceSpace, core),
      MOCK_COMMAND(xrGetReferenceSpaceBoundsRect, getReferenceSpaceBoundsRect, core),
      MOCK_COMMAND(xrCreateActionSpace, createActionSpace, core),
      MOCK_COMMAND(xrLocateSpace, locateSpace, core),
      MOCK_COMMAND(xrDestroySpace, destroySpace, core),
      MOCK_COMMAND(xrLocateViews, locateViews, core),
      MOCK_COMMAND(xrCreateActionSet, createActionSet, core),
      MOCK_COMMAND(xrDestroyActionSet, destroyActionSet, core),
      MOCK_COMMAND(xrCreateAction, createAction, core),
      MOCK_COMMAND(xrDestroyAction, destroyAction, core),
      MOCK_COMMAND(xrSuggestInteractionProfileBindings, suggestInteractionProfileBindings, core),
      MOCK_COMMAND(xrAttachSessionActionSets, attachSessionActionSets, core),
      MOCK_COMMAND(xrGetCurrentInteractionProfile, getCurrentInteractionProfile, core),
      MOCK_COMMAND(xrSyncActions, syncActions, core),
      MOCK_COMMAND(xrGetActionStateBoolean, getActionStateBoolean, core),
      MOCK_COMMAND(xrGetActionStateFloat, getActionStateFloat, core),
      MOCK_COMMAND(xrGetActionStateVector2f, getActionStateVector2f, core),
      MOCK_COMMAND(xrGetActionStatePose, getActionStatePose, core),
      MOCK_COMMAND(xrEnumerateBoundSourcesForAction, enumerateBoundSourcesForAction, core),
      MOCK_COMMAND(xrGetInputSourceLocalizedName, getInputSourceLocalizedName, core),
      MOCK_COMMAND(xrApplyHapticFeedback, applyHapticFeedback, core),
      MOCK_COMMAND(xrStopHapticFeedback, stopHapticFeedback, core),
      MOCK_COMMAND(xrEnumerateSwapchainFormats, enumerateSwapchainFormats, core),
      MOCK_COMMAND(xrCreateSwapchain, createSwapchain, core),
      MOCK_COMMAND(xrDestroySwapchain, destroySwapchainEntry, core),
      MOCK_COMMAND(xrEnumerateSwapchainImages, enumerateSwapchainImages, core),
      MOCK_COMMAND(xrAcquireSwapchainImage, acquireSwapchainImage, core),
      MOCK_COMMAND(xrWaitSwapchainImage, waitSwapchainImage, core),
      MOCK_COMMAND(xrReleaseSwapchainImage, releaseSwapchainImage, core),
      MOCK_COMMAND(xrGetVulkanGraphicsRequirementsKHR, getVulkanGraphicsRequirements, vulkan),
      MOCK_COMMAND(xrGetVulkanInstanceExtensionsKHR, getVulkanInstanceExtensions, vulkan),
      MOCK_COMMAND(xrGetVulkanDeviceExtensionsKHR, getVulkanDeviceExtensions, vulkan),
      MOCK_COMMAND(xrGetVulkanGraphicsDeviceKHR, getVulkanGraphicsDevice, vulkan),
      MOCK_COMMAND(xrGetVulkanGraphicsRequirements2KHR, getVulkanGraphicsRequirements, vulkan2),
      MOCK_COMMAND(xrCreateVulkanInstanceKHR, createVulkanInstance, vulkan2),
      MOCK_COMMAND(xrCreateVulkanDeviceKHR, createVulkanDevice, vulkan2),
      MOCK_COMMAND(xrGetVulkanGraphicsDevice2KHR, getVulkanGraphicsDevice2, vulkan2),
      MOCK_COMMAND(xrConvertTimespecTimeToTimeKHR, convertTimespecTimeToTime, timespec),
      MOCK_COMMAND(xrConvertTimeToTimespecTimeKHR, convertTimeToTimespecTime, timespec),
      MOCK_COMMAND(xrCreateHandTrackerEXT, createHandTracker, handTracking),
      MOCK_COMMAND(xrDestroyHandTrackerEXT, destroyHandTracker, handTracking),
      MOCK_COMMAND(xrLocateHandJointsEXT, locateHandJoints, handTracking),
      MOCK_COMMAND(xrMockRuntimeSetScriptSDFG, mockSetScript, test),
      MOCK_COMMAND(xrMockRuntimeGetStatsSDFG, mockGetStats, test),
      MOCK_COMMAND(xrMockRuntimeGetDepthStatsSDFG, mockGetDepthStats, test),
      MOCK_COMMAND(xrMockRuntimeGetCaptureSDFG, mockGetCapture, test),
      MOCK_COMMAND(xrMockRuntimeGateCallsSDFG, mockGateCalls, test),
      MOCK_COMMAND(xrMockRuntimeGateStatsSDFG, mockGateStats, test),
  };
  return table;
}

bool enabled(const Instance& instance, Needs needs) {
  switch (needs) {
    case Needs::global:
    case Needs::core:
    case Needs::test:
      return true;
    case Needs::vulkan:
      return instance.extVulkan;
    case Needs::vulkan2:
      return instance.extVulkan2;
    case Needs::handTracking:
      return instance.extHandTracking;
    case Needs::timespec:
      return instance.extTimespec;
  }
  return false;
}

XrResult getInstanceProcAddr(XrInstance instance, const char* name, PFN_xrVoidFunction* function) {
  constexpr const char* cmd = "xrGetInstanceProcAddr";
  MOCK_VERIFY_NOT_NULL(cmd, function);
  *function = nullptr;
  MOCK_VERIFY_NOT_NULL(cmd, name);
  const Command* found = nullptr;
  for (const Command& c : commands()) {
    if (std::strcmp(c.name, name) == 0) found = &c;
  }
  if (instance == XR_NULL_HANDLE) {
    // Without an instance only the commands that create one may be fetched (spec 3.2).
    if (found == nullptr || found->needs != Needs::global)
      return fail(cmd, XR_ERROR_HANDLE_INVALID, "%s needs an instance", name);
    *function = found->function;
    return XR_SUCCESS;
  }
  const Instance* inst = lookup<Instance>(instance);
  if (inst == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "instance is not valid");
  if (found == nullptr || !enabled(*inst, found->needs))
    return fail(cmd, XR_ERROR_FUNCTION_UNSUPPORTED, "%s is not supported or not enabled", name);
  *function = found->function;
  return XR_SUCCESS;
}

}  // namespace

CallGate* findGate(const char* command) {
  if (command == nullptr) return nullptr;
  for (const Command& c : commands()) {
    if (std::strcmp(c.name, command) == 0) return c.gate;
  }
  return nullptr;
}

bool setCallFailures(const std::string& fault) {
  for (const Command& c : commands())
    if (c.gate != nullptr) c.gate->setFailure(XR_SUCCESS);
  constexpr std::string_view kPrefix = "fail:";
  if (fault.rfind(kPrefix, 0) != 0) return true;
  bool known = true;
  std::string_view rest = std::string_view(fault).substr(kPrefix.size());
  while (!rest.empty()) {
    const size_t comma = rest.find(',');
    const std::string name(rest.substr(0, comma));
    if (CallGate* gate = findGate(name.c_str()); gate != nullptr)
      gate->setFailure(XR_ERROR_RUNTIME_FAILURE);
    else
      known = false;
    rest = comma == std::string_view::npos ? std::string_view() : rest.substr(comma + 1);
  }
  return known;
}

void CallGate::pass() {
  if (!active_.load(std::memory_order_acquire)) return;
  uint32_t delay = 0;
  {
    std::unique_lock lock(mutex_);
    delay = delayMicroseconds_;
    ++waiting_;
    opened_.wait(lock, [&] { return !held_; });
  }
  if (delay > 0) std::this_thread::sleep_for(std::chrono::microseconds(delay));
  std::lock_guard lock(mutex_);
  --waiting_;
  ++passed_;
}

void CallGate::set(bool hold, uint32_t delayMicroseconds) {
  {
    std::lock_guard lock(mutex_);
    held_ = hold;
    delayMicroseconds_ = delayMicroseconds;
    active_.store(true, std::memory_order_release);
  }
  opened_.notify_all();
}

void CallGate::stats(uint32_t& waiting, uint64_t& passed) const {
  std::lock_guard lock(mutex_);
  waiting = waiting_;
  passed = passed_;
}

namespace {

// Loader structs, declared here because Debian's libopenxr-dev 1.0.20 ships no
// loader_interfaces.h. Layouts from OpenXR-SDK-Source release-1.0.20 src/common.
enum XrLoaderInterfaceStructs {
  XR_LOADER_INTERFACE_STRUCT_UNINTIALIZED = 0,
  XR_LOADER_INTERFACE_STRUCT_LOADER_INFO = 1,
  XR_LOADER_INTERFACE_STRUCT_RUNTIME_REQUEST = 3,
};
constexpr uint32_t kLoaderInfoStructVersion = 1;
constexpr uint32_t kRuntimeInfoStructVersion = 1;
constexpr uint32_t kLoaderRuntimeInterfaceVersion = 1;

}  // namespace

struct XrNegotiateLoaderInfo {
  XrLoaderInterfaceStructs structType;
  uint32_t structVersion;
  size_t structSize;
  uint32_t minInterfaceVersion;
  uint32_t maxInterfaceVersion;
  XrVersion minApiVersion;
  XrVersion maxApiVersion;
};

struct XrNegotiateRuntimeRequest {
  XrLoaderInterfaceStructs structType;
  uint32_t structVersion;
  size_t structSize;
  uint32_t runtimeInterfaceVersion;
  XrVersion runtimeApiVersion;
  PFN_xrGetInstanceProcAddr getInstanceProcAddr;
};
static_assert(sizeof(XrNegotiateLoaderInfo) == 40 && sizeof(XrNegotiateRuntimeRequest) == 40);

XrResult fail(const char* cmd, XrResult result, const char* fmt, ...) {
  static const bool log = [] {
    const char* v = std::getenv(SDFG_MOCK_ENV_LOG);
    return v != nullptr && std::strcmp(v, "1") == 0;
  }();
  if (log) {
    char message[512];
    va_list args;
    va_start(args, fmt);
    std::vsnprintf(message, sizeof message, fmt, args);
    va_end(args);
    std::fprintf(stderr, "[sdfg-mock-runtime] %s: %d: %s\n", cmd, int(result), message);
  }
  return result;
}

void registerHandle(Object* object) {
  // Starts high and odd-looking so a handle is never mistaken for a small integer or an index;
  // only ever grows, so no value is handed out twice in a process.
  static uint64_t next = 0x4D0C'0000'0000'0000ull;
  if (object->handle == 0) object->handle = ++next;
  handleTable()[object->handle] = object;
}

void unregisterHandle(const Object* object) {
  handleTable().erase(object->handle);
}

Object* findHandle(uint64_t handle) {
  const auto it = handleTable().find(handle);
  return it == handleTable().end() ? nullptr : it->second;
}

}  // namespace sdfg::mock

extern "C" __attribute__((visibility("default"))) XrResult xrNegotiateLoaderRuntimeInterface(
    const sdfg::mock::XrNegotiateLoaderInfo* loaderInfo,
    sdfg::mock::XrNegotiateRuntimeRequest* runtimeRequest) {
  using namespace sdfg::mock;
  if (loaderInfo == nullptr || runtimeRequest == nullptr) return XR_ERROR_INITIALIZATION_FAILED;
  if (loaderInfo->structType != XR_LOADER_INTERFACE_STRUCT_LOADER_INFO ||
      loaderInfo->structVersion != kLoaderInfoStructVersion ||
      loaderInfo->structSize != sizeof(XrNegotiateLoaderInfo))
    return XR_ERROR_INITIALIZATION_FAILED;
  if (runtimeRequest->structType != XR_LOADER_INTERFACE_STRUCT_RUNTIME_REQUEST ||
      runtimeRequest->structVersion != kRuntimeInfoStructVersion ||
      runtimeRequest->structSize != sizeof(XrNegotiateRuntimeRequest))
    return XR_ERROR_INITIALIZATION_FAILED;
  if (loaderInfo->minInterfaceVersion > kLoaderRuntimeInterfaceVersion ||
      loaderInfo->maxInterfaceVersion < kLoaderRuntimeInterfaceVersion)
    return XR_ERROR_INITIALIZATION_FAILED;
  if (XR_VERSION_MAJOR(loaderInfo->minApiVersion) > 1 ||
      XR_VERSION_MAJOR(loaderInfo->maxApiVersion) < 1)
    return XR_ERROR_INITIALIZATION_FAILED;
  runtimeRequest->runtimeInterfaceVersion = kLoaderRuntimeInterfaceVersion;
  runtimeRequest->runtimeApiVersion = XR_CURRENT_API_VERSION;
  runtimeRequest->getInstanceProcAddr = &Entry<&getInstanceProcAddr>::call;
  return XR_SUCCESS;
}
