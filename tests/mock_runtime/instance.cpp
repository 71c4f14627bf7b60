// Instance: extensions, creation from the environment, events, paths, ToString functions and
// time conversion.
#include <openxr/openxr_reflection.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include "entry_points.h"

namespace sdfg::mock {
namespace {

std::unique_ptr<Instance>& theInstance() {
  static std::unique_ptr<Instance> instance;
  return instance;
}

HandTrackingMode handTrackingFromEnv() {
  const char* v = std::getenv(SDFG_MOCK_ENV_HAND_TRACKING);
  if (v == nullptr || std::strcmp(v, "1") == 0) return HandTrackingMode::supported;
  if (std::strcmp(v, "absent") == 0) return HandTrackingMode::absent;
  return HandTrackingMode::unsupported;
}

std::vector<XrExtensionProperties> offeredExtensions() {
  std::vector<XrExtensionProperties> list;
  auto add = [&](const char* name, uint32_t version) {
    XrExtensionProperties p{XR_TYPE_EXTENSION_PROPERTIES};
    std::snprintf(p.extensionName, sizeof p.extensionName, "%s", name);
    p.extensionVersion = version;
    list.push_back(p);
  };
  add(XR_KHR_VULKAN_ENABLE_EXTENSION_NAME, XR_KHR_vulkan_enable_SPEC_VERSION);
  add(XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME, XR_KHR_vulkan_enable2_SPEC_VERSION);
  add(XR_MND_HEADLESS_EXTENSION_NAME, XR_MND_headless_SPEC_VERSION);
  add(XR_KHR_CONVERT_TIMESPEC_TIME_EXTENSION_NAME, XR_KHR_convert_timespec_time_SPEC_VERSION);
  // Revision 6, the current one; the SDK headers here say 5, with the same struct.
  add(XR_KHR_COMPOSITION_LAYER_DEPTH_EXTENSION_NAME, 6);
  if (handTrackingFromEnv() != HandTrackingMode::absent) {
    add(XR_EXT_HAND_TRACKING_EXTENSION_NAME, XR_EXT_hand_tracking_SPEC_VERSION);
    add(XR_EXT_HAND_JOINTS_MOTION_RANGE_EXTENSION_NAME,
        XR_EXT_hand_joints_motion_range_SPEC_VERSION);
  }
  return list;
}

// Spec 6.1 "well-formed path string": starts with '/', lowercase letters, digits, '-', '_',
// '.', no empty, "." or ".." component, no trailing '/'.
bool wellFormedPath(const char* s) {
  const size_t n = strnlen(s, XR_MAX_PATH_LENGTH);
  if (n == 0 || n >= XR_MAX_PATH_LENGTH || s[0] != '/' || s[n - 1] == '/') return false;
  size_t componentStart = 1;
  for (size_t i = 1; i <= n; ++i) {
    const char c = s[i];
    if (i == n || c == '/') {
      const std::string_view component(s + componentStart, i - componentStart);
      if (component.empty() || component == "." || component == "..") return false;
      componentStart = i + 1;
      continue;
    }
    const bool ok =
        (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' || c == '_' || c == '.';
    if (!ok) return false;
  }
  return true;
}

}  // namespace

XrTime now() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return XrTime(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

void queueEvent(Instance& instance, const XrEventDataBuffer& event) {
  instance.events.push_back(event);
}

void queueState(Session& session, XrSessionState state) {
  XrEventDataBuffer buffer{XR_TYPE_EVENT_DATA_BUFFER};
  auto* e = reinterpret_cast<XrEventDataSessionStateChanged*>(&buffer);
  e->type = XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED;
  e->next = nullptr;
  e->session = toHandle<XrSession>(&session);
  e->state = state;
  e->time = now();
  session.state = state;
  session.stats.state = state;
  queueEvent(*session.instance, buffer);
}

XrResult twoCallString(const char* cmd, uint32_t capacity, uint32_t* countOutput, char* buffer,
                       const std::string& value) {
  MOCK_VERIFY_NOT_NULL(cmd, countOutput);
  const uint32_t needed = uint32_t(value.size() + 1);
  *countOutput = needed;
  if (capacity == 0) return XR_SUCCESS;
  if (capacity < needed)
    return fail(cmd, XR_ERROR_SIZE_INSUFFICIENT, "capacity %u < %u", capacity, needed);
  MOCK_VERIFY_NOT_NULL(cmd, buffer);
  std::memcpy(buffer, value.c_str(), needed);
  return XR_SUCCESS;
}

XrPath Instance::path(const std::string& s) {
  const auto it = pathIds.find(s);
  if (it != pathIds.end()) return it->second;
  const XrPath id = pathStrings.size();
  pathStrings.push_back(s);
  pathIds.emplace(s, id);
  return id;
}

const std::string* Instance::pathString(XrPath p) const {
  if (p == XR_NULL_PATH || p >= pathStrings.size()) return nullptr;
  return &pathStrings[p];
}

Instance::~Instance() = default;

// Environment first, then the script's directives, which win.
static void applyOptions(Instance& instance) {
  Options o;
  if (const char* v = std::getenv(SDFG_MOCK_ENV_END_AFTER_FRAMES))
    o.endAfterFrames = std::strtoull(v, nullptr, 10);
  if (const char* v = std::getenv(SDFG_MOCK_ENV_PROFILE)) o.profile = v;
  if (const char* v = std::getenv(SDFG_MOCK_ENV_CAPTURE)) o.capturePath = v;
  if (const char* v = std::getenv(SDFG_MOCK_ENV_REPORT)) o.reportPath = v;
  if (const char* v = std::getenv(SDFG_MOCK_ENV_FAULT)) o.fault = v;
  if (!setCallFailures(o.fault))
    std::fprintf(stderr, "mock runtime: %s names an unknown command\n", o.fault.c_str());
  o.capture = !o.capturePath.empty() || !o.reportPath.empty();
  const Script& s = instance.script;
  if (auto d = s.directive("end_after_frames"))
    o.endAfterFrames = std::strtoull(d->c_str(), nullptr, 10);
  if (auto d = s.directive("profile")) o.profile = *d;
  if (auto d = s.directive("capture")) o.capture = *d != "0";
  if (o.profile.empty()) o.profile = "/interaction_profiles/oculus/touch_controller";
  instance.options = o;
}

XrResult setScriptText(Instance& instance, const char* text, const char* cmd) {
  Script parsed;
  std::string error;
  if (!Script::parse(text, parsed, error)) {
    std::fprintf(stderr, "[sdfg-mock-runtime] script: %s\n", error.c_str());
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "script: %s", error.c_str());
  }
  instance.script = std::move(parsed);
  applyOptions(instance);
  if (!isSimulatedProfile(instance.options.profile)) {
    std::fprintf(stderr, "[sdfg-mock-runtime] unknown or handless profile %s\n",
                 instance.options.profile.c_str());
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "unknown or handless profile %s",
                instance.options.profile.c_str());
  }
  return XR_SUCCESS;
}

XrResult enumerateInstanceExtensionProperties(const char* layerName, uint32_t capacity,
                                              uint32_t* countOutput, XrExtensionProperties* props) {
  constexpr const char* cmd = "xrEnumerateInstanceExtensionProperties";
  if (layerName != nullptr)
    return fail(cmd, XR_ERROR_API_LAYER_NOT_PRESENT, "no layer %s", layerName);
  const std::vector<XrExtensionProperties> list = offeredExtensions();
  MOCK_VERIFY_NOT_NULL(cmd, countOutput);
  *countOutput = uint32_t(list.size());
  if (capacity == 0) return XR_SUCCESS;
  if (capacity < list.size()) return fail(cmd, XR_ERROR_SIZE_INSUFFICIENT, "capacity %u", capacity);
  MOCK_VERIFY_NOT_NULL(cmd, props);
  for (size_t i = 0; i < list.size(); ++i) {
    if (props[i].type != XR_TYPE_EXTENSION_PROPERTIES)
      return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "(properties[%zu].type) is wrong", i);
    std::memcpy(props[i].extensionName, list[i].extensionName, sizeof props[i].extensionName);
    props[i].extensionVersion = list[i].extensionVersion;
  }
  return XR_SUCCESS;
}

