// autograsp-frame-cost: what the layer costs an app per frame.
//
// A minimal OpenXR app runs through the real Khronos loader and the mock runtime (controllers
// only: the layer synthesizes the hands), paced at 90 Hz like a compositor would. By default its
// session is headless, so every grab-box SDF is built on the CPU, as on an OpenGL app or a
// machine without a usable GPU. With --session vulkan it is a Vulkan session
// (XR_KHR_vulkan_enable2) on the physical device the runtime names, whose SDFs the layer builds
// on that device; with --target buffer as well, the object lives in the app's Vulkan storage
// buffers (XrGraspTargetVulkanBuffersSDFG), which the deforming phase rewrites on the binding's
// queue every frame as a skinning pass would (vulkan_app.h).
//
// For each object it runs the same script twice in one process: with the layer off (its disable
// variable set) and on (enabled explicitly from the build tree or --layer-dir, with its defaults
// but `gpu`, which --gpu sets on a Vulkan session). It times every OpenXR call the app makes per
// frame with steady_clock: xrWaitFrame, xrBeginFrame, xrSyncActions, xrLocateHandJointsEXT (both
// hands), xrGetGraspStateSDFG, the target's placement or vertex update when the phase has one,
// and xrEndFrame. The time added per frame is the on-run's frame total minus the off-run's median
// frame total of the same phase (the off run makes no extension calls: their whole cost counts
// as added).
//
// Phases: open (squeeze 0), grab (from the squeeze crossing the threshold until the grasp is
// shown; its length is the grab latency in frames), held (still), held moving (30 degrees over 60
// frames about the object's vertical axis), held deforming (vertices rescaled every frame).
//
// The outer-hand scenario ("outer", issue 27): no grab; the open hand is held 5 mm above a table
// beside four blocks (near), then pressed 2 cm into the table and slid along it into the blocks
// (touching), so the outer hand (on by default in the layer) runs in every frame and moves the
// hand in the touching phase. --room N registers N targets in all, the rest spread over a room
// (issue 26's scale: 1000 targets, the hand's 5 among them).
//
// Options: kUsage below (--help prints it). The layer and the mock runtime are found through the
// build tree's paths by default; --layer-dir and --runtime-json point at a relocated copy
// (package-for-device.sh makes one for another machine).
//
// First: it defines XR_USE_GRAPHICS_API_VULKAN before the extension's header, which declares
// XrGraspTargetVulkanBuffersSDFG only then.
#include "vulkan_app.h"

#include <openxr/openxr.h>

#include <openxr/XR_SDFG_auto_grasp.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "build_info.h"
#include "cli_options.h"
#include "frame_cost_config.h"
#include "hand/hand_model.h"
#include "hand/hand_synthesis.h"
#include "io/mesh_io.h"
#include "io/shapes.h"
#include "mock_runtime_test.h"
#include "outer_scene.h"
#include "results.h"
#include "sdf/sdf_grid.h"

