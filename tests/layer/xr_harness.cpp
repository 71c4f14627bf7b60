#include "xr_harness.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace sdfg::test {
namespace {

std::string gWorkDir;

std::vector<std::string>& messageStore() {
  static std::vector<std::string> messages;
  return messages;
}

VKAPI_ATTR VkBool32 VKAPI_CALL onVulkanMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                               VkDebugUtilsMessageTypeFlagsEXT,
                                               const VkDebugUtilsMessengerCallbackDataEXT* data,
                                               void*) {
  if (severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
    messageStore().push_back(data->pMessage);
    std::fprintf(stderr, "vulkan validation: %s\n", data->pMessage);
  }
  return VK_FALSE;
}

VkDebugUtilsMessengerCreateInfoEXT messengerInfo() {
  VkDebugUtilsMessengerCreateInfoEXT mi{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  mi.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  mi.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                   VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                   VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  mi.pfnUserCallback = &onVulkanMessage;
  return mi;
}

std::vector<const char*> splitNames(std::string& text) {
  std::vector<const char*> out;
  for (char& c : text) {
    if (c == ' ') c = '\0';
  }
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '\0' && (i == 0 || text[i - 1] == '\0')) out.push_back(&text[i]);
  }
  return out;
}

std::string workDir() {
  if (gWorkDir.empty()) {
    char tmpl[] = "/tmp/sdfg_layer_test_XXXXXX";
    const char* d = mkdtemp(tmpl);
    gWorkDir = d != nullptr ? d : "/tmp";
  }
  return gWorkDir;
}

}  // namespace

std::string applyEnv(const XrEnv& env) {
  namespace fs = std::filesystem;
  const std::string dir = workDir();
  // The layer under test is implicit, found under $XDG_DATA_HOME; nothing else implicit is.
  const fs::path implicit = fs::path(dir) / "data/openxr/1/api_layers/implicit.d";
  fs::create_directories(implicit);
#ifdef SDFG_LAYER_TEST_JSON
  const char* const manifest = env.testBuild ? SDFG_LAYER_TEST_JSON : SDFG_LAYER_JSON;
#else
  if (env.testBuild) throw std::runtime_error("built without the layer's test build");
  const char* const manifest = SDFG_LAYER_JSON;
#endif
  // Removed first: MinGW's libstdc++ 12 refuses to overwrite, whatever the options say.
  fs::remove(implicit / "XrApiLayer_sdfg_autograsp.json");
  fs::copy_file(manifest, implicit / "XrApiLayer_sdfg_autograsp.json",
                fs::copy_options::overwrite_existing);
  setenv("XDG_DATA_HOME", (fs::path(dir) / "data").c_str(), 1);
  setenv("XDG_DATA_DIRS", "/usr/share", 1);  // core validation's explicit manifest
  setenv("XDG_CONFIG_DIRS", (fs::path(dir) / "no-config").c_str(), 1);
  setenv("XDG_CONFIG_HOME", (fs::path(dir) / "config").c_str(), 1);
  setenv("XR_RUNTIME_JSON", SDFG_MOCK_RUNTIME_JSON, 1);
#ifndef _WIN32  // the SDK the Windows loader is built from has no core validation layer
  setenv("XR_ENABLE_API_LAYERS", "XR_APILAYER_LUNARG_core_validation", 1);
#endif
  const std::string cv = dir + "/core-validation.txt";
  setenv("XR_CORE_VALIDATION_FILE_NAME", cv.c_str(), 1);
  if (env.layer)
    unsetenv(SDFG_LAYER_DISABLE_ENV);
  else
    setenv(SDFG_LAYER_DISABLE_ENV, "1", 1);
  setenv("SDFG_MOCK_HAND_TRACKING", env.handTracking.c_str(), 1);
  if (!env.script.empty()) {
    const std::string path = dir + "/script.txt";
    std::ofstream(path) << env.script;
    setenv("SDFG_MOCK_SCRIPT", path.c_str(), 1);
  } else {
    unsetenv("SDFG_MOCK_SCRIPT");
  }
  // Layer settings a previous test of the process may have set: every SDFG_AUTOGRASP_ variable.
  std::vector<std::string> settings;
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string entry = *e;
    if (entry.rfind("SDFG_AUTOGRASP_", 0) == 0)
      settings.push_back(entry.substr(0, entry.find('=')));
  }
  for (const std::string& name : settings) unsetenv(name.c_str());
  // And the extra variables of the previous test (a mock fault such as zero_display_time would
  // otherwise reach every later test of a process that runs several).
  static std::vector<std::string> previousExtra;
  for (const std::string& name : previousExtra) unsetenv(name.c_str());
  previousExtra.clear();
  for (const auto& [k, v] : env.extra) {
    setenv(k.c_str(), v.c_str(), 1);
    previousExtra.push_back(k);
  }
  // A grab whose build runs past build_time_limit_ms (1 s by default) is given up and the hand
  // stays open until the squeeze is released: a test waiting for a grasp would wait out its whole
  // bound wherever a loaded machine or a sanitizer made one build slow. The tests wait for
  // outcomes, so the layer's bound is lifted unless a test sets it.
  constexpr const char* kBuildLimit = "SDFG_AUTOGRASP_BUILD_TIME_LIMIT_MS";
  if (std::none_of(env.extra.begin(), env.extra.end(),
                   [&](const auto& kv) { return kv.first == kBuildLimit; }))
    setenv(kBuildLimit, "600000", 1);
  return cv;
}