XrResult enumerateApiLayerProperties(uint32_t capacity, uint32_t* countOutput,
                                     XrApiLayerProperties* props) {
  return twoCall<XrApiLayerProperties>("xrEnumerateApiLayerProperties", capacity, countOutput,
                                       props, nullptr, 0);
}

XrResult createInstance(const XrInstanceCreateInfo* info, XrInstance* out) {
  constexpr const char* cmd = "xrCreateInstance";
  MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_INSTANCE_CREATE_INFO);
  MOCK_VERIFY_NOT_NULL(cmd, out);
  if (info->createFlags != 0)
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "createFlags must be 0");
  const XrApplicationInfo& app = info->applicationInfo;
  if (app.applicationName[0] == '\0')
    return fail(cmd, XR_ERROR_NAME_INVALID, "empty applicationName");
  if (strnlen(app.applicationName, XR_MAX_APPLICATION_NAME_SIZE) == XR_MAX_APPLICATION_NAME_SIZE ||
      strnlen(app.engineName, XR_MAX_ENGINE_NAME_SIZE) == XR_MAX_ENGINE_NAME_SIZE)
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "application or engine name not terminated");
  if (XR_VERSION_MAJOR(app.apiVersion) != 1 || XR_VERSION_MINOR(app.apiVersion) != 0)
    return fail(cmd, XR_ERROR_API_VERSION_UNSUPPORTED, "apiVersion %llu.%llu",
                (unsigned long long)XR_VERSION_MAJOR(app.apiVersion),
                (unsigned long long)XR_VERSION_MINOR(app.apiVersion));
  // enabledApiLayerNames are the loader's business: it has loaded them (or refused the app)
  // before the runtime sees the list, so a runtime ignores it.
  if (theInstance()) return fail(cmd, XR_ERROR_LIMIT_REACHED, "one instance at a time");

  auto instance = std::make_unique<Instance>();
  const std::vector<XrExtensionProperties> offered = offeredExtensions();
  if (info->enabledExtensionCount > 0) MOCK_VERIFY_NOT_NULL(cmd, info->enabledExtensionNames);
  for (uint32_t i = 0; i < info->enabledExtensionCount; ++i) {
    const char* name = info->enabledExtensionNames[i];
    MOCK_VERIFY_NOT_NULL(cmd, name);
    bool known = false;
    for (const auto& e : offered) known = known || std::strcmp(e.extensionName, name) == 0;
    if (!known) return fail(cmd, XR_ERROR_EXTENSION_NOT_PRESENT, "%s is not offered", name);
    const std::string_view n(name);
    if (n == XR_KHR_VULKAN_ENABLE_EXTENSION_NAME) instance->extVulkan = true;
    if (n == XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME) instance->extVulkan2 = true;
    if (n == XR_MND_HEADLESS_EXTENSION_NAME) instance->extHeadless = true;
    if (n == XR_KHR_CONVERT_TIMESPEC_TIME_EXTENSION_NAME) instance->extTimespec = true;
    if (n == XR_KHR_COMPOSITION_LAYER_DEPTH_EXTENSION_NAME) instance->extDepth = true;
    if (n == XR_EXT_HAND_TRACKING_EXTENSION_NAME) instance->extHandTracking = true;
    if (n == XR_EXT_HAND_JOINTS_MOTION_RANGE_EXTENSION_NAME) instance->extMotionRange = true;
  }
  instance->handTracking = handTrackingFromEnv();

  std::string text;
  if (const char* file = std::getenv(SDFG_MOCK_ENV_SCRIPT); file != nullptr && *file != '\0') {
    std::ifstream in(file);
    if (!in) {
      std::fprintf(stderr, "[sdfg-mock-runtime] cannot read script %s\n", file);
      return fail(cmd, XR_ERROR_INITIALIZATION_FAILED, "cannot read script %s", file);
    }
    std::ostringstream ss;
    ss << in.rdbuf();
    text = ss.str();
  }
  if (setScriptText(*instance, text.c_str(), cmd) != XR_SUCCESS)
    return fail(cmd, XR_ERROR_INITIALIZATION_FAILED, "bad script or options");

  registerHandle(instance.get());
  *out = toHandle<XrInstance>(instance.get());
  theInstance() = std::move(instance);
  return XR_SUCCESS;
}

