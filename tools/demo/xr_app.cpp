#include "xr_app.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <thread>

#include "demo_config.h"

namespace sdfg::demo {
namespace {

const char* resultName(XrInstance instance, XrResult r) {
  static thread_local char buf[XR_MAX_RESULT_STRING_SIZE];
  if (instance == XR_NULL_HANDLE || xrResultToString(instance, r, buf) != XR_SUCCESS)
    std::snprintf(buf, sizeof buf, "XrResult %d", int(r));
  return buf;
}

std::string gripLine(uint64_t frame, const XrPosef& p) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "%llu right grip %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n",
                (unsigned long long)frame, p.position.x, p.position.y, p.position.z,
                p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w);
  return buf;
}

std::string squeezeLine(uint64_t frame, float value) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%llu right squeeze %.3f\n", (unsigned long long)frame, value);
  return buf;
}

}  // namespace

std::string prepareEnvironment() {
  std::string what;
  if (std::getenv("XR_RUNTIME_JSON") == nullptr) {
    setenv("XR_RUNTIME_JSON", SDFG_DEMO_MOCK_RUNTIME_JSON, 1);
    // Controllers only: the layer synthesizes the hand from grip pose and squeeze.
    if (std::getenv("SDFG_MOCK_HAND_TRACKING") == nullptr)
      setenv("SDFG_MOCK_HAND_TRACKING", "absent", 1);
    what += "runtime: the mock runtime of this build";
  } else {
    what += std::string("runtime: XR_RUNTIME_JSON=") + std::getenv("XR_RUNTIME_JSON");
  }
  if (std::getenv("XR_ENABLE_API_LAYERS") == nullptr &&
      std::getenv("XR_API_LAYER_PATH") == nullptr) {
    setenv("XR_API_LAYER_PATH", SDFG_DEMO_LAYER_EXPLICIT_DIR, 1);
    setenv("XR_ENABLE_API_LAYERS", SDFG_DEMO_LAYER_NAME, 1);
    what += "; layer: the build tree's, enabled explicitly";
  } else {
    what += "; layers: as XR_ENABLE_API_LAYERS / XR_API_LAYER_PATH say";
  }
  return what;
}

XrApp::~XrApp() {
  if (session_ != XR_NULL_HANDLE) {
    if (running_) {
      xrRequestExitSession(session_);
      for (int i = 0; i < 10 && running_; ++i) pollEvents();
    }
    if (tracker_ != XR_NULL_HANDLE && destroyTracker_ != nullptr) destroyTracker_(tracker_);
    xrDestroySession(session_);
  }
  if (vkDevice_ != VK_NULL_HANDLE) vkDestroyDevice(vkDevice_, nullptr);
  if (instance_ != XR_NULL_HANDLE) xrDestroyInstance(instance_);
  if (vkInstance_ != VK_NULL_HANDLE) vkDestroyInstance(vkInstance_, nullptr);
}