std::string validationLog() {
  std::ifstream in(workDir() + "/core-validation.txt");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> vulkanMessages() {
  return messageStore();
}

std::string vulkanUnavailable() {
  uint32_t count = 0;
  if (vkEnumerateInstanceLayerProperties(&count, nullptr) != VK_SUCCESS) return "no Vulkan loader";
  std::vector<VkLayerProperties> layers(count);
  vkEnumerateInstanceLayerProperties(&count, layers.data());
  bool validation = false;
  for (const auto& l : layers)
    validation |= std::strcmp(l.layerName, "VK_LAYER_KHRONOS_validation") == 0;
  if (!validation) return "the Khronos Vulkan validation layer is not installed";
  VkApplicationInfo ai{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  ai.apiVersion = VK_API_VERSION_1_1;
  VkInstanceCreateInfo ci{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ci.pApplicationInfo = &ai;
  VkInstance instance = VK_NULL_HANDLE;
  if (vkCreateInstance(&ci, nullptr, &instance) != VK_SUCCESS) return "vkCreateInstance failed";
  uint32_t devices = 0;
  vkEnumeratePhysicalDevices(instance, &devices, nullptr);
  vkDestroyInstance(instance, nullptr);
  return devices == 0 ? "no Vulkan physical device" : "";
}

uint32_t hostCoherentMemoryType(const VulkanSide& vk, uint32_t typeBits) {
  VkPhysicalDeviceMemoryProperties mem;
  vkGetPhysicalDeviceMemoryProperties(vk.physicalDevice, &mem);
  const VkMemoryPropertyFlags want =
      VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  for (uint32_t type = 0; type < mem.memoryTypeCount; ++type)
    if ((typeBits & (1u << type)) && (mem.memoryTypes[type].propertyFlags & want) == want)
      return type;
  return UINT32_MAX;
}

HostBuffer App::createBuffer(VkDeviceSize bytes) {
  HostBuffer b;
  VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bi.size = bytes;
  bi.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  if (vkCreateBuffer(vk.device, &bi, nullptr, &b.buffer) != VK_SUCCESS) return {};
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(vk.device, b.buffer, &req);
  const uint32_t type = hostCoherentMemoryType(vk, req.memoryTypeBits);
  VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  ai.allocationSize = req.size;
  ai.memoryTypeIndex = type;
  if (type == UINT32_MAX || vkAllocateMemory(vk.device, &ai, nullptr, &b.memory) != VK_SUCCESS ||
      vkBindBufferMemory(vk.device, b.buffer, b.memory, 0) != VK_SUCCESS ||
      vkMapMemory(vk.device, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped) != VK_SUCCESS) {
    if (b.memory != VK_NULL_HANDLE) vkFreeMemory(vk.device, b.memory, nullptr);
    vkDestroyBuffer(vk.device, b.buffer, nullptr);
    return {};
  }
  buffers_.push_back(b);
  return b;
}

bool App::setUpVulkan(Graphics graphics) {
  const bool two = graphics == Graphics::vulkan2;
  const char* layer = "VK_LAYER_KHRONOS_validation";
  VkApplicationInfo appInfo{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  appInfo.apiVersion = VK_API_VERSION_1_1;
  VkDebugUtilsMessengerCreateInfoEXT mi = messengerInfo();
  VkResult vr = VK_ERROR_UNKNOWN;
  if (two) {
    XrGraphicsRequirementsVulkan2KHR req{XR_TYPE_GRAPHICS_REQUIREMENTS_VULKAN2_KHR};
    if (fn<PFN_xrGetVulkanGraphicsRequirements2KHR>("xrGetVulkanGraphicsRequirements2KHR")(
            instance, system, &req) != XR_SUCCESS)
      return false;
    const char* extension = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
    VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO, &mi};
    ici.pApplicationInfo = &appInfo;
    ici.enabledLayerCount = 1;
    ici.ppEnabledLayerNames = &layer;
    ici.enabledExtensionCount = 1;
    ici.ppEnabledExtensionNames = &extension;
    XrVulkanInstanceCreateInfoKHR xi{XR_TYPE_VULKAN_INSTANCE_CREATE_INFO_KHR};
    xi.systemId = system;
    xi.pfnGetInstanceProcAddr = &vkGetInstanceProcAddr;
    xi.vulkanCreateInfo = &ici;
    if (fn<PFN_xrCreateVulkanInstanceKHR>("xrCreateVulkanInstanceKHR")(instance, &xi, &vk.instance,
                                                                       &vr) != XR_SUCCESS ||
        vr != VK_SUCCESS)
      return false;
    XrVulkanGraphicsDeviceGetInfoKHR gi{XR_TYPE_VULKAN_GRAPHICS_DEVICE_GET_INFO_KHR};
    gi.systemId = system;
    gi.vulkanInstance = vk.instance;
    if (fn<PFN_xrGetVulkanGraphicsDevice2KHR>("xrGetVulkanGraphicsDevice2KHR")(
            instance, &gi, &vk.physicalDevice) != XR_SUCCESS)
      return false;
  } else {
    XrGraphicsRequirementsVulkanKHR req{XR_TYPE_GRAPHICS_REQUIREMENTS_VULKAN_KHR};
    if (fn<PFN_xrGetVulkanGraphicsRequirementsKHR>("xrGetVulkanGraphicsRequirementsKHR")(
            instance, system, &req) != XR_SUCCESS)
      return false;
    auto getExt = fn<PFN_xrGetVulkanInstanceExtensionsKHR>("xrGetVulkanInstanceExtensionsKHR");
    uint32_t n = 0;
    getExt(instance, system, 0, &n, nullptr);
    std::string names(n, '\0');
    getExt(instance, system, n, &n, names.data());
    names.resize(std::strlen(names.c_str()));
    std::vector<const char*> exts = splitNames(names);
    exts.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO, &mi};
    ici.pApplicationInfo = &appInfo;
    ici.enabledLayerCount = 1;
    ici.ppEnabledLayerNames = &layer;
    ici.enabledExtensionCount = uint32_t(exts.size());
    ici.ppEnabledExtensionNames = exts.data();
    if (vkCreateInstance(&ici, nullptr, &vk.instance) != VK_SUCCESS) return false;
    if (fn<PFN_xrGetVulkanGraphicsDeviceKHR>("xrGetVulkanGraphicsDeviceKHR")(
            instance, system, vk.instance, &vk.physicalDevice) != XR_SUCCESS)
      return false;
  }
  auto createMessenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
      vkGetInstanceProcAddr(vk.instance, "vkCreateDebugUtilsMessengerEXT"));
  if (createMessenger(vk.instance, &mi, nullptr, &vk.messenger) != VK_SUCCESS) return false;

  uint32_t familyCount = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(vk.physicalDevice, &familyCount, nullptr);
  std::vector<VkQueueFamilyProperties> families(familyCount);
  vkGetPhysicalDeviceQueueFamilyProperties(vk.physicalDevice, &familyCount, families.data());
  while (vk.family < familyCount && !(families[vk.family].queueFlags & VK_QUEUE_GRAPHICS_BIT))
    ++vk.family;
  if (vk.family == familyCount) return false;
  const float priority = 0.0f;
  VkDeviceQueueCreateInfo qi{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qi.queueFamilyIndex = vk.family;
  qi.queueCount = 1;
  qi.pQueuePriorities = &priority;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qi;
  if (two) {
    XrVulkanDeviceCreateInfoKHR xd{XR_TYPE_VULKAN_DEVICE_CREATE_INFO_KHR};
    xd.systemId = system;
    xd.pfnGetInstanceProcAddr = &vkGetInstanceProcAddr;
    xd.vulkanPhysicalDevice = vk.physicalDevice;
    xd.vulkanCreateInfo = &dci;
    if (fn<PFN_xrCreateVulkanDeviceKHR>("xrCreateVulkanDeviceKHR")(instance, &xd, &vk.device,
                                                                   &vr) != XR_SUCCESS ||
        vr != VK_SUCCESS)
      return false;
  } else {
    auto getExt = fn<PFN_xrGetVulkanDeviceExtensionsKHR>("xrGetVulkanDeviceExtensionsKHR");
    uint32_t n = 0;
    getExt(instance, system, 0, &n, nullptr);
    std::string names(n, '\0');
    getExt(instance, system, n, &n, names.data());
    names.resize(std::strlen(names.c_str()));
    std::vector<const char*> exts = splitNames(names);
    dci.enabledExtensionCount = uint32_t(exts.size());
    dci.ppEnabledExtensionNames = exts.empty() ? nullptr : exts.data();
    if (vkCreateDevice(vk.physicalDevice, &dci, nullptr, &vk.device) != VK_SUCCESS) return false;
  }
  vkGetDeviceQueue(vk.device, vk.family, 0, &vk.queue);
  return true;
}

void App::destroyVulkan() {
  if (vk.device != VK_NULL_HANDLE) {
    vkDeviceWaitIdle(vk.device);
    for (const HostBuffer& b : buffers_) {
      vkDestroyBuffer(vk.device, b.buffer, nullptr);
      vkFreeMemory(vk.device, b.memory, nullptr);
    }
    buffers_.clear();
    // The validation layer reports here any object the layer left on the app's device.
    vkDestroyDevice(vk.device, nullptr);
    vk.device = VK_NULL_HANDLE;
  }
  if (vk.messenger != VK_NULL_HANDLE) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(vk.instance, "vkDestroyDebugUtilsMessengerEXT"));
    destroy(vk.instance, vk.messenger, nullptr);
    vk.messenger = VK_NULL_HANDLE;
  }
  if (vk.instance != VK_NULL_HANDLE) {
    vkDestroyInstance(vk.instance, nullptr);
    vk.instance = VK_NULL_HANDLE;
  }
}

