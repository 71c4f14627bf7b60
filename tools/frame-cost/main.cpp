// autograsp-frame-cost: what the layer costs an app per frame.
//
// A minimal OpenXR app (headless session, so every grab-box SDF is built on the CPU, as on an
// OpenGL app or a machine without a usable GPU) runs through the real Khronos loader and the mock
// runtime (controllers only: the layer synthesizes the hands), paced at 90 Hz like a compositor
// would. For each object it runs the same script twice in one process: with the layer off (its
// disable variable set) and on (enabled explicitly from the build tree, with its defaults). It
// times every OpenXR call the app makes per frame with steady_clock: xrWaitFrame, xrBeginFrame,
// xrSyncActions, xrLocateHandJointsEXT (both hands), xrGetGraspStateSDFG, the target's
// placement or vertex update when the phase has one, and xrEndFrame. The time added per frame is
// the on-run's frame total minus the off-run's median frame total of the same phase (the off run
// makes no extension calls: their whole cost counts as added).
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
// Options: kUsage below (--help prints it).
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
    "                            [--json FILE]\n"
    "  --frames N       frames per phase (default 60, at least 2; the smoke test uses a few)\n"
    "  --embedded-only  skip ../shared/meshes (the bunny and the armadillos)\n"
    "  --only NAME      measure only the object called NAME (repeatable); \"outer\" names the\n"
    "                   outer-hand scenario\n"
    "  --room N         the outer-hand scenario registers N targets (default 5, at least 5): 5 in\n"
    "                   the hand's box, the rest spread over a 10 x 10 m room\n"
    "  --json FILE      write the results as JSON (without it nothing is written)\n"
    "  --help           this text\n"
    "exit codes: 0 every object measured; 1 an object failed or the JSON could not be written;\n"
    "2 bad option\n";

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