XrResult destroyInstance(XrInstance handle) {
  constexpr const char* cmd = "xrDestroyInstance";
  Instance* instance = lookup<Instance>(handle);
  if (instance == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "instance is not valid");
  while (!instance->sessions.empty()) destroySession(instance->sessions.back().get());
  for (auto& set : instance->actionSets) unregisterHandle(set.get());
  for (auto& action : instance->actions) unregisterHandle(action.get());
  unregisterHandle(instance);
  theInstance().reset();
  return XR_SUCCESS;
}

XrResult getInstanceProperties(XrInstance handle, XrInstanceProperties* props) {
  constexpr const char* cmd = "xrGetInstanceProperties";
  if (lookup<Instance>(handle) == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "instance");
  MOCK_VERIFY_TYPE(cmd, props, XR_TYPE_INSTANCE_PROPERTIES);
  props->runtimeVersion = XR_MAKE_VERSION(0, 1, 0);
  std::snprintf(props->runtimeName, sizeof props->runtimeName, "SDFG mock runtime");
  return XR_SUCCESS;
}

XrResult pollEvent(XrInstance handle, XrEventDataBuffer* event) {
  constexpr const char* cmd = "xrPollEvent";
  Instance* instance = lookup<Instance>(handle);
  if (instance == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "instance is not valid");
  MOCK_VERIFY_TYPE(cmd, event, XR_TYPE_EVENT_DATA_BUFFER);
  if (instance->events.empty()) return XR_EVENT_UNAVAILABLE;
  *event = instance->events.front();
  instance->events.pop_front();
  return XR_SUCCESS;
}