App::App(const AppOptions& options) {
  std::vector<const char*> ext{
      options.graphics == Graphics::headless ? XR_MND_HEADLESS_EXTENSION_NAME
      : options.graphics == Graphics::vulkan ? XR_KHR_VULKAN_ENABLE_EXTENSION_NAME
                                             : XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME};
  for (const std::string& e : options.extensions) ext.push_back(e.c_str());
  XrInstanceCreateInfo ci{XR_TYPE_INSTANCE_CREATE_INFO};
  std::strcpy(ci.applicationInfo.applicationName, "sdfg layer test");
  ci.applicationInfo.apiVersion = XR_MAKE_VERSION(1, 0, 0);
  ci.enabledExtensionCount = uint32_t(ext.size());
  ci.enabledExtensionNames = ext.data();
  if (xrCreateInstance(&ci, &instance) != XR_SUCCESS) return;
  XrSystemGetInfo sgi{XR_TYPE_SYSTEM_GET_INFO};
  sgi.formFactor = XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY;
  if (xrGetSystem(instance, &sgi, &system) != XR_SUCCESS) return;
  XrSessionCreateInfo sci{XR_TYPE_SESSION_CREATE_INFO};
  sci.systemId = system;
  XrGraphicsBindingVulkanKHR binding{XR_TYPE_GRAPHICS_BINDING_VULKAN_KHR};
  if (options.graphics != Graphics::headless) {
    if (!setUpVulkan(options.graphics)) return;
    binding.instance = vk.instance;
    binding.physicalDevice = vk.physicalDevice;
    binding.device = vk.device;
    binding.queueFamilyIndex = vk.family;
    binding.queueIndex = 0;
    sci.next = &binding;
  } else {
    sci.next = options.sessionNext;
  }
  if (xrCreateSession(instance, &sci, &session) != XR_SUCCESS) return;
  XrReferenceSpaceCreateInfo rs{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
  rs.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_LOCAL;
  rs.poseInReferenceSpace.orientation.w = 1;
  if (xrCreateReferenceSpace(session, &rs, &local) != XR_SUCCESS) return;
  xrStringToPath(instance, "/user/hand/left", &hands[0]);
  xrStringToPath(instance, "/user/hand/right", &hands[1]);
  if (options.appActions) {
    XrActionSetCreateInfo asci{XR_TYPE_ACTION_SET_CREATE_INFO};
    std::strcpy(asci.actionSetName, "app");
    std::strcpy(asci.localizedActionSetName, "App");
    if (xrCreateActionSet(instance, &asci, &appSet) != XR_SUCCESS) return;
    XrActionCreateInfo aci{XR_TYPE_ACTION_CREATE_INFO};
    aci.actionType = XR_ACTION_TYPE_FLOAT_INPUT;
    std::strcpy(aci.actionName, "grab");
    std::strcpy(aci.localizedActionName, "Grab");
    aci.countSubactionPaths = 2;
    aci.subactionPaths = hands.data();
    if (xrCreateAction(appSet, &aci, &appSqueeze) != XR_SUCCESS) return;
    XrPath profile, l, r;
    xrStringToPath(instance, "/interaction_profiles/oculus/touch_controller", &profile);
    xrStringToPath(instance, "/user/hand/left/input/squeeze/value", &l);
    xrStringToPath(instance, "/user/hand/right/input/squeeze/value", &r);
    XrActionSuggestedBinding b[2] = {{appSqueeze, l}, {appSqueeze, r}};
    XrInteractionProfileSuggestedBinding sb{XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING};
    sb.interactionProfile = profile;
    sb.countSuggestedBindings = 2;
    sb.suggestedBindings = b;
    if (xrSuggestInteractionProfileBindings(instance, &sb) != XR_SUCCESS) return;
    XrSessionActionSetsAttachInfo at{XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO};
    at.countActionSets = 1;
    at.actionSets = &appSet;
    if (xrAttachSessionActionSets(session, &at) != XR_SUCCESS) return;
  }
  ok_ = true;
}

App::~App() {
  destroySession();
  destroyInstance();
  destroyVulkan();
}

void App::destroyInstance() {
  if (instance != XR_NULL_HANDLE) xrDestroyInstance(instance);
  instance = XR_NULL_HANDLE;
  session = XR_NULL_HANDLE;
}

void App::destroySession() {
  if (session == XR_NULL_HANDLE) return;
  if (running_) {
    xrRequestExitSession(session);
    for (int i = 0; i < 10 && running_; ++i) pollEvents();
  }
  xrDestroySession(session);
  session = XR_NULL_HANDLE;
}

void App::pollEvents() {
  XrEventDataBuffer e{XR_TYPE_EVENT_DATA_BUFFER};
  while (xrPollEvent(instance, &e) == XR_SUCCESS) {
    events.push_back(e);
    if (e.type == XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED) {
      const auto* s = reinterpret_cast<XrEventDataSessionStateChanged*>(&e);
      if (s->state == XR_SESSION_STATE_READY) {
        XrSessionBeginInfo bi{XR_TYPE_SESSION_BEGIN_INFO};
        bi.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
        if (xrBeginSession(session, &bi) == XR_SUCCESS) running_ = true;
      } else if (s->state == XR_SESSION_STATE_STOPPING) {
        xrEndSession(session);
        running_ = false;
      }
    }
    e = XrEventDataBuffer{XR_TYPE_EVENT_DATA_BUFFER};
  }
}

void App::frame(const std::function<void()>& beforeEnd) {
  pollEvents();
  if (!running_) return;
  // Info structs passed although they may be null: the mock runtime's null check is broken
  // (frame.cpp: `if (info) MOCK_VERIFY_TYPE(...)` guards only the macro's first statement).
  XrFrameState fs{XR_TYPE_FRAME_STATE};
  XrFrameWaitInfo wi{XR_TYPE_FRAME_WAIT_INFO};
  if (xrWaitFrame(session, &wi, &fs) != XR_SUCCESS) return;
  lastTime = fs.predictedDisplayTime;
  XrFrameBeginInfo bi{XR_TYPE_FRAME_BEGIN_INFO};
  xrBeginFrame(session, &bi);
  if (appSet != XR_NULL_HANDLE) {
    XrActiveActionSet active{appSet, XR_NULL_PATH};
    XrActionsSyncInfo si{XR_TYPE_ACTIONS_SYNC_INFO};
    si.countActiveActionSets = 1;
    si.activeActionSets = &active;
    lastSync = xrSyncActions(session, &si);
  }
  if (beforeEnd) beforeEnd();
  XrFrameEndInfo ei{XR_TYPE_FRAME_END_INFO};
  ei.displayTime = fs.predictedDisplayTime;
  ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
  ei.layerCount = uint32_t(layers.size());
  ei.layers = layers.empty() ? nullptr : layers.data();
  lastEndFrame = xrEndFrame(session, &ei);
  layers.clear();
  if (lastEndFrame == XR_SUCCESS) ++framesEnded;
}

float App::appSqueezeValue(int hand) const {
  XrActionStateGetInfo gi{XR_TYPE_ACTION_STATE_GET_INFO};
  gi.action = appSqueeze;
  gi.subactionPath = hands[hand];
  XrActionStateFloat st{XR_TYPE_ACTION_STATE_FLOAT};
  if (xrGetActionStateFloat(session, &gi, &st) != XR_SUCCESS) return -1.0f;
  return st.isActive ? st.currentState : -2.0f;
}

XrResult locateJoints(const App& app, XrHandTrackerEXT tracker, Joints& out,
                      const void* locateNext) {
  auto locate = app.fn<PFN_xrLocateHandJointsEXT>("xrLocateHandJointsEXT");
  if (locate == nullptr) return XR_ERROR_FUNCTION_UNSUPPORTED;
  XrHandJointsLocateInfoEXT info{XR_TYPE_HAND_JOINTS_LOCATE_INFO_EXT};
  info.next = locateNext;
  info.baseSpace = app.local;
  info.time = app.lastTime;
  out.locations = XrHandJointLocationsEXT{XR_TYPE_HAND_JOINT_LOCATIONS_EXT};
  out.locations.jointCount = XR_HAND_JOINT_COUNT_EXT;
  out.locations.jointLocations = out.joints.data();
  return locate(tracker, &info, &out.locations);
}

XrResult App::setScript(const std::string& text) const {
  // The mock runtime's test-only command (tests/mock_runtime/mock_runtime_test.h).
  using SetScript = XrResult(XRAPI_PTR*)(XrInstance, const char*);
  const auto set = fn<SetScript>("xrMockRuntimeSetScriptSDFG");
  return set == nullptr ? XR_ERROR_FUNCTION_UNSUPPORTED : set(instance, text.c_str());
}

std::string gripLine(uint64_t frame, const char* hand, const XrPosef& p) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "%llu %s grip %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n",
                (unsigned long long)frame, hand, p.position.x, p.position.y, p.position.z,
                p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w);
  return buf;
}

std::string squeezeLine(uint64_t frame, const char* hand, float value) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "%llu %s squeeze %.9g\n", (unsigned long long)frame, hand, value);
  return buf;
}

}  // namespace sdfg::test
