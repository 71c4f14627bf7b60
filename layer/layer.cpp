// Loader entry: negotiation, xrCreateApiLayerInstance, xrGetInstanceProcAddr routing,
// xrDestroyInstance and the layer's xrEnumerateInstanceExtensionProperties.
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "intercepts.h"
#include "loader_interfaces.h"
#include "log.h"
#include "rollback.h"
#include "state.h"
#include "test_fault.h"

namespace sdfg::layer {
namespace {

struct OwnExtension {
  const char* name;
  uint32_t version;
};
// Must match the manifests' instance_extensions.
constexpr OwnExtension kOwnExtensions[] = {
    {XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_SDFG_auto_grasp_SPEC_VERSION},
    {XR_EXT_HAND_TRACKING_EXTENSION_NAME, XR_EXT_hand_tracking_SPEC_VERSION},
    {XR_EXT_HAND_JOINTS_MOTION_RANGE_EXTENSION_NAME, XR_EXT_hand_joints_motion_range_SPEC_VERSION},
    {XR_EXT_HAND_TRACKING_DATA_SOURCE_EXTENSION_NAME,
     XR_EXT_hand_tracking_data_source_SPEC_VERSION},
};

XrResult XRAPI_CALL SdfgXrGetInstanceProcAddr(XrInstance, const char*, PFN_xrVoidFunction*);

bool contains(const std::vector<std::string>& list, const char* name) {
  for (const auto& s : list) {
    if (s == name) return true;
  }
  return false;
}

// Layers that add no instance extension and mishandle xrGetInstanceProcAddr(XR_NULL_HANDLE):
// core validation 1.0.20 answers it but prints "INTERNAL VALIDATION LAYER ERROR: Null handle
// passed to HandleInfoBase::get()" on stderr. Asking past them loses nothing.
constexpr const char* kSkipForQuery[] = {"XR_APILAYER_LUNARG_core_validation",
                                         "XR_APILAYER_LUNARG_api_dump"};

// The instance extensions the chain below offers, asked before creating the instance so that a
// runtime without hand tracking is never sent a list it refuses (a failed create makes core
// validation 1.0.20 print "INTERNAL VALIDATION LAYER ERROR: Null handle passed to
// HandleInfoBase::insert()", and some runtimes log it). Entries are asked nearest first; one in
// kSkipForQuery, or one that refuses the query, is stepped over, which loses only extensions
// that layer itself would add. The last entry is the loader's terminator, which asks the
// runtime. Nothing when no entry answers.
std::optional<std::vector<std::string>> chainExtensions(const XrApiLayerNextInfo* nextInfo) {
  constexpr const char* cmd = "xrCreateApiLayerInstance";
  for (const XrApiLayerNextInfo* info = nextInfo; info != nullptr; info = info->next) {
    // An entry's gipa is that of the layer named in the entry after it (the last entry's: the
    // loader's terminator).
    bool skip = false;
    for (const char* name : kSkipForQuery)
      skip |= info->next != nullptr &&
              std::strncmp(info->next->layerName, name, kMaxApiLayerNameSize) == 0;
    if (skip) continue;
    PFN_xrVoidFunction f = nullptr;
    if (info->nextGetInstanceProcAddr == nullptr ||
        info->nextGetInstanceProcAddr(XR_NULL_HANDLE, "xrEnumerateInstanceExtensionProperties",
                                      &f) != XR_SUCCESS ||
        f == nullptr)
      continue;
    auto enumerate = reinterpret_cast<PFN_xrEnumerateInstanceExtensionProperties>(f);
    uint32_t count = 0;
    XrResult r = enumerate(nullptr, 0, &count, nullptr);
    std::vector<XrExtensionProperties> props;
    if (XR_SUCCEEDED(r)) {
      props.assign(count, XrExtensionProperties{XR_TYPE_EXTENSION_PROPERTIES});
      r = enumerate(nullptr, count, &count, props.data());
    }
    SDFG_LOG_INFO(cmd, "extensions below '%.256s': %d (%u)",
                  info->next != nullptr ? info->next->layerName : "(runtime)", int(r), count);
    if (XR_FAILED(r)) continue;
    std::vector<std::string> names;
    for (uint32_t i = 0; i < count && i < props.size(); ++i)
      names.emplace_back(props[i].extensionName);
    return names;
  }
  return std::nullopt;
}

// Whether the head-mounted system below tracks hands (XrSystemHandTrackingPropertiesEXT). False
// also when it cannot be asked (no such system now): the layer then stays ready to synthesize.
bool systemHasHands(const InstanceState& state) {
  if (state.next.xrGetSystem == nullptr || state.next.xrGetSystemProperties == nullptr)
    return false;
  XrSystemGetInfo info{XR_TYPE_SYSTEM_GET_INFO};
  info.formFactor = XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY;
  XrSystemId system = XR_NULL_SYSTEM_ID;
  if (state.next.xrGetSystem(state.handle, &info, &system) != XR_SUCCESS) return false;
  XrSystemHandTrackingPropertiesEXT hands{XR_TYPE_SYSTEM_HAND_TRACKING_PROPERTIES_EXT};
  XrSystemProperties props{XR_TYPE_SYSTEM_PROPERTIES, &hands};
  if (state.next.xrGetSystemProperties(state.handle, system, &props) != XR_SUCCESS) return false;
  return hands.supportsHandTracking == XR_TRUE;
}

XrResult XRAPI_CALL SdfgXrCreateApiLayerInstance(const XrInstanceCreateInfo* info,
                                                 const XrApiLayerCreateInfo* layerInfo,
                                                 XrInstance* instance) {
  constexpr const char* cmd = "xrCreateApiLayerInstance";
  SDFG_ENTRY_BEGIN
  // The loader's structs, checked field by field like the Khronos layers do.
  if (layerInfo == nullptr ||
      layerInfo->structType != XR_LOADER_INTERFACE_STRUCT_API_LAYER_CREATE_INFO ||
      layerInfo->structVersion != kApiLayerCreateInfoStructVersion ||
      layerInfo->structSize != sizeof(XrApiLayerCreateInfo))
    return logError(XR_ERROR_INITIALIZATION_FAILED, cmd, "invalid XrApiLayerCreateInfo");
  const XrApiLayerNextInfo* nextInfo = layerInfo->nextInfo;
  if (nextInfo == nullptr ||
      nextInfo->structType != XR_LOADER_INTERFACE_STRUCT_API_LAYER_NEXT_INFO ||
      nextInfo->structVersion != kApiLayerNextInfoStructVersion ||
      nextInfo->structSize != sizeof(XrApiLayerNextInfo))
    return logError(XR_ERROR_INITIALIZATION_FAILED, cmd, "invalid XrApiLayerNextInfo");
  if (std::strncmp(nextInfo->layerName, kLayerName, kMaxApiLayerNameSize) != 0)
    return logError(XR_ERROR_INITIALIZATION_FAILED, cmd, "next info is for layer '%.256s'",
                    nextInfo->layerName);
  if (nextInfo->nextGetInstanceProcAddr == nullptr ||
      nextInfo->nextCreateApiLayerInstance == nullptr)
    return logError(XR_ERROR_INITIALIZATION_FAILED, cmd, "next layer functions are null");
  if (info == nullptr || instance == nullptr)
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(info) or (instance) is null");
  if (info->enabledExtensionCount > 0 && info->enabledExtensionNames == nullptr)
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(info->enabledExtensionNames) is null");

  auto state = std::make_shared<InstanceState>();
  state->config = loadConfig();
  setLogLevel(state->config.logLevel);
  state->nextGipa = nextInfo->nextGetInstanceProcAddr;

  std::vector<std::string> appExtensions;
  for (uint32_t i = 0; i < info->enabledExtensionCount; ++i) {
    const char* name = info->enabledExtensionNames[i];
    if (name == nullptr)
      return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(enabledExtensionNames[%u]) is null", i);
    appExtensions.emplace_back(name);
  }
  state->appAutoGrasp = contains(appExtensions, XR_SDFG_AUTO_GRASP_EXTENSION_NAME);
  state->appHandTracking = contains(appExtensions, XR_EXT_HAND_TRACKING_EXTENSION_NAME);
  state->appMotionRange = contains(appExtensions, XR_EXT_HAND_JOINTS_MOTION_RANGE_EXTENSION_NAME);
  state->appDataSource = contains(appExtensions, XR_EXT_HAND_TRACKING_DATA_SOURCE_EXTENSION_NAME);
  state->appDebugUtils = contains(appExtensions, XR_EXT_DEBUG_UTILS_EXTENSION_NAME);
  state->appVulkan2 = contains(appExtensions, XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME);
  state->appDepthLayer = contains(appExtensions, XR_KHR_COMPOSITION_LAYER_DEPTH_EXTENSION_NAME);
  const bool appTimespec = contains(appExtensions, XR_KHR_CONVERT_TIMESPEC_TIME_EXTENSION_NAME);

  // What the chain offers decides the list sent down. Only when nobody below answers the query
  // does the layer find out by trying, as HTCC does: the full list first, then without motion
  // range, then without hand tracking, each tried only when the chain refuses the previous one.
  const bool wantHandTracking = state->appHandTracking || state->appAutoGrasp;
  const std::optional<std::vector<std::string>> offered = chainExtensions(nextInfo);
  const bool offersHandTracking =
      !offered || contains(*offered, XR_EXT_HAND_TRACKING_EXTENSION_NAME);
  // Only a runtime that says it has the data source (and hand tracking) is sent it.
  const bool offersDataSource =
      offered && contains(*offered, XR_EXT_HAND_TRACKING_DATA_SOURCE_EXTENSION_NAME);
  const bool offersMotionRange =
      !offered || contains(*offered, XR_EXT_HAND_JOINTS_MOTION_RANGE_EXTENSION_NAME);
  // Grasping needs a time to locate the hands at. A runtime that predicts a display time of 0
  // (Monado's headless sessions) gives none, so the layer converts the clock itself where the
  // chain offers the conversion (it is added only when offered: it never costs a retry).
  state->layerAddedTimespec = wantHandTracking && !appTimespec && offered &&
                              contains(*offered, XR_KHR_CONVERT_TIMESPEC_TIME_EXTENSION_NAME);
  XrApiLayerCreateInfo downLayerInfo = *layerInfo;
  downLayerInfo.nextInfo = nextInfo->next;
  // Core validation 1.0.20 reports the runtime's refusal as XR_ERROR_INITIALIZATION_FAILED.
  auto refused = [](XrResult res) {
    return res == XR_ERROR_EXTENSION_NOT_PRESENT || res == XR_ERROR_INITIALIZATION_FAILED;
  };
  XrResult r = XR_ERROR_EXTENSION_NOT_PRESENT;
  for (int attempt = 0; attempt < 3 && refused(r); ++attempt) {
    const bool withMotionRange = attempt == 0;
    const bool withHandTracking = attempt < 2;
    if (attempt == 1 && !state->appMotionRange) continue;
    if (attempt == 2 && !wantHandTracking) break;
    // Lists the chain said it lacks are not tried at all.
    if (withMotionRange && state->appMotionRange && !offersMotionRange) continue;
    if (withHandTracking && wantHandTracking && !offersHandTracking) continue;
    state->runtimeHandTracking = withHandTracking;
    state->runtimeMotionRange = withMotionRange;
    state->provideHandTracking = state->appHandTracking && !withHandTracking;
    state->stripMotionRange = state->appMotionRange && !withMotionRange;
    state->downstreamHandTracking = withHandTracking && wantHandTracking;
    state->runtimeDataSource = state->appDataSource && withHandTracking && offersDataSource;
    // What goes down: the app's list without the layer's own extensions (the runtime would
    // answer XR_ERROR_EXTENSION_NOT_PRESENT), plus hand tracking when grasping wants it.
    std::vector<const char*> down;
    for (const std::string& name : appExtensions) {
      if (name == XR_SDFG_AUTO_GRASP_EXTENSION_NAME) continue;
      if (name == XR_EXT_HAND_TRACKING_EXTENSION_NAME) continue;
      if (name == XR_EXT_HAND_JOINTS_MOTION_RANGE_EXTENSION_NAME && !withMotionRange) continue;
      if (name == XR_EXT_HAND_TRACKING_DATA_SOURCE_EXTENSION_NAME && !state->runtimeDataSource)
        continue;
      down.push_back(name.c_str());
    }
    if (state->downstreamHandTracking) down.push_back(XR_EXT_HAND_TRACKING_EXTENSION_NAME);
    if (state->layerAddedTimespec) down.push_back(XR_KHR_CONVERT_TIMESPEC_TIME_EXTENSION_NAME);
    XrInstanceCreateInfo downInfo = *info;
    downInfo.enabledExtensionCount = uint32_t(down.size());
    downInfo.enabledExtensionNames = down.empty() ? nullptr : down.data();
    r = nextInfo->nextCreateApiLayerInstance(&downInfo, &downLayerInfo, instance);
    SDFG_LOG_INFO(cmd, "create with hand tracking %d, motion range %d: %d", withHandTracking,
                  withMotionRange, int(r));
  }
  if (XR_FAILED(r)) return r;
  // From here on a failure (the dispatch table, the layer's actions, the map) gives the instance
  // back: destroyed through the chain below, as the app would.
  const XrInstance made = *instance;
  const PFN_xrGetInstanceProcAddr nextGipa = state->nextGipa;
  Rollback undo([&] {
    clearDebugUtilsSink(made);
    PFN_xrVoidFunction destroy = nullptr;
    if (nextGipa(made, "xrDestroyInstance", &destroy) == XR_SUCCESS && destroy != nullptr)
      reinterpret_cast<PFN_xrDestroyInstance>(destroy)(made);
    *instance = XR_NULL_HANDLE;
  });
  state->handle = made;
  state->next.load(state->nextGipa, made);
  // A runtime may list hand tracking for a system that has no hands (Monado with controllers
  // only): then the layer synthesizes them. Asked now, because the routing is fixed when the
  // loader fills its dispatch table right after this call.
  if (state->appHandTracking && !state->provideHandTracking && state->config.synthesis &&
      !systemHasHands(*state)) {
    state->runtimeSystemLacksHands = true;
    SDFG_LOG_WARN(cmd,
                  "the runtime's system cannot track hands; the layer synthesizes them from "
                  "the controllers' grip pose and squeeze");
  }
  state->active = state->appAutoGrasp || state->provideHandTracking || state->stripMotionRange ||
                  state->runtimeSystemLacksHands ||
                  (state->appDataSource && !state->runtimeDataSource);
  if (state->appDebugUtils && state->next.xrSubmitDebugUtilsMessageEXT != nullptr)
    setDebugUtilsSink(*instance, state->next.xrSubmitDebugUtilsMessageEXT);
  if (state->active) createLayerActions(*state);
  SDFG_LOG_INFO(cmd,
                "instance %p: %s (auto_grasp %d, app hand tracking %d, runtime hand tracking %d, "
                "synthesized %d, system without hands %d)",
                static_cast<void*>(*instance), state->active ? "active" : "pass-through",
                state->appAutoGrasp, state->appHandTracking, state->runtimeHandTracking,
                state->provideHandTracking, bool(state->runtimeSystemLacksHands));
  throwIfTestFault(*state, "after_create_instance");
  instances().insert(key(made), std::move(state));
  undo.dismiss();
  return r;
  SDFG_ENTRY_END(cmd)
}

XrResult XRAPI_CALL SdfgXrDestroyInstance(XrInstance instance) {
  constexpr const char* cmd = "xrDestroyInstance";
  SDFG_ENTRY_BEGIN
  auto state = instances().find(key(instance));
  if (state == nullptr) return logError(XR_ERROR_HANDLE_INVALID, cmd, "(instance) is not valid");
  clearDebugUtilsSink(instance);
  // Sessions the app did not destroy go with the instance: the layer's work on each ends here,
  // on this thread and under no lock (the map's lock is only held to list them), GPU work first
  // while the app's Vulkan device surely exists.
  std::vector<std::shared_ptr<SessionState>> own;
  sessions().forEach([&](const std::shared_ptr<SessionState>& s) {
    if (s->instance == state) own.push_back(s);
  });
  for (const auto& s : own) endSessionWork(*s);
  const XrResult r = state->next.xrDestroyInstance(instance);
  if (XR_SUCCEEDED(r)) {
    // The instance took its sessions and their children with it.
    trackers().eraseIf([&](const TrackerState& t) {
      auto s = t.session.lock();
      return s == nullptr || s->instance == state;
    });
    targets().eraseIf([&](const TargetState& t) {
      auto s = t.session.lock();
      return s == nullptr || s->instance == state;
    });
    spaceOwners().eraseIf([&](const SessionState& s) { return s.instance == state; });
    sessions().eraseIf([&](const SessionState& s) { return s.instance == state; });
    instances().erase(key(instance));
  }
  return r;
  SDFG_ENTRY_END(cmd)
}

XrResult XRAPI_CALL SdfgXrEnumerateInstanceExtensionProperties(const char* layerName,
                                                               uint32_t capacity, uint32_t* count,
                                                               XrExtensionProperties* props) {
  constexpr const char* cmd = "xrEnumerateInstanceExtensionProperties";
  SDFG_ENTRY_BEGIN
  // Called only by layers above this one (the loader answers apps from the manifests). With this
  // layer's name: its own extensions. Without the chain below at hand, other names are not ours.
  if (layerName != nullptr && std::strcmp(layerName, kLayerName) != 0)
    return XR_ERROR_API_LAYER_NOT_PRESENT;
  if (count == nullptr)
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(propertyCountOutput) is null");
  const uint32_t n = uint32_t(std::size(kOwnExtensions));
  *count = n;
  if (capacity == 0) return XR_SUCCESS;
  if (capacity < n) return XR_ERROR_SIZE_INSUFFICIENT;
  if (props == nullptr) return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(properties) is null");
  for (uint32_t i = 0; i < n; ++i) {
    if (props[i].type != XR_TYPE_EXTENSION_PROPERTIES)
      return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(properties[%u].type) is wrong", i);
  }
  for (uint32_t i = 0; i < n; ++i) {
    std::strncpy(props[i].extensionName, kOwnExtensions[i].name, XR_MAX_EXTENSION_NAME_SIZE - 1);
    props[i].extensionName[XR_MAX_EXTENSION_NAME_SIZE - 1] = '\0';
    props[i].extensionVersion = kOwnExtensions[i].version;
  }
  return XR_SUCCESS;
  SDFG_ENTRY_END(cmd)
}

// Which interceptor answers a command, and when.
enum class Gate {
  always,        // whenever the instance is ours
  active,        // only when the layer is active on the instance, else the next layer's function
  autoGrasp,     // XR_SDFG_auto_grasp commands: only when the app enabled it
  handTracking,  // XR_EXT_hand_tracking commands: enabled by the app; ours when active
  vulkan2,       // XR_KHR_vulkan_enable2 commands: ours when active and the app enabled it
  timespec,      // XR_KHR_convert_timespec_time: the next layer's, unless only the layer enabled it
  events,        // xrPollEvent: ours when the app enabled XR_SDFG_auto_grasp (its events)
};

struct Route {
  const char* name;
  PFN_xrVoidFunction function;
  Gate gate;
};

#define SDFG_ROUTE(name, gate)                                       \
  Route {                                                            \
#name, reinterpret_cast < PFN_xrVoidFunction>(&Sdfg##name), gate \
  }

const Route kRoutes[] = {
    SDFG_ROUTE(XrGetInstanceProcAddr, Gate::always),
    SDFG_ROUTE(XrDestroyInstance, Gate::always),
    SDFG_ROUTE(XrPollEvent, Gate::events),
    SDFG_ROUTE(XrGetSystemProperties, Gate::active),
    SDFG_ROUTE(XrCreateSession, Gate::active),
    SDFG_ROUTE(XrDestroySession, Gate::active),
    SDFG_ROUTE(XrWaitFrame, Gate::active),
    SDFG_ROUTE(XrBeginFrame, Gate::active),
    SDFG_ROUTE(XrEndFrame, Gate::active),
    SDFG_ROUTE(XrCreateSwapchain, Gate::active),
    SDFG_ROUTE(XrDestroySwapchain, Gate::active),
    SDFG_ROUTE(XrEnumerateSwapchainImages, Gate::active),
    SDFG_ROUTE(XrAcquireSwapchainImage, Gate::active),
    SDFG_ROUTE(XrReleaseSwapchainImage, Gate::active),
    SDFG_ROUTE(XrCreateVulkanInstanceKHR, Gate::vulkan2),
    SDFG_ROUTE(XrCreateVulkanDeviceKHR, Gate::vulkan2),
    SDFG_ROUTE(XrCreateReferenceSpace, Gate::active),
    SDFG_ROUTE(XrCreateActionSpace, Gate::active),
    SDFG_ROUTE(XrDestroySpace, Gate::active),
    SDFG_ROUTE(XrSuggestInteractionProfileBindings, Gate::active),
    SDFG_ROUTE(XrAttachSessionActionSets, Gate::active),
    SDFG_ROUTE(XrSyncActions, Gate::active),
    SDFG_ROUTE(XrCreateHandTrackerEXT, Gate::handTracking),
    SDFG_ROUTE(XrDestroyHandTrackerEXT, Gate::handTracking),
    SDFG_ROUTE(XrLocateHandJointsEXT, Gate::handTracking),
    Route{"xrConvertTimespecTimeToTimeKHR", nullptr, Gate::timespec},
    Route{"xrConvertTimeToTimespecTimeKHR", nullptr, Gate::timespec},
    SDFG_ROUTE(XrCreateGraspTargetSDFG, Gate::autoGrasp),
    SDFG_ROUTE(XrDestroyGraspTargetSDFG, Gate::autoGrasp),
    SDFG_ROUTE(XrUpdateGraspTargetVerticesSDFG, Gate::autoGrasp),
    SDFG_ROUTE(XrSetGraspTargetPlacementSDFG, Gate::autoGrasp),
    SDFG_ROUTE(XrGetGraspStateSDFG, Gate::autoGrasp),
    SDFG_ROUTE(XrSetGraspOptionsSDFG, Gate::autoGrasp),
    SDFG_ROUTE(XrSetGraspTargetSettingsSDFG, Gate::autoGrasp),
    SDFG_ROUTE(XrGetGraspTargetStateSDFG, Gate::autoGrasp),
};

XrResult XRAPI_CALL SdfgXrGetInstanceProcAddr(XrInstance instance, const char* name,
                                              PFN_xrVoidFunction* function) {
  constexpr const char* cmd = "xrGetInstanceProcAddr";
  SDFG_ENTRY_BEGIN
  if (name == nullptr || function == nullptr)
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(name) or (function) is null");
  *function = nullptr;
  if (instance == XR_NULL_HANDLE) {
    // Before an instance exists only the global commands may be asked for.
    if (std::strcmp(name, "xrGetInstanceProcAddr") == 0) {
      *function = reinterpret_cast<PFN_xrVoidFunction>(&SdfgXrGetInstanceProcAddr);
      return XR_SUCCESS;
    }
    if (std::strcmp(name, "xrEnumerateInstanceExtensionProperties") == 0) {
      *function = reinterpret_cast<PFN_xrVoidFunction>(&SdfgXrEnumerateInstanceExtensionProperties);
      return XR_SUCCESS;
    }
    return XR_ERROR_HANDLE_INVALID;
  }
  auto state = instances().find(key(instance));
  if (state == nullptr) return logError(XR_ERROR_HANDLE_INVALID, cmd, "(instance) is not valid");
  for (const Route& route : kRoutes) {
    // Route names are "Xr<Command>"; commands are "xr<Command>".
    if (name[0] != 'x' || std::strcmp(name + 1, route.name + 1) != 0) continue;
    switch (route.gate) {
      case Gate::always:
        *function = route.function;
        return XR_SUCCESS;
      case Gate::active:
        if (state->active) {
          *function = route.function;
          return XR_SUCCESS;
        }
        break;
      case Gate::autoGrasp:
        if (!state->appAutoGrasp) return XR_ERROR_FUNCTION_UNSUPPORTED;
        *function = route.function;
        return XR_SUCCESS;
      case Gate::vulkan2:
        if (state->active && state->appVulkan2 && state->appAutoGrasp) {
          *function = route.function;
          return XR_SUCCESS;
        }
        break;
      case Gate::timespec:
        // Enabled below only for the layer's own clock: not the app's to call (spec 3.2).
        if (state->layerAddedTimespec) return XR_ERROR_FUNCTION_UNSUPPORTED;
        break;
      case Gate::events:
        if (state->active && state->appAutoGrasp) {
          *function = route.function;
          return XR_SUCCESS;
        }
        break;
      case Gate::handTracking:
        if (!state->appHandTracking) return XR_ERROR_FUNCTION_UNSUPPORTED;
        if (state->active) {
          *function = route.function;
          return XR_SUCCESS;
        }
        break;
    }
    break;
  }
  return state->nextGipa(instance, name, function);
  SDFG_ENTRY_END(cmd)
}

}  // namespace
}  // namespace sdfg::layer