class App {
 public:
  explicit App(bool layer) : layer_(layer) {}
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
    std::vector<const char*> ext{XR_MND_HEADLESS_EXTENSION_NAME};
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

void setLayer(bool on) {
  if (on) {
    unsetenv(SDFG_FC_LAYER_DISABLE_ENV);
    setenv("XR_API_LAYER_PATH", SDFG_FC_LAYER_EXPLICIT_DIR, 1);
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

RunResult run(const Object& object, bool layer, int phaseFrames) {
  RunResult out;
  setLayer(layer);
  App app(layer);
  if (!app.init(out.error)) return out;
  const XrPosef grip = kGrip;
  const XrPosef pose0 = objectPose(grip, 0.0f);
  auto none = [] { return 0.0; };
  std::map<std::string, std::vector<double>> ignored;
  if (!app.script(gripLine(0, grip) + squeezeLine(0, 0.0f))) {
    out.error = "the script was refused";
    return out;
  }
  if (layer) {
    if (!app.createTarget(object, pose0, out.createMs)) {
      out.error = "xrCreateGraspTargetSDFG refused the mesh";
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
    app.frame(ignored, none);
  }
  // Open hand.
  uint64_t buildsBefore = app.cpuBuilds();
  auto endPhase = [&](int phase) {
    out.builds[phase] = app.cpuBuilds() - buildsBefore;
    buildsBefore = app.cpuBuilds();
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
  // Held, deforming: every vertex rescaled about the centre each frame (down to 94 %).
  std::vector<XrVector3f> scaled = object.vertices;
  for (int i = 1; i <= phaseFrames; ++i) {
    const float k = 1.0f - 0.06f * float(i) / float(phaseFrames);
    for (size_t v = 0; v < scaled.size(); ++v)
      scaled[v] = {object.vertices[v].x * k, object.vertices[v].y * k, object.vertices[v].z * k};
    out.frameMs[4].push_back(app.frame(out.callMs, [&] {
      if (!layer) return 0.0;
      const double d = app.updateVertices(scaled);
      out.callMs["xrUpdateGraspTargetVerticesSDFG"].push_back(d);
      out.maxUpdateCallMs = std::max(out.maxUpdateCallMs, d);
      return d;
    }));
  }
  endPhase(4);
  out.ok = true;
  return out;
}

// `outerHand`: the layer's outer_hand setting (through its environment variable).
OuterRun runOuter(const OuterScene& scene, bool layer, bool outerHand, int phaseFrames) {
  OuterRun out;
  setLayer(layer);
  if (outerHand)
    unsetenv("SDFG_AUTOGRASP_OUTER_HAND");
  else
    setenv("SDFG_AUTOGRASP_OUTER_HAND", "off", 1);
  App app(layer);
  if (!app.init(out.error)) return out;
  auto none = [] { return 0.0; };
  std::map<std::string, std::vector<double>> ignored;
  if (!app.script(gripLine(0, scene.grip) + squeezeLine(0, 0.0f))) {
    out.error = "the script was refused";
    return out;
  }
  if (layer) {
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
}  // namespace

int main(int argc, char** argv) {
  int phaseFrames = 60;
  int room = 5;
  bool embeddedOnly = false;
  std::string json;
  std::vector<std::string> onlyNames;
  CLI::App cli{"", "autograsp-frame-cost"};
  // Fewer than 2 frames per phase leave nothing to take percentiles of: raised to 2, as always.
  sdfg::tools::cli::addInteger(
      cli, "--frames", std::numeric_limits<int>::min(), std::numeric_limits<int>::max(),
      [&](long long n) { phaseFrames = std::max(2, int(n)); }, "an integer");
  cli.add_flag("--embedded-only", embeddedOnly);
  sdfg::tools::cli::addInteger(cli, "--room", room, 5, 100000);
  sdfg::tools::cli::addName(cli, "--json", json, "file name");
  sdfg::tools::cli::addRepeatable(cli, "--only", onlyNames);
  if (auto exit = sdfg::tools::cli::parseOrUsage(cli, argc, argv, "autograsp-frame-cost", kUsage))
    return *exit;
  const std::set<std::string> only(onlyNames.begin(), onlyNames.end());
  if (std::getenv("XR_RUNTIME_JSON") == nullptr)
    setenv("XR_RUNTIME_JSON", SDFG_FC_MOCK_RUNTIME_JSON, 1);
  setenv("SDFG_MOCK_HAND_TRACKING", "absent", 1);  // controllers only: the layer makes the hands

  std::vector<Object> objects;
  for (const sdfg::NamedMesh& m : sdfg::embeddedObjects())
    objects.push_back(toObject(m.name, m.mesh, 0.10f));
  std::vector<std::string> skipped;
  if (!embeddedOnly) {
    const std::filesystem::path dir = SDFG_FC_SHARED_MESHES;
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
    r.off = run(o, false, phaseFrames);
    std::printf(" on...");
    std::fflush(stdout);
    r.on = run(o, true, phaseFrames);
    std::printf(" done\n");
    r.ok = r.off.ok && r.on.ok;
    r.error = !r.off.ok ? "layer off: " + r.off.error : !r.on.ok ? "layer on: " + r.on.error : "";
    for (int p = 0; p < kPhaseCount; ++p) {
      r.offStats[p] = percentiles(r.off.frameMs[p]);
      r.added[p] = addedOver(r.on.frameMs[p], r.offStats[p].p50);
    }
    results.push_back(std::move(r));
  }

  int failures = 0;
  // The objects' table, unless only the outer-hand scenario ran.
  if (!results.empty() || !skipped.empty()) {
    std::printf(
        "\nTime the layer adds to the app's OpenXR calls per frame (ms; layer on minus the "
        "layer-off median of the phase), 90 Hz pacing, %d frames per phase; code at commit %s\n\n",
        phaseFrames, sdfg::tools::describeBuild().c_str());
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
    r.off = runOuter(scene, false, true, phaseFrames);
    std::printf(" on...");
    std::fflush(stdout);
    r.on = runOuter(scene, true, true, phaseFrames);
    std::printf(" on without the outer hand...");
    std::fflush(stdout);
    r.onWithoutOuter = runOuter(scene, true, false, phaseFrames);
    unsetenv("SDFG_AUTOGRASP_OUTER_HAND");
    std::printf(" done\n");
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
    if (auto error =
            sdfg::tools::writeJsonFile(json, resultsJson(results, phaseFrames, ms(kFramePeriod),
                                                         skipped, outer ? &*outer : nullptr))) {
      std::fprintf(stderr, "autograsp-frame-cost: %s\n", error->message.c_str());
      return 1;
    }
    std::printf("\nwrote %s\n", json.c_str());
  }
  return failures == 0 ? 0 : 1;
}