XrResult resultToString(XrInstance handle, XrResult value, char buffer[XR_MAX_RESULT_STRING_SIZE]) {
  constexpr const char* cmd = "xrResultToString";
  if (lookup<Instance>(handle) == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "instance");
  MOCK_VERIFY_NOT_NULL(cmd, buffer);
  const char* name = nullptr;
  switch (value) {
#define MOCK_RESULT_CASE(n, v) \
  case n:                      \
    name = #n;                 \
    break;
    XR_LIST_ENUM_XrResult(MOCK_RESULT_CASE)
#undef MOCK_RESULT_CASE
        default : break;
  }
  if (name != nullptr)
    std::snprintf(buffer, XR_MAX_RESULT_STRING_SIZE, "%s", name);
  else if (value >= 0)
    std::snprintf(buffer, XR_MAX_RESULT_STRING_SIZE, "XR_UNKNOWN_SUCCESS_%d", int(value));
  else
    std::snprintf(buffer, XR_MAX_RESULT_STRING_SIZE, "XR_UNKNOWN_FAILURE_%d", int(value));
  return XR_SUCCESS;
}

XrResult structureTypeToString(XrInstance handle, XrStructureType value,
                               char buffer[XR_MAX_STRUCTURE_NAME_SIZE]) {
  constexpr const char* cmd = "xrStructureTypeToString";
  if (lookup<Instance>(handle) == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "instance");
  MOCK_VERIFY_NOT_NULL(cmd, buffer);
  const char* name = nullptr;
  switch (value) {
#define MOCK_TYPE_CASE(n, v) \
  case n:                    \
    name = #n;               \
    break;
    XR_LIST_ENUM_XrStructureType(MOCK_TYPE_CASE)
#undef MOCK_TYPE_CASE
        default : break;
  }
  if (name != nullptr)
    std::snprintf(buffer, XR_MAX_STRUCTURE_NAME_SIZE, "%s", name);
  else
    std::snprintf(buffer, XR_MAX_STRUCTURE_NAME_SIZE, "XR_UNKNOWN_STRUCTURE_TYPE_%d", int(value));
  return XR_SUCCESS;
}

XrResult stringToPath(XrInstance handle, const char* pathString, XrPath* path) {
  constexpr const char* cmd = "xrStringToPath";
  Instance* instance = lookup<Instance>(handle);
  if (instance == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "instance is not valid");
  MOCK_VERIFY_NOT_NULL(cmd, pathString);
  MOCK_VERIFY_NOT_NULL(cmd, path);
  if (!wellFormedPath(pathString))
    return fail(cmd, XR_ERROR_PATH_FORMAT_INVALID, "'%.300s' is not a well-formed path",
                pathString);
  *path = instance->path(pathString);
  return XR_SUCCESS;
}

XrResult pathToString(XrInstance handle, XrPath path, uint32_t capacity, uint32_t* countOutput,
                      char* buffer) {
  constexpr const char* cmd = "xrPathToString";
  const Instance* instance = lookup<Instance>(handle);
  if (instance == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "instance is not valid");
  const std::string* s = instance->pathString(path);
  if (s == nullptr) return fail(cmd, XR_ERROR_PATH_INVALID, "path %llu", (unsigned long long)path);
  return twoCallString(cmd, capacity, countOutput, buffer, *s);
}

XrResult convertTimespecTimeToTime(XrInstance handle, const struct timespec* ts, XrTime* time) {
  constexpr const char* cmd = "xrConvertTimespecTimeToTimeKHR";
  if (lookup<Instance>(handle) == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "instance");
  MOCK_VERIFY_NOT_NULL(cmd, ts);
  MOCK_VERIFY_NOT_NULL(cmd, time);
  *time = XrTime(ts->tv_sec) * 1000000000 + ts->tv_nsec;
  if (*time <= 0) return fail(cmd, XR_ERROR_TIME_INVALID, "time before the epoch");
  return XR_SUCCESS;
}

XrResult convertTimeToTimespecTime(XrInstance handle, XrTime time, struct timespec* ts) {
  constexpr const char* cmd = "xrConvertTimeToTimespecTimeKHR";
  if (lookup<Instance>(handle) == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "instance");
  MOCK_VERIFY_NOT_NULL(cmd, ts);
  if (time <= 0) return fail(cmd, XR_ERROR_TIME_INVALID, "time %lld", (long long)time);
  ts->tv_sec = time / 1000000000;
  ts->tv_nsec = time % 1000000000;
  return XR_SUCCESS;
}

XrResult mockSetScript(XrInstance handle, const char* scriptText) {
  constexpr const char* cmd = "xrMockRuntimeSetScriptSDFG";
  Instance* instance = lookup<Instance>(handle);
  if (instance == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "instance is not valid");
  MOCK_VERIFY_NOT_NULL(cmd, scriptText);
  Script previous = instance->script;
  const XrResult r = setScriptText(*instance, scriptText, cmd);
  if (r != XR_SUCCESS) {
    instance->script = std::move(previous);
    applyOptions(*instance);
  }
  return r;
}

}  // namespace sdfg::mock