// The one exported symbol.
extern "C" __attribute__((visibility("default"))) XrResult XRAPI_CALL
xrNegotiateLoaderApiLayerInterface(const sdfg::layer::XrNegotiateLoaderInfo* loaderInfo,
                                   const char* layerName,
                                   sdfg::layer::XrNegotiateApiLayerRequest* request) {
  using namespace sdfg::layer;
  constexpr const char* cmd = "xrNegotiateLoaderApiLayerInterface";
  SDFG_ENTRY_BEGIN
  if (loaderInfo == nullptr || loaderInfo->structType != XR_LOADER_INTERFACE_STRUCT_LOADER_INFO ||
      loaderInfo->structVersion != kLoaderInfoStructVersion ||
      loaderInfo->structSize != sizeof(XrNegotiateLoaderInfo))
    return logError(XR_ERROR_INITIALIZATION_FAILED, cmd, "invalid XrNegotiateLoaderInfo");
  if (request == nullptr || request->structType != XR_LOADER_INTERFACE_STRUCT_API_LAYER_REQUEST ||
      request->structVersion != kApiLayerInfoStructVersion ||
      request->structSize != sizeof(XrNegotiateApiLayerRequest))
    return logError(XR_ERROR_INITIALIZATION_FAILED, cmd, "invalid XrNegotiateApiLayerRequest");
  if (layerName == nullptr || std::strcmp(layerName, kLayerName) != 0)
    return logError(XR_ERROR_INITIALIZATION_FAILED, cmd, "asked for layer '%s'",
                    layerName == nullptr ? "(null)" : layerName);
  if (loaderInfo->minInterfaceVersion > kCurrentLoaderApiLayerVersion ||
      loaderInfo->maxInterfaceVersion < kCurrentLoaderApiLayerVersion)
    return logError(XR_ERROR_INITIALIZATION_FAILED, cmd, "loader interface %u..%u lacks %u",
                    loaderInfo->minInterfaceVersion, loaderInfo->maxInterfaceVersion,
                    kCurrentLoaderApiLayerVersion);
  // The layer is written against OpenXR 1.0.
  if (XR_VERSION_MAJOR(loaderInfo->minApiVersion) > 1 ||
      XR_VERSION_MAJOR(loaderInfo->maxApiVersion) < 1 ||
      loaderInfo->maxApiVersion < XR_MAKE_VERSION(1, 0, 0))
    return logError(XR_ERROR_INITIALIZATION_FAILED, cmd, "loader API range excludes 1.0");
  request->layerInterfaceVersion = kCurrentLoaderApiLayerVersion;
  request->layerApiVersion = XR_CURRENT_API_VERSION;
  request->getInstanceProcAddr = &SdfgXrGetInstanceProcAddr;
  request->createApiLayerInstance = &SdfgXrCreateApiLayerInstance;
  return XR_SUCCESS;
  SDFG_ENTRY_END(cmd)
}