namespace {

using namespace sdfg::frame_cost;
using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

constexpr auto kFramePeriod = std::chrono::nanoseconds(11'111'111);  // 90 Hz

const char* const kUsage =
    "usage: autograsp-frame-cost [--frames N] [--embedded-only] [--only NAME]... [--room N]\n"
    "                            [--session headless|vulkan] [--target arrays|buffer]\n"
    "                            [--gpu auto|on|off] [--layer-dir DIR] [--runtime-json FILE]\n"
    "                            [--meshes DIR] [--json FILE]\n"
    "  --frames N       frames per phase (default 60, at least 2; the smoke test uses a few)\n"
    "  --embedded-only  skip the research meshes (the bunny and the armadillos)\n"
    "  --meshes DIR     where the research meshes are (default: ../shared/meshes of the source\n"
    "                   tree the tool was built from)\n"
    "  --only NAME      measure only the object called NAME (repeatable); \"outer\" names the\n"
    "                   outer-hand scenario\n"
    "  --room N         the outer-hand scenario registers N targets (default 5, at least 5): 5 in\n"
    "                   the hand's box, the rest spread over a 10 x 10 m room\n"
    "  --session KIND   headless (default: every SDF built on the CPU) or vulkan (a Vulkan\n"
    "                   session on the first device the runtime names; VK_DRIVER_FILES picks\n"
    "                   the driver)\n"
    "  --target KIND    the objects as arrays (default) or, with --session vulkan, in the app's\n"
    "                   Vulkan storage buffers (XrGraspTargetVulkanBuffersSDFG); the outer-hand\n"
    "                   scenario always uses arrays\n"
    "  --gpu MODE       the layer's gpu setting for --session vulkan (default on: the device\n"
    "                   builds every target, also on a CPU device such as lavapipe)\n"
    "  --layer-dir DIR  folder of the layer's explicit manifest (default: the build tree's)\n"
    "  --runtime-json FILE  the mock runtime's manifest (default: $XR_RUNTIME_JSON, else the\n"
    "                   build tree's)\n"
    "  --json FILE      write the results as JSON (without it nothing is written)\n"
    "  --help           this text\n"
    "exit codes: 0 every object measured; 1 an object failed or the JSON could not be written;\n"
    "2 bad option, or the runtime's or the layer's manifest or library is missing\n";

double ms(Clock::duration d) {
  return std::chrono::duration<double, std::milli>(d).count();
}

// Centred at the origin and scaled so its largest extent is `extent` metres (the armadillos are
// in millimetres; every object becomes hand-sized).
Object toObject(const std::string& name, const sdfg::TriangleMesh& m, float extent) {
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const glm::vec3& p : m.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  const glm::vec3 c = (lo + hi) * 0.5f;
  const glm::vec3 size = hi - lo;
  const float s = extent / std::max(size.x, std::max(size.y, size.z));
  Object o;
  o.name = name;
  for (const glm::vec3& p : m.positions) {
    const glm::vec3 q = (p - c) * s;
    o.vertices.push_back({q.x, q.y, q.z});
  }
  o.indices = m.indices;
  return o;
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

enum class SessionKind { headless, vulkan };
enum class TargetKind { arrays, buffer };

class App {
 public:
  App(bool layer, SessionKind session) : layer_(layer), sessionKind_(session) {}
  // The session and the instance first: the layer frees what it made on the app's device in
  // xrDestroySession; then vk_'s destructor frees the buffers and the device.
  ~App() {
    if (session_ != XR_NULL_HANDLE) {
      if (running_) {
        xrRequestExitSession(session_);
        for (int i = 0; i < 10 && running_; ++i) pollEvents();
      }
      xrDestroySession(session_);
    }
    if (instance_ != XR_NULL_HANDLE) xrDestroyInstance(instance_);
  }

  bool init(std::string& error) {
    const bool vulkan = sessionKind_ == SessionKind::vulkan;
    std::vector<const char*> ext{vulkan ? XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME
                                        : XR_MND_HEADLESS_EXTENSION_NAME};
    if (layer_) {
      ext.push_back(XR_SDFG_AUTO_GRASP_EXTENSION_NAME);
      ext.push_back(XR_EXT_HAND_TRACKING_EXTENSION_NAME);
    }
    XrInstanceCreateInfo ci{XR_TYPE_INSTANCE_CREATE_INFO};
    std::strcpy(ci.applicationInfo.applicationName, "autograsp-frame-cost");
    ci.applicationInfo.apiVersion = XR_MAKE_VERSION(1, 0, 0);
    ci.enabledExtensionCount = uint32_t(ext.size());
    ci.enabledExtensionNames = ext.data();
    if (XrResult r = xrCreateInstance(&ci, &instance_); r != XR_SUCCESS) {
      error = "xrCreateInstance failed (" + std::to_string(r) + ")";
      return false;
    }
    XrSystemGetInfo sgi{XR_TYPE_SYSTEM_GET_INFO};
    sgi.formFactor = XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY;
    XrSystemId system = XR_NULL_SYSTEM_ID;
    if (xrGetSystem(instance_, &sgi, &system) != XR_SUCCESS) return fail(error, "xrGetSystem");
    XrSessionCreateInfo sci{XR_TYPE_SESSION_CREATE_INFO};
    sci.systemId = system;
    XrGraphicsBindingVulkan2KHR binding{XR_TYPE_GRAPHICS_BINDING_VULKAN2_KHR};
    if (vulkan) {
      if (!vk_.create(instance_, system, error)) return false;
      binding = vk_.binding();
      sci.next = &binding;
    }
    if (xrCreateSession(instance_, &sci, &session_) != XR_SUCCESS)
      return fail(error, "xrCreateSession");
    XrReferenceSpaceCreateInfo rs{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
    rs.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_LOCAL;
    rs.poseInReferenceSpace.orientation.w = 1;
    if (xrCreateReferenceSpace(session_, &rs, &local_) != XR_SUCCESS)
      return fail(error, "xrCreateReferenceSpace");
    // The app's own input: one float action on the squeeze, so its xrSyncActions is a real one.
    XrActionSetCreateInfo asci{XR_TYPE_ACTION_SET_CREATE_INFO};
    std::strcpy(asci.actionSetName, "app");
    std::strcpy(asci.localizedActionSetName, "App");
    if (xrCreateActionSet(instance_, &asci, &appSet_) != XR_SUCCESS)
      return fail(error, "xrCreateActionSet");
    XrPath hands[2];
    xrStringToPath(instance_, "/user/hand/left", &hands[0]);
    xrStringToPath(instance_, "/user/hand/right", &hands[1]);
    XrActionCreateInfo aci{XR_TYPE_ACTION_CREATE_INFO};
    aci.actionType = XR_ACTION_TYPE_FLOAT_INPUT;
    std::strcpy(aci.actionName, "grab");
    std::strcpy(aci.localizedActionName, "Grab");
    aci.countSubactionPaths = 2;
    aci.subactionPaths = hands;
    XrAction grab = XR_NULL_HANDLE;
    if (xrCreateAction(appSet_, &aci, &grab) != XR_SUCCESS) return fail(error, "xrCreateAction");
    XrPath profile, l, r;
    xrStringToPath(instance_, "/interaction_profiles/oculus/touch_controller", &profile);
    xrStringToPath(instance_, "/user/hand/left/input/squeeze/value", &l);
    xrStringToPath(instance_, "/user/hand/right/input/squeeze/value", &r);
    XrActionSuggestedBinding b[2] = {{grab, l}, {grab, r}};
    XrInteractionProfileSuggestedBinding sb{XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING};
    sb.interactionProfile = profile;
    sb.countSuggestedBindings = 2;
    sb.suggestedBindings = b;
    if (xrSuggestInteractionProfileBindings(instance_, &sb) != XR_SUCCESS)
      return fail(error, "xrSuggestInteractionProfileBindings");
    XrSessionActionSetsAttachInfo at{XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO};
    at.countActionSets = 1;
    at.actionSets = &appSet_;
    if (xrAttachSessionActionSets(session_, &at) != XR_SUCCESS)
      return fail(error, "xrAttachSessionActionSets");
    setScript_ = fn<PFN_xrMockRuntimeSetScriptSDFG>("xrMockRuntimeSetScriptSDFG");
    if (setScript_ == nullptr) return fail(error, "the mock runtime's scripting function");
    if (layer_) {
      createTarget_ = fn<PFN_xrCreateGraspTargetSDFG>("xrCreateGraspTargetSDFG");
      place_ = fn<PFN_xrSetGraspTargetPlacementSDFG>("xrSetGraspTargetPlacementSDFG");
      update_ = fn<PFN_xrUpdateGraspTargetVerticesSDFG>("xrUpdateGraspTargetVerticesSDFG");
      state_ = fn<PFN_xrGetGraspStateSDFG>("xrGetGraspStateSDFG");
      locate_ = fn<PFN_xrLocateHandJointsEXT>("xrLocateHandJointsEXT");
      auto createTracker = fn<PFN_xrCreateHandTrackerEXT>("xrCreateHandTrackerEXT");
      if (!createTarget_ || !place_ || !update_ || !state_ || !locate_ || !createTracker)
        return fail(error, "the layer's functions (is the layer loaded?)");
      for (int h = 0; h < 2; ++h) {
        XrHandTrackerCreateInfoEXT tci{XR_TYPE_HAND_TRACKER_CREATE_INFO_EXT};
        tci.hand = h == 0 ? XR_HAND_LEFT_EXT : XR_HAND_RIGHT_EXT;
        tci.handJointSet = XR_HAND_JOINT_SET_DEFAULT_EXT;
        if (createTracker(session_, &tci, &trackers_[h]) != XR_SUCCESS)
          return fail(error, "xrCreateHandTrackerEXT");
      }
    }
    // Until the session runs.
    for (int i = 0; i < 20 && !running_; ++i) pollEvents();
    if (!running_) return fail(error, "the session did not start");
    return true;
  }

  bool script(const std::string& text) { return setScript_(instance_, text.c_str()) == XR_SUCCESS; }

  // Creates the target (timed). False on refusal.
  bool createTarget(const Object& o, const XrPosef& pose, double& callMs) {
    return create(o, pose, target_, callMs);
  }

  // Creates one more target (timed), kept until the session ends. False on refusal.
  bool addTarget(const Object& o, const XrPosef& pose, double& callMs) {
    XrGraspTargetSDFG handle = XR_NULL_HANDLE;
    if (!create(o, pose, handle, callMs)) return false;
    others_.push_back(handle);
    return true;
  }

  // One frame, paced to 90 Hz; `before` runs first (the app's own updates of the target, timed
  // as part of the frame). Returns the app's time in OpenXR calls (ms); fills calls[name].
  template <class F>
  double frame(std::map<std::string, std::vector<double>>& calls, F before) {
    return frame(calls, before, [] { return 0.0; });
  }
  // The same, and `inFrame` (its returned time counted too) runs after xrBeginFrame, before
  // xrSyncActions: where an app submits its skinning on the binding's queue, which is the app's
  // between the frame calls.
  template <class F, class G>
  double frame(std::map<std::string, std::vector<double>>& calls, F before, G inFrame) {
    const auto frameStart = Clock::now();
    double total = 0;
    auto timed = [&](const char* name, auto&& call) {
      const auto t0 = Clock::now();
      call();
      const double d = ms(Clock::now() - t0);
      calls[name].push_back(d);
      total += d;
    };
    total += before();
    pollEvents();
    XrFrameState fs{XR_TYPE_FRAME_STATE};
    XrFrameWaitInfo wi{XR_TYPE_FRAME_WAIT_INFO};
    timed("xrWaitFrame", [&] { xrWaitFrame(session_, &wi, &fs); });
    XrFrameBeginInfo bi{XR_TYPE_FRAME_BEGIN_INFO};
    timed("xrBeginFrame", [&] { xrBeginFrame(session_, &bi); });
    total += inFrame();
    XrActiveActionSet active{appSet_, XR_NULL_PATH};
    XrActionsSyncInfo si{XR_TYPE_ACTIONS_SYNC_INFO};
    si.countActiveActionSets = 1;
    si.activeActionSets = &active;
    timed("xrSyncActions", [&] { xrSyncActions(session_, &si); });
    grasping_ = false;
    if (layer_) {
      for (int h = 0; h < 2; ++h) {
        XrHandJointsLocateInfoEXT info{XR_TYPE_HAND_JOINTS_LOCATE_INFO_EXT};
        info.baseSpace = local_;
        info.time = fs.predictedDisplayTime;
        XrHandJointLocationsEXT locations{XR_TYPE_HAND_JOINT_LOCATIONS_EXT};
        locations.jointCount = XR_HAND_JOINT_COUNT_EXT;
        locations.jointLocations = joints_.data();
        timed("xrLocateHandJointsEXT", [&] { locate_(trackers_[h], &info, &locations); });
      }
      XrGraspStateGetInfoSDFG gi{XR_TYPE_GRASP_STATE_GET_INFO_SDFG, nullptr, XR_HAND_RIGHT_EXT};
      XrGraspHandOffsetSDFG offset{XR_TYPE_GRASP_HAND_OFFSET_SDFG};
      XrGraspBuildInfoSDFG build{XR_TYPE_GRASP_BUILD_INFO_SDFG, &offset};
      XrGraspTargetsSetupInfoSDFG setup{XR_TYPE_GRASP_TARGETS_SETUP_INFO_SDFG, &build};
      XrGraspStateSDFG st{XR_TYPE_GRASP_STATE_SDFG, &setup};
      timed("xrGetGraspStateSDFG", [&] { state_(session_, &gi, &st); });
      grasping_ = st.isGrasping == XR_TRUE;
      readyCount_ = setup.readyCount;
      const XrPosef& o = offset.offset;
      handMoved_ = o.position.x != 0.0f || o.position.y != 0.0f || o.position.z != 0.0f ||
                   o.orientation.x != 0.0f || o.orientation.y != 0.0f || o.orientation.z != 0.0f;
      cpuBuilds_ = build.cpuBuildCount;
      gpuBuilds_ = build.gpuBuildCount;
      gpuReady_ = build.sessionBackend == XR_GRASP_SDF_BACKEND_VULKAN_SDFG;
      gpuFailed_ = build.gpuFailed == XR_TRUE;
      graspBackend_ = build.graspBackend;
    }
    XrFrameEndInfo ei{XR_TYPE_FRAME_END_INFO};
    ei.displayTime = fs.predictedDisplayTime;
    ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
    timed("xrEndFrame", [&] {
      if (xrEndFrame(session_, &ei) == XR_SUCCESS) ++framesEnded_;
    });
    std::this_thread::sleep_until(frameStart + kFramePeriod);
    return total;
  }

  double place(const XrPosef& pose) {
    XrGraspTargetPlacementSDFG p{XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG, nullptr, local_, pose};
    const auto t0 = Clock::now();
    place_(target_, &p);
    return ms(Clock::now() - t0);
  }

  // The object in the app's Vulkan buffers (a Vulkan session); the create call timed.
  bool createBufferTarget(const Object& o, const XrPosef& pose, double& callMs,
                          std::string& error) {
    if (!uploadBuffers(o, error)) return false;
    XrGraspTargetCreateInfoSDFG ci{XR_TYPE_GRASP_TARGET_CREATE_INFO_SDFG, &bufferDesc_};
    ci.placement = {XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG, nullptr, local_, pose};
    const auto t0 = Clock::now();
    const XrResult r = createTarget_(session_, &ci, &target_);
    callMs = ms(Clock::now() - t0);
    if (r != XR_SUCCESS)
      error = "xrCreateGraspTargetSDFG refused the Vulkan buffers (" + std::to_string(r) +
              (r == XR_ERROR_FEATURE_UNSUPPORTED ? ": the session builds on the CPU" : "") + ")";
    return r == XR_SUCCESS;
  }
  // The buffers alone (the layer-off run, so both runs do the same Vulkan work).
  bool uploadBuffers(const Object& o, std::string& error) {
    return vk_.uploadMesh(o, bufferDesc_, error);
  }
  // The skinning pass's new positions, submitted on the binding's queue (untimed: the app's own
  // work, as the arrays' rescaling is); then, with the layer, "my buffers changed" (timed).
  double updateBuffers(const std::vector<XrVector3f>& vertices, std::string& error) {
    if (!vk_.writeVertices(vertices, error)) return 0.0;
    if (!layer_) return 0.0;
    const auto t0 = Clock::now();
    const XrResult r = update_(target_, &bufferDesc_);
    const double d = ms(Clock::now() - t0);
    if (r != XR_SUCCESS)
      error = "xrUpdateGraspTargetVerticesSDFG failed (" + std::to_string(r) + ")";
    return d;
  }

  double updateVertices(const std::vector<XrVector3f>& vertices) {
    XrGraspTargetVerticesSDFG v{XR_TYPE_GRASP_TARGET_VERTICES_SDFG};
    v.vertexCount = uint32_t(vertices.size());
    v.vertices = vertices.data();
    const auto t0 = Clock::now();
    update_(target_, &v);
    return ms(Clock::now() - t0);
  }

  bool grasping() const { return grasping_; }
  bool ready() const { return readyCount_ > 0; }
  uint32_t readyCount() const { return readyCount_; }
  // The frame's XrGraspHandOffsetSDFG::offset (right hand) was not the identity.
  bool handMoved() const { return handMoved_; }
  uint64_t cpuBuilds() const { return cpuBuilds_; }
  uint64_t gpuBuilds() const { return gpuBuilds_; }
  // The session's GPU path is prepared (its next build goes to the device).
  bool gpuReady() const { return gpuReady_; }
  bool gpuFailed() const { return gpuFailed_; }
  // Where the shown grasp's field was built: "vulkan", "cpu", or "none" when not grasping.
  const char* graspBackend() const {
    return graspBackend_ == XR_GRASP_SDF_BACKEND_VULKAN_SDFG ? "vulkan"
           : graspBackend_ == XR_GRASP_SDF_BACKEND_CPU_SDFG  ? "cpu"
                                                             : "none";
  }
  const VulkanApp& vulkan() const { return vk_; }
  uint64_t framesEnded() const { return framesEnded_; }
  bool layer() const { return layer_; }

 private:
  // xrCreateGraspTargetSDFG on `o` at `pose`, the call timed.
  bool create(const Object& o, const XrPosef& pose, XrGraspTargetSDFG& handle, double& callMs) {
    XrGraspTargetVerticesSDFG v{XR_TYPE_GRASP_TARGET_VERTICES_SDFG};
    v.vertexCount = uint32_t(o.vertices.size());
    v.vertices = o.vertices.data();
    v.indexCount = uint32_t(o.indices.size());
    v.indices = o.indices.data();
    XrGraspTargetCreateInfoSDFG ci{XR_TYPE_GRASP_TARGET_CREATE_INFO_SDFG, &v};
    ci.placement = {XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG, nullptr, local_, pose};
    const auto t0 = Clock::now();
    const XrResult r = createTarget_(session_, &ci, &handle);
    callMs = ms(Clock::now() - t0);
    return r == XR_SUCCESS;
  }

  template <class F>
  F fn(const char* name) const {
    PFN_xrVoidFunction f = nullptr;
    if (xrGetInstanceProcAddr(instance_, name, &f) != XR_SUCCESS) return nullptr;
    return reinterpret_cast<F>(f);
  }
  static bool fail(std::string& error, const char* what) {
    error = std::string(what) + " failed";
    return false;
  }
  void pollEvents() {
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

  bool layer_;
  SessionKind sessionKind_;
  VulkanApp vk_;  // a Vulkan session's instance, device and buffers (the app's own)
  XrGraspTargetVulkanBuffersSDFG bufferDesc_{XR_TYPE_GRASP_TARGET_VULKAN_BUFFERS_SDFG};
  XrInstance instance_ = XR_NULL_HANDLE;
  XrSession session_ = XR_NULL_HANDLE;
  XrSpace local_ = XR_NULL_HANDLE;
  XrActionSet appSet_ = XR_NULL_HANDLE;
  bool running_ = false;
  uint64_t framesEnded_ = 0;
  bool grasping_ = false;
  uint32_t readyCount_ = 0;
  bool handMoved_ = false;
  std::vector<XrGraspTargetSDFG> others_;  // addTarget()'s
  uint64_t cpuBuilds_ = 0;                 // the session's CPU builds so far (XrGraspBuildInfoSDFG)
  uint64_t gpuBuilds_ = 0;                 // and GPU builds
  bool gpuReady_ = false;
  bool gpuFailed_ = false;
  XrGraspSdfBackendSDFG graspBackend_ = XR_GRASP_SDF_BACKEND_NONE_SDFG;
  XrGraspTargetSDFG target_ = XR_NULL_HANDLE;
  std::array<XrHandTrackerEXT, 2> trackers_{};
  std::array<XrHandJointLocationEXT, XR_HAND_JOINT_COUNT_EXT> joints_{};
  PFN_xrMockRuntimeSetScriptSDFG setScript_ = nullptr;
  PFN_xrCreateGraspTargetSDFG createTarget_ = nullptr;
  PFN_xrSetGraspTargetPlacementSDFG place_ = nullptr;
  PFN_xrUpdateGraspTargetVerticesSDFG update_ = nullptr;
  PFN_xrGetGraspStateSDFG state_ = nullptr;
  PFN_xrLocateHandJointsEXT locate_ = nullptr;
};

// How the app runs (the command line's --session, --target, --gpu, --layer-dir).
struct Settings {
  SessionKind session = SessionKind::headless;
  TargetKind target = TargetKind::arrays;
  std::string gpu = "on";  // the layer's gpu key on a Vulkan session
  std::string layerDir = SDFG_FC_LAYER_EXPLICIT_DIR;
};

void setLayer(bool on, const Settings& settings) {
  if (on) {
    unsetenv(SDFG_FC_LAYER_DISABLE_ENV);
    setenv("XR_API_LAYER_PATH", settings.layerDir.c_str(), 1);
    setenv("XR_ENABLE_API_LAYERS", SDFG_FC_LAYER_NAME, 1);
  } else {
    // Off however it is installed: explicit not enabled, implicit disabled.
    setenv(SDFG_FC_LAYER_DISABLE_ENV, "1", 1);
    unsetenv("XR_ENABLE_API_LAYERS");
  }
}

// The placement of the object: centred in the default grab box of the right hand at `grip`.
XrPosef objectPose(const XrPosef& grip, float yawRadians) {
  const sdfg::HandModel model = sdfg::HandModel::defaultAdult(sdfg::Hand::right);
  const sdfg::Pose worldFromWrist = toPose(grip) * sdfg::wristFromGrip(model).inverse();
  const glm::vec3 c =
      worldFromWrist.transformPoint(sdfg::GridBox::referenceDefault().handFromBox.position);
  const glm::quat q = glm::angleAxis(yawRadians, glm::vec3(0, 1, 0));
  return {{q.x, q.y, q.z, q.w}, {c.x, c.y, c.z}};
}

// On a Vulkan session with the layer and its GPU path wanted: frames until the path is prepared
// (pipelines made and warmed up off the app's calls; seconds on lavapipe with a cold shader
// cache), at most 60 s, so the grab is built where it would be in a running app. Its time is
// recorded apart from the target's set-up. False with `error` set when it never gets ready.
bool waitForGpu(App& app, const Settings& settings, double& prepareMs, std::string& error) {
  if (settings.session != SessionKind::vulkan || settings.gpu == "off") return true;
  std::map<std::string, std::vector<double>> ignored;
  const auto t0 = Clock::now();
  while (!app.gpuReady() && !app.gpuFailed() && Clock::now() - t0 < 60s)
    app.frame(ignored, [] { return 0.0; });
  prepareMs = ms(Clock::now() - t0);
  if (app.gpuReady()) return true;
  error = app.gpuFailed() ? "the layer's GPU path failed (its log says why)"
                          : "the layer's GPU path was not ready after 60 s";
  return false;
}

RunResult run(const Object& object, bool layer, int phaseFrames, const Settings& settings) {
  RunResult out;
  setLayer(layer, settings);
  const bool buffer = settings.target == TargetKind::buffer;
  App app(layer, settings.session);
  if (!app.init(out.error)) return out;
  out.vulkanDevice = app.vulkan().deviceName();
  out.vulkanDeviceType = app.vulkan().deviceType();
  const XrPosef grip = kGrip;
  const XrPosef pose0 = objectPose(grip, 0.0f);
  auto none = [] { return 0.0; };
  std::map<std::string, std::vector<double>> ignored;
  if (!app.script(gripLine(0, grip) + squeezeLine(0, 0.0f))) {
    out.error = "the script was refused";
    return out;
  }
  if (layer) {
    if (!waitForGpu(app, settings, out.gpuPrepareMs, out.error)) return out;
    if (buffer ? !app.createBufferTarget(object, pose0, out.createMs, out.error)
               : !app.createTarget(object, pose0, out.createMs)) {
      if (!buffer) out.error = "xrCreateGraspTargetSDFG refused the mesh";
      return out;
    }
    // The set-up runs on the layer's worker; frames go on meanwhile (at most 60 s).
    const auto t0 = Clock::now();
    while (!app.ready() && Clock::now() - t0 < 60s) app.frame(ignored, none);
    out.setupMs = ms(Clock::now() - t0);
    if (!app.ready()) {
      out.error = "the target was not ready after 60 s";
      return out;
    }
  } else {
    if (buffer && !app.uploadBuffers(object, out.error)) return out;
    app.frame(ignored, none);
  }
  // Open hand.
  uint64_t buildsBefore = app.cpuBuilds();
  uint64_t gpuBuildsBefore = app.gpuBuilds();
  auto endPhase = [&](int phase) {
    out.builds[phase] = app.cpuBuilds() - buildsBefore;
    buildsBefore = app.cpuBuilds();
    out.gpuBuilds[phase] = app.gpuBuilds() - gpuBuildsBefore;
    gpuBuildsBefore = app.gpuBuilds();
  };
  for (int i = 0; i < phaseFrames; ++i) out.frameMs[0].push_back(app.frame(out.callMs, none));
  endPhase(0);
  // Grab: the squeeze crosses the threshold at frame S (read by that frame's xrSyncActions).
  const uint64_t s = app.framesEnded();
  app.script(gripLine(0, grip) + squeezeLine(0, 0.0f) + squeezeLine(s > 0 ? s - 1 : 0, 0.0f) +
             squeezeLine(s, 1.0f));
  const int maxGrab = layer ? 900 : std::max(phaseFrames, 3);  // 10 s at 90 Hz
  for (int i = 0; i < maxGrab; ++i) {
    out.frameMs[1].push_back(app.frame(out.callMs, none));
    if (layer && app.grasping()) {
      out.grabLatencyFrames = i;  // 0: shown by the frame the squeeze crossed in
      out.grasped = true;
      out.graspBackend = app.graspBackend();
      break;
    }
  }
  if (layer && !out.grasped) {
    out.error = "no grasp within " + std::to_string(maxGrab) + " frames";
    return out;
  }
  endPhase(1);
  // Held still.
  for (int i = 0; i < phaseFrames; ++i) out.frameMs[2].push_back(app.frame(out.callMs, none));
  endPhase(2);
  // Held, moving: 30 degrees over 60 frames (scaled with --frames), about its vertical axis.
  const float turn = glm::radians(30.0f);
  for (int i = 1; i <= phaseFrames; ++i) {
    const XrPosef p = objectPose(grip, turn * float(i) / float(phaseFrames));
    out.frameMs[3].push_back(app.frame(out.callMs, [&] {
      if (!layer) return 0.0;
      const double d = app.place(p);
      out.callMs["xrSetGraspTargetPlacementSDFG"].push_back(d);
      return d;
    }));
  }
  endPhase(3);
  // Held, deforming: every vertex rescaled about the centre each frame (down to 94 %). Arrays:
  // handed over before the frame. Buffers: written on the binding's queue inside the frame,
  // then announced, as a skinned mesh's app does (docs/layer.md).
  std::vector<XrVector3f> scaled = object.vertices;
  auto timedUpdate = [&](double d) {
    out.callMs["xrUpdateGraspTargetVerticesSDFG"].push_back(d);
    out.maxUpdateCallMs = std::max(out.maxUpdateCallMs, d);
    return d;
  };
  for (int i = 1; i <= phaseFrames && out.error.empty(); ++i) {
    const float k = 1.0f - 0.06f * float(i) / float(phaseFrames);
    for (size_t v = 0; v < scaled.size(); ++v)
      scaled[v] = {object.vertices[v].x * k, object.vertices[v].y * k, object.vertices[v].z * k};
    out.frameMs[4].push_back(app.frame(
        out.callMs,
        [&] {
          if (!layer || buffer) return 0.0;
          return timedUpdate(app.updateVertices(scaled));
        },
        [&] {
          if (!buffer) return 0.0;
          const double d = app.updateBuffers(scaled, out.error);
          return layer ? timedUpdate(d) : 0.0;
        }));
  }
  if (!out.error.empty()) return out;
  endPhase(4);
  out.gpuFailed = app.gpuFailed();
  out.ok = true;
  return out;
}

// `outerHand`: the layer's outer_hand setting (through its environment variable).
OuterRun runOuter(const OuterScene& scene, bool layer, bool outerHand, int phaseFrames,
                  const Settings& settings) {
  OuterRun out;
  setLayer(layer, settings);
  if (outerHand)
    unsetenv("SDFG_AUTOGRASP_OUTER_HAND");
  else
    setenv("SDFG_AUTOGRASP_OUTER_HAND", "off", 1);
  App app(layer, settings.session);
  if (!app.init(out.error)) return out;
  out.vulkanDevice = app.vulkan().deviceName();
  out.vulkanDeviceType = app.vulkan().deviceType();
  auto none = [] { return 0.0; };
  std::map<std::string, std::vector<double>> ignored;
  if (!app.script(gripLine(0, scene.grip) + squeezeLine(0, 0.0f))) {
    out.error = "the script was refused";
    return out;
  }
  if (layer) {
    double prepareMs = 0;
    if (!waitForGpu(app, settings, prepareMs, out.error)) return out;
    const auto t0 = Clock::now();
    for (size_t i = 0; i < scene.objects.size(); ++i) {
      double call = 0;
      if (!app.addTarget(scene.objects[i], scene.poses[i], call)) {
        out.error = "xrCreateGraspTargetSDFG refused target " + std::to_string(i);
        return out;
      }
      out.createTotalMs += call;
      out.createMaxMs = std::max(out.createMaxMs, call);
    }
    // The set-ups run on the layer's worker; frames go on meanwhile (at most 120 s).
    while (app.readyCount() < scene.objects.size() && Clock::now() - t0 < 120s)
      app.frame(ignored, none);
    out.setupMs = ms(Clock::now() - t0);
    if (app.readyCount() < scene.objects.size()) {
      out.error = std::to_string(app.readyCount()) + " of " + std::to_string(scene.objects.size()) +
                  " targets ready after 120 s";
      return out;
    }
  } else {
    app.frame(ignored, none);
  }
  // Near: the open hand held 5 mm above the table, beside the blocks.
  for (int i = 0; i < phaseFrames; ++i) {
    out.frameMs[0].push_back(app.frame(out.callMs, none));
    out.movedFrames[0] += app.handMoved();
  }
  // Touching: pressed into the table and sliding along it, into the blocks at the ends.
  const uint64_t s = app.framesEnded();
  std::string script = gripLine(0, scene.grip) + squeezeLine(0, 0.0f);
  for (int i = 0; i < phaseFrames; ++i)
    script += gripLine(s + uint64_t(i), touchingGrip(scene, i, phaseFrames));
  if (!app.script(script)) {
    out.error = "the touching script was refused";
    return out;
  }
  for (int i = 0; i < phaseFrames; ++i) {
    out.frameMs[1].push_back(app.frame(out.callMs, none));
    out.movedFrames[1] += app.handMoved();
  }
  out.ok = true;
  return out;
}

// One of `names` (a, b or c), as the other options' errors say it.
CLI::Option* addChoice(CLI::App& cli, const std::string& name, std::vector<std::string> names,
                       std::string& out) {
  return cli
      .add_option_function<std::string>(
          name,
          [name, names, &out](const std::string& v) {
            if (std::find(names.begin(), names.end(), v) != names.end()) {
              out = v;
              return;
            }
            std::string expected;
            for (size_t i = 0; i < names.size(); ++i)
              expected += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
            throw CLI::ValidationError(name, "\"" + v + "\" is not " + expected);
          })
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
}

// Why the loader could not use `manifest` (a layer's or a runtime's; `section` is "api_layer" or
// "runtime"): unreadable, not JSON, no library_path, or a library_path naming no file (absolute,
// or relative to the manifest's folder, as the loader reads it); empty when it can. A bare file
// name is left to the dynamic linker's search, as the loader does.
std::string manifestProblem(const std::filesystem::path& manifest, const char* section) {
  namespace fs = std::filesystem;
  if (!fs::is_regular_file(manifest)) return manifest.string() + " does not exist";
  auto json = sdfg::tools::readJsonFile(manifest);
  if (!json) return json.error().message;
  const sdfg::tools::Json& j = *json;
  if (!j.is_object() || !j.contains(section) || !j[section].is_object() ||
      !j[section].contains("library_path") || !j[section]["library_path"].is_string())
    return manifest.string() + " has no " + section + ".library_path";
  const fs::path lib = j[section]["library_path"].get<std::string>();
  if (!lib.has_parent_path()) return {};
  const fs::path resolved = lib.is_absolute() ? lib : manifest.parent_path() / lib;
  if (fs::is_regular_file(resolved)) return {};
  std::string why = manifest.string() + " names the library " + lib.string() + ", which is not " +
                    "there" + (lib.is_absolute() ? "" : " (" + resolved.string() + ")");
  // The build tree's layer manifest names its library by absolute path: a moved copy needs one
  // beside the library with a relative path.
  if (lib.is_absolute())
    why +=
        "; a copy on another machine needs a manifest whose library_path is relative "
        "(tools/frame-cost/package-for-device.sh writes one)";
  return why;
}

// The manifest of our layer in `dir` (XR_API_LAYER_PATH: the loader reads every *.json there),
// or why there is none usable.
std::string layerDirProblem(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return dir.string() + " is not a folder";
  std::string problems;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    if (e.path().extension() != ".json") continue;
    auto json = sdfg::tools::readJsonFile(e.path());
    if (!json || !json->is_object() || !json->contains("api_layer") ||
        !(*json)["api_layer"].is_object() ||
        (*json)["api_layer"].value("name", std::string()) != SDFG_FC_LAYER_NAME)
      continue;
    const std::string why = manifestProblem(e.path(), "api_layer");
    if (why.empty()) return {};
    problems += "; " + why;
  }
  return dir.string() + " has no usable manifest of " + SDFG_FC_LAYER_NAME +
         (problems.empty() ? " (a *.json whose api_layer.name is it)" : problems);
}
}  // namespace

int main(int argc, char** argv) {
  int phaseFrames = 60;
  int room = 5;
  bool embeddedOnly = false;
  std::string json;
  std::vector<std::string> onlyNames;
  std::string sessionName = "headless", targetName = "arrays", gpu, runtimeJson;
  std::string meshesDir = SDFG_FC_SHARED_MESHES;
  Settings settings;
  CLI::App cli{"", "autograsp-frame-cost"};
  // Fewer than 2 frames per phase leave nothing to take percentiles of: raised to 2, as always.
  sdfg::tools::cli::addInteger(
      cli, "--frames", std::numeric_limits<int>::min(), std::numeric_limits<int>::max(),
      [&](long long n) { phaseFrames = std::max(2, int(n)); }, "an integer");
  cli.add_flag("--embedded-only", embeddedOnly);
  sdfg::tools::cli::addInteger(cli, "--room", room, 5, 100000);
  sdfg::tools::cli::addName(cli, "--json", json, "file name");
  sdfg::tools::cli::addRepeatable(cli, "--only", onlyNames);
  addChoice(cli, "--session", {"headless", "vulkan"}, sessionName);
  addChoice(cli, "--target", {"arrays", "buffer"}, targetName);
  addChoice(cli, "--gpu", {"auto", "on", "off"}, gpu);
  sdfg::tools::cli::addName(cli, "--layer-dir", settings.layerDir, "folder name");
  sdfg::tools::cli::addName(cli, "--runtime-json", runtimeJson, "file name");
  sdfg::tools::cli::addName(cli, "--meshes", meshesDir, "folder name");
  if (auto exit = sdfg::tools::cli::parseOrUsage(cli, argc, argv, "autograsp-frame-cost", kUsage))
    return *exit;
  auto usageError = [](const std::string& message) {
    std::fprintf(stderr, "autograsp-frame-cost: %s\n%s", message.c_str(), kUsage);
    return 2;
  };
  settings.session = sessionName == "vulkan" ? SessionKind::vulkan : SessionKind::headless;
  settings.target = targetName == "buffer" ? TargetKind::buffer : TargetKind::arrays;
  if (settings.session == SessionKind::headless && !gpu.empty())
    return usageError("--gpu: only with --session vulkan (a headless session builds on the CPU)");
  if (settings.target == TargetKind::buffer && settings.session != SessionKind::vulkan)
    return usageError(
        "--target buffer: needs --session vulkan (the buffers are the app's "
        "Vulkan buffers)");
  if (!gpu.empty()) settings.gpu = gpu;
  if (settings.target == TargetKind::buffer && settings.gpu == "off")
    return usageError(
        "--target buffer with --gpu off: the layer refuses buffer targets when "
        "it builds on the CPU");
  const std::set<std::string> only(onlyNames.begin(), onlyNames.end());
  // Where the loader finds the mock runtime: --runtime-json, else the environment's, else the
  // build tree's. Checked here so a moved copy says what is missing rather than failing in
  // xrCreateInstance.
  if (!runtimeJson.empty())
    setenv("XR_RUNTIME_JSON", runtimeJson.c_str(), 1);
  else if (std::getenv("XR_RUNTIME_JSON") == nullptr)
    setenv("XR_RUNTIME_JSON", SDFG_FC_MOCK_RUNTIME_JSON, 1);
  if (const std::string why = manifestProblem(std::getenv("XR_RUNTIME_JSON"), "runtime");
      !why.empty()) {
    std::fprintf(stderr, "autograsp-frame-cost: the runtime manifest (%s): %s\n",
                 runtimeJson.empty() ? "XR_RUNTIME_JSON or the build tree's; --runtime-json FILE"
                                     : "--runtime-json",
                 why.c_str());
    return 2;
  }
  if (const std::string why = layerDirProblem(settings.layerDir); !why.empty()) {
    std::fprintf(stderr, "autograsp-frame-cost: the layer (--layer-dir DIR): %s\n", why.c_str());
    return 2;
  }
  setenv("SDFG_MOCK_HAND_TRACKING", "absent", 1);  // controllers only: the layer makes the hands
  // The layer reads its settings' environment variables at xrCreateInstance (docs/layer.md).
  if (settings.session == SessionKind::vulkan)
    setenv("SDFG_AUTOGRASP_GPU", settings.gpu.c_str(), 1);

  std::vector<Object> objects;
  for (const sdfg::NamedMesh& m : sdfg::embeddedObjects())
    objects.push_back(toObject(m.name, m.mesh, 0.10f));
  std::vector<std::string> skipped;
  if (!embeddedOnly) {
    const std::filesystem::path dir = meshesDir;
    for (const char* file : {"stanford-bunny.obj", "stanford-armadillo-100k.obj",
                             "stanford-armadillo-400k-subdiv.obj"}) {
      const std::string name = std::filesystem::path(file).stem().string();
      if (!only.empty() && only.count(name) == 0) continue;
      if (!std::filesystem::exists(dir / file)) {
        std::printf("skipped %s: %s not found\n", name.c_str(), (dir / file).c_str());
        skipped.push_back(name);
        continue;
      }
      auto loaded = sdfg::loadMesh(dir / file);
      if (!loaded) {
        std::printf("skipped %s: %s\n", name.c_str(), loaded.error().message.c_str());
        skipped.push_back(name);
        continue;
      }
      objects.push_back(toObject(name, loaded->mesh, 0.12f));
    }
  }
  if (!only.empty())
    std::erase_if(objects, [&](const Object& o) { return only.count(o.name) == 0; });

  std::vector<MeshResult> results;
  for (const Object& o : objects) {
    MeshResult r;
    r.name = o.name;
    r.triangles = o.indices.size() / 3;
    std::printf("%s (%zu triangles): layer off...", r.name.c_str(), r.triangles);
    std::fflush(stdout);
    r.off = run(o, false, phaseFrames, settings);
    std::printf(" on...");
    std::fflush(stdout);
    r.on = run(o, true, phaseFrames, settings);
    std::printf(" done\n");
    r.ok = r.off.ok && r.on.ok;
    r.error = !r.off.ok ? "layer off: " + r.off.error : !r.on.ok ? "layer on: " + r.on.error : "";
    for (int p = 0; p < kPhaseCount; ++p) {
      r.offStats[p] = percentiles(r.off.frameMs[p]);
      r.added[p] = addedOver(r.on.frameMs[p], r.offStats[p].p50);
    }
    results.push_back(std::move(r));
  }

  // The session the figures come from, and on a Vulkan session the device (any run that made one:
  // every run's is the first the runtime names).
  SessionInfo session;
  session.session = sessionName;
  session.target = targetName;
  if (settings.session == SessionKind::vulkan) session.gpu = settings.gpu;
  for (const MeshResult& r : results)
    for (const RunResult* run : {&r.on, &r.off})
      if (session.vulkanDevice.empty() && !run->vulkanDevice.empty()) {
        session.vulkanDevice = run->vulkanDevice;
        session.vulkanDeviceType = run->vulkanDeviceType;
      }
  // `arrays`: the outer-hand scenario, whose targets are always arrays.
  auto printSession = [&](bool arrays) {
    if (settings.session != SessionKind::vulkan) return;
    std::printf("Vulkan session on %s (%s); targets %s; the layer's gpu = %s\n\n",
                session.vulkanDevice.empty() ? "no device" : session.vulkanDevice.c_str(),
                session.vulkanDeviceType.c_str(),
                settings.target == TargetKind::buffer && !arrays ? "in the app's Vulkan buffers"
                                                                 : "as arrays",
                settings.gpu.c_str());
  };

  int failures = 0;
  // The objects' table, unless only the outer-hand scenario ran.
  if (!results.empty() || !skipped.empty()) {
    std::printf(
        "\nTime the layer adds to the app's OpenXR calls per frame (ms; layer on minus the "
        "layer-off median of the phase), 90 Hz pacing, %d frames per phase; code at commit %s\n\n",
        phaseFrames, sdfg::tools::describeBuild().c_str());
    printSession(false);
    std::printf("| object | triangles | create call | set-up | grab latency (frames) |");
    for (const char* p : kPhases) std::printf(" %s p50 / p99 / max |", p);
    std::printf("\n|---|---:|---:|---:|---:|");
    for (int p = 0; p < kPhaseCount; ++p) std::printf("---|");
    std::printf("\n");
    for (const MeshResult& r : results) {
      if (!r.ok) {
        std::printf("| %s | %zu | failed: %s |\n", r.name.c_str(), r.triangles, r.error.c_str());
        ++failures;
        continue;
      }
      std::printf("| %s | %zu | %.3f ms | %.0f ms | %d |", r.name.c_str(), r.triangles,
                  r.on.createMs, r.on.setupMs, r.on.grabLatencyFrames);
      for (const Percentiles& a : r.added)
        std::printf(" %.3f / %.3f / %.3f |", a.p50, a.p99, a.max);
      std::printf("\n");
    }
    for (const std::string& s : skipped) std::printf("| %s | skipped: not found |\n", s.c_str());
  }

  std::optional<OuterResult> outer;
  if (only.empty() || only.count("outer") != 0) {
    const OuterScene scene = outerScene(room);
    OuterResult r;
    r.targets = int(scene.objects.size());
    r.inHandBox = scene.inHandBox;
    std::printf("\nouter (%d targets, %d in the hand's box): layer off...", r.targets, r.inHandBox);
    std::fflush(stdout);
    r.off = runOuter(scene, false, true, phaseFrames, settings);
    std::printf(" on...");
    std::fflush(stdout);
    r.on = runOuter(scene, true, true, phaseFrames, settings);
    std::printf(" on without the outer hand...");
    std::fflush(stdout);
    r.onWithoutOuter = runOuter(scene, true, false, phaseFrames, settings);
    unsetenv("SDFG_AUTOGRASP_OUTER_HAND");
    std::printf(" done\n");
    for (const OuterRun* run : {&r.on, &r.off})
      if (session.vulkanDevice.empty() && !run->vulkanDevice.empty()) {
        session.vulkanDevice = run->vulkanDevice;
        session.vulkanDeviceType = run->vulkanDeviceType;
      }
    r.ok = r.off.ok && r.on.ok && r.onWithoutOuter.ok;
    r.error = !r.off.ok              ? "layer off: " + r.off.error
              : !r.on.ok             ? "layer on: " + r.on.error
              : !r.onWithoutOuter.ok ? "outer hand off: " + r.onWithoutOuter.error
                                     : "";
    for (int p = 0; p < kOuterPhaseCount; ++p) {
      r.offStats[p] = percentiles(r.off.frameMs[p]);
      r.added[p] = addedOver(r.on.frameMs[p], r.offStats[p].p50);
      r.addedWithoutOuter[p] = addedOver(r.onWithoutOuter.frameMs[p], r.offStats[p].p50);
    }
    std::printf(
        "\nThe outer hand: time the layer adds per frame (ms), open hand near, then pressed into "
        "and sliding along, the targets in its box; code at commit %s\n\n",
        sdfg::tools::describeBuild().c_str());
    printSession(true);
    std::printf(
        "| layer | targets | in hand box | create calls total / max | set-up | near p50 / p99 / "
        "max | "
        "touching p50 / p99 / max | frames the hand was moved (near, touching) |\n"
        "|---|---:|---:|---:|---:|---:|---:|---:|\n");
    if (!r.ok) {
      std::printf("| on | %d | %d | failed: %s |\n", r.targets, r.inHandBox, r.error.c_str());
      ++failures;
    } else {
      auto row = [&](const char* what, const OuterRun& run,
                     const std::array<Percentiles, kOuterPhaseCount>& added) {
        std::printf("| %s | %d | %d | %.1f / %.3f ms | %.0f ms |", what, r.targets, r.inHandBox,
                    run.createTotalMs, run.createMaxMs, run.setupMs);
        for (const Percentiles& a : added)
          std::printf(" %.3f / %.3f / %.3f |", a.p50, a.p99, a.max);
        std::printf(" %d of %zu, %d of %zu |\n", run.movedFrames[0], run.frameMs[0].size(),
                    run.movedFrames[1], run.frameMs[1].size());
      };
      row("on", r.on, r.added);
      row("on, outer hand off", r.onWithoutOuter, r.addedWithoutOuter);
    }
    outer = std::move(r);
  }
  if (!json.empty()) {
    if (auto error = sdfg::tools::writeJsonFile(
            json, resultsJson(results, phaseFrames, ms(kFramePeriod), skipped,
                              outer ? &*outer : nullptr, &session))) {
      std::fprintf(stderr, "autograsp-frame-cost: %s\n", error->message.c_str());
      return 1;
    }
    std::printf("\nwrote %s\n", json.c_str());
  }
  return failures == 0 ? 0 : 1;
}