bool XrApp::init(std::string& error) {
  // The layer lists its extensions in the loader's enumeration; missing means it is not loaded.
  uint32_t count = 0;
  xrEnumerateInstanceExtensionProperties(nullptr, 0, &count, nullptr);
  std::vector<XrExtensionProperties> props(count, {XR_TYPE_EXTENSION_PROPERTIES});
  if (xrEnumerateInstanceExtensionProperties(nullptr, count, &count, props.data()) != XR_SUCCESS) {
    error = "the OpenXR loader found no runtime (XR_RUNTIME_JSON=" +
            std::string(std::getenv("XR_RUNTIME_JSON") ? std::getenv("XR_RUNTIME_JSON") : "") + ")";
    return false;
  }
  bool hasGrasp = false, hasVulkan2 = false;
  for (const auto& p : props) {
    hasGrasp |= std::strcmp(p.extensionName, XR_SDFG_AUTO_GRASP_EXTENSION_NAME) == 0;
    hasVulkan2 |= std::strcmp(p.extensionName, XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME) == 0;
  }
  if (!hasGrasp) {
    error = "the SDF Autograsp layer is not loaded (no " XR_SDFG_AUTO_GRASP_EXTENSION_NAME
            "); enable " SDFG_DEMO_LAYER_NAME " or unset XR_ENABLE_API_LAYERS/XR_API_LAYER_PATH";
    return false;
  }
  if (!hasVulkan2) {
    error = "the runtime does not offer " XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME;
    return false;
  }
  const char* ext[] = {XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME,
                       XR_SDFG_AUTO_GRASP_EXTENSION_NAME};
  XrInstanceCreateInfo ci{XR_TYPE_INSTANCE_CREATE_INFO};
  std::strcpy(ci.applicationInfo.applicationName, "autograsp-demo");
  ci.applicationInfo.apiVersion = XR_MAKE_VERSION(1, 0, 0);
  ci.enabledExtensionCount = 3;
  ci.enabledExtensionNames = ext;
  XrResult r = xrCreateInstance(&ci, &instance_);
  if (r != XR_SUCCESS) {
    error = std::string("xrCreateInstance failed: ") + resultName(XR_NULL_HANDLE, r);
    return false;
  }
  XrInstanceProperties ip{XR_TYPE_INSTANCE_PROPERTIES};
  if (xrGetInstanceProperties(instance_, &ip) == XR_SUCCESS) runtimeName_ = ip.runtimeName;
  XrSystemGetInfo sgi{XR_TYPE_SYSTEM_GET_INFO};
  sgi.formFactor = XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY;
  if ((r = xrGetSystem(instance_, &sgi, &system_)) != XR_SUCCESS) {
    error = std::string("xrGetSystem failed: ") + resultName(instance_, r);
    return false;
  }
  createTarget_ = fn<PFN_xrCreateGraspTargetSDFG>("xrCreateGraspTargetSDFG");
  destroyTarget_ = fn<PFN_xrDestroyGraspTargetSDFG>("xrDestroyGraspTargetSDFG");
  getState_ = fn<PFN_xrGetGraspStateSDFG>("xrGetGraspStateSDFG");
  setOptions_ = fn<PFN_xrSetGraspOptionsSDFG>("xrSetGraspOptionsSDFG");
  locateJoints_ = fn<PFN_xrLocateHandJointsEXT>("xrLocateHandJointsEXT");
  destroyTracker_ = fn<PFN_xrDestroyHandTrackerEXT>("xrDestroyHandTrackerEXT");
  setScript_ = fn<SetScript>("xrMockRuntimeSetScriptSDFG");
  if (!createTarget_ || !destroyTarget_ || !getState_ || !setOptions_ || !locateJoints_) {
    error = "the layer's functions are missing from xrGetInstanceProcAddr";
    return false;
  }
  if (setScript_ == nullptr) {
    error = "the runtime (" + runtimeName_ +
            ") cannot script controllers (no xrMockRuntimeSetScriptSDFG); the demo needs the "
            "mock runtime: unset XR_RUNTIME_JSON";
    return false;
  }
  if (!createVulkan(error)) return false;

  XrGraphicsBindingVulkan2KHR binding{XR_TYPE_GRAPHICS_BINDING_VULKAN2_KHR};
  binding.instance = vkInstance_;
  binding.physicalDevice = vkPhysical_;
  binding.device = vkDevice_;
  binding.queueFamilyIndex = queueFamily_;
  binding.queueIndex = 0;
  XrSessionCreateInfo sci{XR_TYPE_SESSION_CREATE_INFO, &binding};
  sci.systemId = system_;
  if ((r = xrCreateSession(instance_, &sci, &session_)) != XR_SUCCESS) {
    error = std::string("xrCreateSession (Vulkan2) failed: ") + resultName(instance_, r);
    return false;
  }
  XrReferenceSpaceCreateInfo rs{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
  rs.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_LOCAL;
  rs.poseInReferenceSpace.orientation.w = 1;
  if ((r = xrCreateReferenceSpace(session_, &rs, &local_)) != XR_SUCCESS) {
    error = std::string("xrCreateReferenceSpace failed: ") + resultName(instance_, r);
    return false;
  }
  // The app's own grab action: the layer reads its input when the app syncs its actions.
  XrPath hands[2];
  xrStringToPath(instance_, "/user/hand/left", &hands[0]);
  xrStringToPath(instance_, "/user/hand/right", &hands[1]);
  XrActionSetCreateInfo asci{XR_TYPE_ACTION_SET_CREATE_INFO};
  std::strcpy(asci.actionSetName, "demo");
  std::strcpy(asci.localizedActionSetName, "Demo");
  XrActionCreateInfo aci{XR_TYPE_ACTION_CREATE_INFO};
  aci.actionType = XR_ACTION_TYPE_FLOAT_INPUT;
  std::strcpy(aci.actionName, "grab");
  std::strcpy(aci.localizedActionName, "Grab");
  aci.countSubactionPaths = 2;
  aci.subactionPaths = hands;
  XrPath profile, l, rp;
  xrStringToPath(instance_, "/interaction_profiles/oculus/touch_controller", &profile);
  xrStringToPath(instance_, "/user/hand/left/input/squeeze/value", &l);
  xrStringToPath(instance_, "/user/hand/right/input/squeeze/value", &rp);
  if (xrCreateActionSet(instance_, &asci, &appSet_) != XR_SUCCESS ||
      xrCreateAction(appSet_, &aci, &grab_) != XR_SUCCESS) {
    error = "could not create the app's action set";
    return false;
  }
  XrActionSuggestedBinding b[2] = {{grab_, l}, {grab_, rp}};
  XrInteractionProfileSuggestedBinding sb{XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING};
  sb.interactionProfile = profile;
  sb.countSuggestedBindings = 2;
  sb.suggestedBindings = b;
  XrSessionActionSetsAttachInfo at{XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO};
  at.countActionSets = 1;
  at.actionSets = &appSet_;
  if (xrSuggestInteractionProfileBindings(instance_, &sb) != XR_SUCCESS ||
      xrAttachSessionActionSets(session_, &at) != XR_SUCCESS) {
    error = "could not suggest and attach the app's actions";
    return false;
  }
  auto createTracker = fn<PFN_xrCreateHandTrackerEXT>("xrCreateHandTrackerEXT");
  XrHandTrackerCreateInfoEXT hci{XR_TYPE_HAND_TRACKER_CREATE_INFO_EXT};
  hci.hand = XR_HAND_RIGHT_EXT;
  hci.handJointSet = XR_HAND_JOINT_SET_DEFAULT_EXT;
  if (createTracker == nullptr || (r = createTracker(session_, &hci, &tracker_)) != XR_SUCCESS) {
    error = std::string("xrCreateHandTrackerEXT failed: ") + resultName(instance_, r);
    return false;
  }
  // Start the session: READY arrives at creation.
  for (int i = 0; i < 4 && !running_; ++i) pollEvents();
  if (!running_) {
    error = "the session never became ready";
    return false;
  }
  return true;
}

bool XrApp::createVulkan(std::string& error) {
  auto getRequirements =
      fn<PFN_xrGetVulkanGraphicsRequirements2KHR>("xrGetVulkanGraphicsRequirements2KHR");
  auto createInstance = fn<PFN_xrCreateVulkanInstanceKHR>("xrCreateVulkanInstanceKHR");
  auto getDevice = fn<PFN_xrGetVulkanGraphicsDevice2KHR>("xrGetVulkanGraphicsDevice2KHR");
  auto createDevice = fn<PFN_xrCreateVulkanDeviceKHR>("xrCreateVulkanDeviceKHR");
  if (!getRequirements || !createInstance || !getDevice || !createDevice) {
    error = "XR_KHR_vulkan_enable2 functions are missing";
    return false;
  }
  XrGraphicsRequirementsVulkan2KHR req{XR_TYPE_GRAPHICS_REQUIREMENTS_VULKAN2_KHR};
  XrResult r = getRequirements(instance_, system_, &req);
  if (r != XR_SUCCESS) {
    error = std::string("xrGetVulkanGraphicsRequirements2KHR failed: ") + resultName(instance_, r);
    return false;
  }
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "autograsp-demo";
  app.apiVersion = VK_API_VERSION_1_1;
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &app;
  XrVulkanInstanceCreateInfoKHR xici{XR_TYPE_VULKAN_INSTANCE_CREATE_INFO_KHR};
  xici.systemId = system_;
  xici.pfnGetInstanceProcAddr = &vkGetInstanceProcAddr;
  xici.vulkanCreateInfo = &ici;
  VkResult vr = VK_SUCCESS;
  r = createInstance(instance_, &xici, &vkInstance_, &vr);
  if (r != XR_SUCCESS || vr != VK_SUCCESS) {
    error = "xrCreateVulkanInstanceKHR failed (" + std::string(resultName(instance_, r)) +
            ", VkResult " + std::to_string(int(vr)) + "); is a Vulkan driver (lavapipe) installed?";
    return false;
  }
  XrVulkanGraphicsDeviceGetInfoKHR gdi{XR_TYPE_VULKAN_GRAPHICS_DEVICE_GET_INFO_KHR};
  gdi.systemId = system_;
  gdi.vulkanInstance = vkInstance_;
  if ((r = getDevice(instance_, &gdi, &vkPhysical_)) != XR_SUCCESS) {
    error = std::string("xrGetVulkanGraphicsDevice2KHR failed: ") + resultName(instance_, r);
    return false;
  }
  VkPhysicalDeviceProperties pp{};
  vkGetPhysicalDeviceProperties(vkPhysical_, &pp);
  deviceName_ = pp.deviceName;
  uint32_t familyCount = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(vkPhysical_, &familyCount, nullptr);
  std::vector<VkQueueFamilyProperties> families(familyCount);
  vkGetPhysicalDeviceQueueFamilyProperties(vkPhysical_, &familyCount, families.data());
  queueFamily_ = UINT32_MAX;
  for (uint32_t i = 0; i < familyCount; ++i) {
    if (families[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) {
      queueFamily_ = i;
      break;
    }
  }
  if (queueFamily_ == UINT32_MAX) {
    error = "the Vulkan device " + deviceName_ + " has no graphics queue";
    return false;
  }
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = queueFamily_;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  XrVulkanDeviceCreateInfoKHR xdci{XR_TYPE_VULKAN_DEVICE_CREATE_INFO_KHR};
  xdci.systemId = system_;
  xdci.pfnGetInstanceProcAddr = &vkGetInstanceProcAddr;
  xdci.vulkanPhysicalDevice = vkPhysical_;
  xdci.vulkanCreateInfo = &dci;
  r = createDevice(instance_, &xdci, &vkDevice_, &vr);
  if (r != XR_SUCCESS || vr != VK_SUCCESS) {
    error = "xrCreateVulkanDeviceKHR failed (" + std::string(resultName(instance_, r)) +
            ", VkResult " + std::to_string(int(vr)) + ")";
    return false;
  }
  vkGetDeviceQueue(vkDevice_, queueFamily_, 0, &queue_);
  return true;
}

void XrApp::pollEvents() {
  XrEventDataBuffer e{XR_TYPE_EVENT_DATA_BUFFER};
  while (xrPollEvent(instance_, &e) == XR_SUCCESS) {
    if (e.type == XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED) {
      const auto* s = reinterpret_cast<XrEventDataSessionStateChanged*>(&e);
      if (s->state == XR_SESSION_STATE_READY) {
        XrSessionBeginInfo bi{XR_TYPE_SESSION_BEGIN_INFO};
        bi.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
        if (xrBeginSession(session_, &bi) == XR_SUCCESS) running_ = true;
      } else if (s->state == XR_SESSION_STATE_STOPPING) {
        xrEndSession(session_);
        running_ = false;
      }
    }
    e = XrEventDataBuffer{XR_TYPE_EVENT_DATA_BUFFER};
  }
}

void XrApp::frame() {
  pollEvents();
  if (!running_) return;
  XrFrameState fs{XR_TYPE_FRAME_STATE};
  XrFrameWaitInfo wi{XR_TYPE_FRAME_WAIT_INFO};
  if (xrWaitFrame(session_, &wi, &fs) != XR_SUCCESS) return;
  lastTime_ = fs.predictedDisplayTime;
  XrFrameBeginInfo bi{XR_TYPE_FRAME_BEGIN_INFO};
  xrBeginFrame(session_, &bi);
  XrActiveActionSet active{appSet_, XR_NULL_PATH};
  XrActionsSyncInfo si{XR_TYPE_ACTIONS_SYNC_INFO};
  si.countActiveActionSets = 1;
  si.activeActionSets = &active;
  xrSyncActions(session_, &si);
  // No composition layers: the demo renders its pictures offscreen, not to the headset.
  XrFrameEndInfo ei{XR_TYPE_FRAME_END_INFO};
  ei.displayTime = fs.predictedDisplayTime;
  ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
  if (xrEndFrame(session_, &ei) == XR_SUCCESS) ++framesEnded_;
}

bool XrApp::locate(HandJoints& out) {
  std::array<XrHandJointLocationEXT, XR_HAND_JOINT_COUNT_EXT> joints{};
  XrHandJointLocationsEXT locations{XR_TYPE_HAND_JOINT_LOCATIONS_EXT};
  locations.jointCount = XR_HAND_JOINT_COUNT_EXT;
  locations.jointLocations = joints.data();
  XrHandJointsLocateInfoEXT info{XR_TYPE_HAND_JOINTS_LOCATE_INFO_EXT};
  info.baseSpace = local_;
  info.time = lastTime_;
  if (locateJoints_(tracker_, &info, &locations) != XR_SUCCESS || !locations.isActive) return false;
  for (int j = 0; j < XR_HAND_JOINT_COUNT_EXT; ++j) {
    out.poses[j] = joints[j].pose;
    out.radii[j] = joints[j].radius;
  }
  return true;
}

bool XrApp::locateActive(HandJoints& out) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (!locate(out)) {
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    frame();
  }
  return true;
}

bool XrApp::graspState(XrGraspStateSDFG& out, XrGraspBuildInfoSDFG* build,
                       XrGraspHandOffsetSDFG* offset) {
  XrGraspStateGetInfoSDFG gi{XR_TYPE_GRASP_STATE_GET_INFO_SDFG, nullptr, XR_HAND_RIGHT_EXT};
  out = XrGraspStateSDFG{XR_TYPE_GRASP_STATE_SDFG};
  if (offset != nullptr) {
    *offset = XrGraspHandOffsetSDFG{XR_TYPE_GRASP_HAND_OFFSET_SDFG};
    out.next = offset;
  }
  if (build != nullptr) {
    *build = XrGraspBuildInfoSDFG{XR_TYPE_GRASP_BUILD_INFO_SDFG, out.next};
    out.next = build;
  }
  const bool ok = getState_(session_, &gi, &out) == XR_SUCCESS;
  out.next = nullptr;
  return ok;
}

bool XrApp::script(const std::string& text) {
  return setScript_(instance_, text.c_str()) == XR_SUCCESS;
}

bool XrApp::createTarget(const std::vector<XrVector3f>& vertices,
                         const std::vector<uint32_t>& indices, const XrPosef& pose,
                         XrGraspTargetSDFG& out, std::string& error) {
  XrGraspTargetVerticesSDFG v{XR_TYPE_GRASP_TARGET_VERTICES_SDFG};
  v.vertexCount = uint32_t(vertices.size());
  v.vertices = vertices.data();
  v.indexCount = uint32_t(indices.size());
  v.indices = indices.data();
  XrGraspTargetCreateInfoSDFG ci{XR_TYPE_GRASP_TARGET_CREATE_INFO_SDFG, &v};
  ci.placement = {XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG, nullptr, local_, pose};
  const XrResult r = createTarget_(session_, &ci, &out);
  if (r != XR_SUCCESS) {
    error = std::string("xrCreateGraspTargetSDFG refused the mesh: ") + resultName(instance_, r);
    return false;
  }
  return true;
}

void XrApp::destroyTarget(XrGraspTargetSDFG target) {
  if (target != XR_NULL_HANDLE) destroyTarget_(target);
}

GraspReading XrApp::grasp(XrGraspTargetSDFG target, const XrPosef& grip, XrGraspSolverSDFG solver,
                          uint32_t resolution) {
  GraspReading out;
  XrGraspOptionsSDFG o{XR_TYPE_GRASP_OPTIONS_SDFG};
  o.solver = solver;
  o.resolution = resolution;
  XrResult r = setOptions_(session_, &o);
  if (r != XR_SUCCESS) {
    out.error = std::string("xrSetGraspOptionsSDFG failed: ") + resultName(instance_, r);
    return out;
  }
  // Hand placed and open for two frames, then the squeeze ramps to 1 over two frames.
  const uint64_t f = framesEnded_;
  if (!script(gripLine(f, grip) + squeezeLine(f, 0.0f) + squeezeLine(f + 2, 0.0f) +
              squeezeLine(f + 4, 1.0f))) {
    out.error = "the mock runtime refused the controller script";
    return out;
  }
  frame();
  frame();
  if (!locateActive(out.openJoints)) {
    out.error = "xrLocateHandJointsEXT: the right hand is not active after 5 s";
    return out;
  }
  const auto start = std::chrono::steady_clock::now();
  XrGraspStateSDFG st{XR_TYPE_GRASP_STATE_SDFG};
  XrGraspBuildInfoSDFG build{XR_TYPE_GRASP_BUILD_INFO_SDFG};
  // Until the grasp shows, at most 10 s: the layer sets targets up and solves on its session's
  // worker (and with gpu = on, a software Vulkan device takes up to a second): a real app keeps
  // rendering meanwhile. The sleep stands for the rest of a frame.
  const auto deadline = start + std::chrono::seconds(10);
  while (std::chrono::steady_clock::now() < deadline) {
    frame();
    ++out.frames;
    if (graspState(st, &build) && st.isGrasping && st.target == target) {
      out.grasped = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  out.milliseconds =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  // The solved pose is applied from the next locate after the grasp is reported; a hand moved
  // out of the object blends there over a few frames (offset_blend_time): wait for all of it.
  frame();
  for (int i = 0; i < 240 && out.grasped; ++i) {
    if (graspState(st, nullptr, &out.offset) && (out.offset.blend >= 1.0f || !st.isGrasping)) break;
    frame();
  }
  if (!locateActive(out.joints))
    out.error = "xrLocateHandJointsEXT: the right hand is not active after 5 s";
  graspState(out.state, nullptr, &out.offset);
  out.state.next = nullptr;
  if (!out.grasped && out.error.empty())
    out.error = "the layer reported no grasp within 10 s (is the object in the grab box?)";
  // Let go and wait until the hand is open again, so the next grab starts afresh.
  const uint64_t g = framesEnded_;
  script(gripLine(g, grip) + squeezeLine(g, 0.0f));
  XrGraspHandOffsetSDFG offset{XR_TYPE_GRASP_HAND_OFFSET_SDFG};
  for (int i = 0; i < 240; ++i) {
    frame();
    if (graspState(st, nullptr, &offset) && !st.isGrasping && offset.blend <= 0.0f) break;
  }
  return out;
}

}  // namespace sdfg::demo
