#include "xr_harness.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace sdfg::test {
namespace {

std::string gWorkDir;

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
  fs::copy_file(SDFG_LAYER_JSON, implicit / "XrApiLayer_sdfg_autograsp.json",
                fs::copy_options::overwrite_existing);
  setenv("XDG_DATA_HOME", (fs::path(dir) / "data").c_str(), 1);
  setenv("XDG_DATA_DIRS", "/usr/share", 1);  // core validation's explicit manifest
  setenv("XDG_CONFIG_DIRS", (fs::path(dir) / "no-config").c_str(), 1);
  setenv("XDG_CONFIG_HOME", (fs::path(dir) / "config").c_str(), 1);
  setenv("XR_RUNTIME_JSON", SDFG_MOCK_RUNTIME_JSON, 1);
  setenv("XR_ENABLE_API_LAYERS", "XR_APILAYER_LUNARG_core_validation", 1);
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
  for (const auto& [k, v] : env.extra) setenv(k.c_str(), v.c_str(), 1);
  return cv;
}

std::string validationLog() {
  std::ifstream in(workDir() + "/core-validation.txt");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

App::App(const AppOptions& options) {
  std::vector<const char*> ext{XR_MND_HEADLESS_EXTENSION_NAME};
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
  if (instance != XR_NULL_HANDLE) xrDestroyInstance(instance);
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

void App::frame() {
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
  XrFrameEndInfo ei{XR_TYPE_FRAME_END_INFO};
  ei.displayTime = fs.predictedDisplayTime;
  ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
  if (xrEndFrame(session, &ei) == XR_SUCCESS) ++framesEnded;
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
