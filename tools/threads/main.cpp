// autograsp-threads: what the layer's locks cost an app with two threads, and how long
// destroying a session or instance takes while the layer's worker is busy (docs/threading.md).
//
// An OpenXR app goes through the real Khronos loader, the layer (explicit, from the build tree,
// its defaults) and the mock runtime (controllers only: the layer synthesizes the hands), with a
// target held in the right hand.
//
// 1. Two threads, paced at 90 Hz: a main thread that polls events, waits frames and syncs
//    actions, and a render thread that begins the frame, locates both hands (timed) and ends it.
//    The same run twice side by side: the runtime's xrGetActionStateFloat (which the layer calls
//    inside the app's xrSyncActions, twice: one per hand) as fast as it is, then made slow on
//    purpose (the mock's call gate, --delay-us each). Printed: the render thread's locate time
//    (p50, p99, max of both hands' calls), the ratio slow / normal, and how many locates ran
//    while the main thread was inside a sync.
// 2. Destroys, each --trials times at spread moments: xrDestroySession during the set-up of 1.3
//    million triangles (four 327,680-triangle spheres), xrDestroyInstance (its session alive)
//    during it, and xrDestroySession during a 128^3 grab-box build (no time bound, every node
//    exact). Printed: the call's time (median, max) beside what the work it stopped takes whole.
//
// Usage: autograsp-threads [--frames N] [--delay-us D] [--trials N] [--quick] [--json FILE]
//   --frames N    frames of each two-thread run (default 600)
//   --delay-us D  the slow xrGetActionStateFloat, microseconds a call (default 4000)
//   --trials N    destroys of each kind (default 10)
//   --quick       small work (80k triangles, a 48^3 build): the smoke test
#include <openxr/openxr.h>

#include <openxr/XR_SDFG_auto_grasp.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "build_info.h"
#include "cli_options.h"
#include "hand/hand_model.h"
#include "hand/hand_synthesis.h"
#include "io/shapes.h"
#include "json_file.h"
#include "mock_runtime_test.h"
#include "percentiles.h"
#include "sdf/sdf_grid.h"
#include "threads_config.h"

namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

constexpr auto kFramePeriod = std::chrono::nanoseconds(11'111'111);  // 90 Hz
const XrPosef kGrip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};

double ms(Clock::duration d) {
  return std::chrono::duration<double, std::milli>(d).count();
}

using sdfg::tools::Percentiles;
using sdfg::tools::percentiles;

struct Mesh {
  std::vector<XrVector3f> vertices;
  std::vector<uint32_t> indices;
};

// `copies` spheres of `levels` subdivisions, 9 cm apart along x, centred at `centre`.
Mesh spheres(int levels, int copies, const XrVector3f& centre) {
  const sdfg::TriangleMesh one = sdfg::makeSphere(0.04f, levels);
  Mesh m;
  for (int k = 0; k < copies; ++k) {
    const uint32_t base = uint32_t(m.vertices.size());
    for (const glm::vec3& p : one.positions)
      m.vertices.push_back({p.x + centre.x + 0.09f * float(k), p.y + centre.y, p.z + centre.z});
    for (uint32_t i : one.indices) m.indices.push_back(base + i);
  }
  return m;
}

// The centre of the right hand's default grab box with the controller at kGrip.
XrVector3f boxCentre() {
  const sdfg::HandModel model = sdfg::HandModel::defaultAdult(sdfg::Hand::right);
  const sdfg::Pose grip{glm::quat(1, 0, 0, 0),
                        glm::vec3(kGrip.position.x, kGrip.position.y, kGrip.position.z)};
  const glm::vec3 c = (grip * sdfg::wristFromGrip(model).inverse())
                          .transformPoint(sdfg::GridBox::referenceDefault().handFromBox.position);
  return {c.x, c.y, c.z};
}

// A minimal app: headless session, the app's own squeeze action, both hands' trackers.
class App {
 public:
  // Layer settings (SDFG_AUTOGRASP_<KEY>) for this app's instance only.
  explicit App(const std::vector<std::pair<std::string, std::string>>& settings) {
    for (const auto& [k, v] : settings) setenv(k.c_str(), v.c_str(), 1);
    ok_ = init();
    for (const auto& [k, v] : settings) unsetenv(k.c_str());
  }
  ~App() {
    if (session != XR_NULL_HANDLE) xrDestroySession(session);
    if (instance != XR_NULL_HANDLE) xrDestroyInstance(instance);
  }
  bool ok() const { return ok_; }

  template <class F>
  F fn(const char* name) const {
    PFN_xrVoidFunction f = nullptr;
    return xrGetInstanceProcAddr(instance, name, &f) == XR_SUCCESS ? reinterpret_cast<F>(f)
                                                                   : nullptr;
  }
  bool script(const std::string& text) const {
    return fn<PFN_xrMockRuntimeSetScriptSDFG>("xrMockRuntimeSetScriptSDFG")(
               instance, text.c_str()) == XR_SUCCESS;
  }
  void gate(uint32_t delayMicroseconds) const {
    fn<PFN_xrMockRuntimeGateCallsSDFG>("xrMockRuntimeGateCallsSDFG")(
        instance, "xrGetActionStateFloat", XR_FALSE, delayMicroseconds);
  }
  bool createTarget(const Mesh& mesh, const XrVector3f& at) {
    XrGraspTargetVerticesSDFG v{XR_TYPE_GRASP_TARGET_VERTICES_SDFG};
    v.vertexCount = uint32_t(mesh.vertices.size());
    v.vertices = mesh.vertices.data();
    v.indexCount = uint32_t(mesh.indices.size());
    v.indices = mesh.indices.data();
    XrGraspTargetCreateInfoSDFG ci{XR_TYPE_GRASP_TARGET_CREATE_INFO_SDFG, &v};
    ci.placement = {XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG, nullptr, local, {{0, 0, 0, 1}, at}};
    return fn<PFN_xrCreateGraspTargetSDFG>("xrCreateGraspTargetSDFG")(session, &ci, &target) ==
           XR_SUCCESS;
  }
  // The right hand's state, with the set-up counts.
  XrGraspStateSDFG state(XrGraspTargetsSetupInfoSDFG* setup = nullptr) const {
    XrGraspStateGetInfoSDFG gi{XR_TYPE_GRASP_STATE_GET_INFO_SDFG, nullptr, XR_HAND_RIGHT_EXT};
    XrGraspStateSDFG st{XR_TYPE_GRASP_STATE_SDFG, setup};
    fn<PFN_xrGetGraspStateSDFG>("xrGetGraspStateSDFG")(session, &gi, &st);
    return st;
  }
  bool ready() const {
    XrGraspTargetsSetupInfoSDFG setup{XR_TYPE_GRASP_TARGETS_SETUP_INFO_SDFG};
    state(&setup);
    return setup.readyCount > 0;
  }
  void pollEvents() {
    XrEventDataBuffer e{XR_TYPE_EVENT_DATA_BUFFER};
    while (xrPollEvent(instance, &e) == XR_SUCCESS) {
      if (e.type == XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED &&
          reinterpret_cast<XrEventDataSessionStateChanged*>(&e)->state == XR_SESSION_STATE_READY) {
        XrSessionBeginInfo bi{XR_TYPE_SESSION_BEGIN_INFO};
        bi.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
        running = xrBeginSession(session, &bi) == XR_SUCCESS;
      }
      e = XrEventDataBuffer{XR_TYPE_EVENT_DATA_BUFFER};
    }
  }
  XrTime waitFrame() {
    XrFrameState fs{XR_TYPE_FRAME_STATE};
    XrFrameWaitInfo wi{XR_TYPE_FRAME_WAIT_INFO};
    xrWaitFrame(session, &wi, &fs);
    return fs.predictedDisplayTime;
  }
  void sync() {
    XrActiveActionSet active{appSet, XR_NULL_PATH};
    XrActionsSyncInfo si{XR_TYPE_ACTIONS_SYNC_INFO};
    si.countActiveActionSets = 1;
    si.activeActionSets = &active;
    xrSyncActions(session, &si);
  }
  // Begin, both hands (their time, ms, added to `locateMs`), end.
  void render(XrTime time, std::vector<double>& locateMs, const std::atomic<bool>& mainInSync,
              size_t& overlapped) {
    XrFrameBeginInfo bi{XR_TYPE_FRAME_BEGIN_INFO};
    xrBeginFrame(session, &bi);
    for (XrHandTrackerEXT t : trackers) {
      std::array<XrHandJointLocationEXT, XR_HAND_JOINT_COUNT_EXT> joints{};
      XrHandJointLocationsEXT locations{XR_TYPE_HAND_JOINT_LOCATIONS_EXT};
      locations.jointCount = XR_HAND_JOINT_COUNT_EXT;
      locations.jointLocations = joints.data();
      XrHandJointsLocateInfoEXT info{XR_TYPE_HAND_JOINTS_LOCATE_INFO_EXT};
      info.baseSpace = local;
      info.time = time;
      const bool during = mainInSync.load();
      const auto t0 = Clock::now();
      locate_(t, &info, &locations);
      locateMs.push_back(ms(Clock::now() - t0));
      if (during || mainInSync.load()) ++overlapped;
    }
    XrFrameEndInfo ei{XR_TYPE_FRAME_END_INFO};
    ei.displayTime = time;
    ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
    xrEndFrame(session, &ei);
  }

  XrInstance instance = XR_NULL_HANDLE;
  XrSession session = XR_NULL_HANDLE;
  XrSpace local = XR_NULL_HANDLE;
  XrActionSet appSet = XR_NULL_HANDLE;
  XrGraspTargetSDFG target = XR_NULL_HANDLE;
  std::array<XrHandTrackerEXT, 2> trackers{};
  bool running = false;

 private:
  bool init() {
    const char* ext[] = {XR_MND_HEADLESS_EXTENSION_NAME, XR_SDFG_AUTO_GRASP_EXTENSION_NAME,
                         XR_EXT_HAND_TRACKING_EXTENSION_NAME};
    XrInstanceCreateInfo ci{XR_TYPE_INSTANCE_CREATE_INFO};
    std::strcpy(ci.applicationInfo.applicationName, "autograsp-threads");
    ci.applicationInfo.apiVersion = XR_MAKE_VERSION(1, 0, 0);
    ci.enabledExtensionCount = 3;
    ci.enabledExtensionNames = ext;
    if (xrCreateInstance(&ci, &instance) != XR_SUCCESS) return false;
    XrSystemGetInfo sgi{XR_TYPE_SYSTEM_GET_INFO};
    sgi.formFactor = XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY;
    XrSystemId system = XR_NULL_SYSTEM_ID;
    XrSessionCreateInfo sci{XR_TYPE_SESSION_CREATE_INFO};
    XrReferenceSpaceCreateInfo rs{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
    rs.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_LOCAL;
    rs.poseInReferenceSpace.orientation.w = 1;
    if (xrGetSystem(instance, &sgi, &system) != XR_SUCCESS) return false;
    sci.systemId = system;
    if (xrCreateSession(instance, &sci, &session) != XR_SUCCESS ||
        xrCreateReferenceSpace(session, &rs, &local) != XR_SUCCESS)
      return false;
    // The app's own squeeze action, so its xrSyncActions syncs something of its own.
    XrActionSetCreateInfo asci{XR_TYPE_ACTION_SET_CREATE_INFO};
    std::strcpy(asci.actionSetName, "app");
    std::strcpy(asci.localizedActionSetName, "App");
    XrPath hands[2], profile, bindings[2];
    xrStringToPath(instance, "/user/hand/left", &hands[0]);
    xrStringToPath(instance, "/user/hand/right", &hands[1]);
    xrStringToPath(instance, "/interaction_profiles/oculus/touch_controller", &profile);
    xrStringToPath(instance, "/user/hand/left/input/squeeze/value", &bindings[0]);
    xrStringToPath(instance, "/user/hand/right/input/squeeze/value", &bindings[1]);
    XrActionCreateInfo aci{XR_TYPE_ACTION_CREATE_INFO};
    aci.actionType = XR_ACTION_TYPE_FLOAT_INPUT;
    std::strcpy(aci.actionName, "grab");
    std::strcpy(aci.localizedActionName, "Grab");
    aci.countSubactionPaths = 2;
    aci.subactionPaths = hands;
    XrAction grab = XR_NULL_HANDLE;
    if (xrCreateActionSet(instance, &asci, &appSet) != XR_SUCCESS ||
        xrCreateAction(appSet, &aci, &grab) != XR_SUCCESS)
      return false;
    XrActionSuggestedBinding b[2] = {{grab, bindings[0]}, {grab, bindings[1]}};
    XrInteractionProfileSuggestedBinding sb{XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING};
    sb.interactionProfile = profile;
    sb.countSuggestedBindings = 2;
    sb.suggestedBindings = b;
    XrSessionActionSetsAttachInfo at{XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO};
    at.countActionSets = 1;
    at.actionSets = &appSet;
    if (xrSuggestInteractionProfileBindings(instance, &sb) != XR_SUCCESS ||
        xrAttachSessionActionSets(session, &at) != XR_SUCCESS)
      return false;
    locate_ = fn<PFN_xrLocateHandJointsEXT>("xrLocateHandJointsEXT");
    auto createTracker = fn<PFN_xrCreateHandTrackerEXT>("xrCreateHandTrackerEXT");
    if (locate_ == nullptr || createTracker == nullptr) return false;
    for (int h = 0; h < 2; ++h) {
      XrHandTrackerCreateInfoEXT tci{XR_TYPE_HAND_TRACKER_CREATE_INFO_EXT};
      tci.hand = h == 0 ? XR_HAND_LEFT_EXT : XR_HAND_RIGHT_EXT;
      tci.handJointSet = XR_HAND_JOINT_SET_DEFAULT_EXT;
      if (createTracker(session, &tci, &trackers[size_t(h)]) != XR_SUCCESS) return false;
    }
    for (int i = 0; i < 20 && !running; ++i) pollEvents();
    return running;
  }

  PFN_xrLocateHandJointsEXT locate_ = nullptr;
  bool ok_ = false;
};

std::string scriptSqueezing() {
  char buf[256];
  std::snprintf(buf, sizeof buf, "0 right grip %g %g %g 0 0 0 1\n0 right squeeze 1\n",
                kGrip.position.x, kGrip.position.y, kGrip.position.z);
  return buf;
}

struct TwoThreads {
  Percentiles locate;
  size_t overlapped = 0;
  double syncMs = 0;  // median of the main thread's xrSyncActions
  bool ok = false;
};

// Part 1: N paced frames, main and render thread, the layer's squeeze read delayed by `delayUs`.
TwoThreads twoThreads(int frames, uint32_t delayUs) {
  TwoThreads out;
  App app({});
  if (!app.ok() || !app.script(scriptSqueezing()) ||
      !app.createTarget(spheres(3, 1, {0, 0, 0}), boxCentre()))
    return out;
  // Held before measuring: the locate then rewrites the fingers every frame.
  const auto deadline = Clock::now() + 60s;
  while (Clock::now() < deadline && !app.state().isGrasping) {
    const XrTime t = app.waitFrame();
    app.sync();
    std::vector<double> ignored;
    size_t none = 0;
    const std::atomic<bool> no{false};
    app.render(t, ignored, no, none);
    std::this_thread::sleep_for(1ms);
  }
  if (!app.state().isGrasping) return out;
  app.gate(delayUs);

  std::mutex m;
  std::condition_variable cv;
  std::optional<XrTime> frame;
  bool busy = false, done = false;
  std::atomic<bool> mainInSync{false};
  std::vector<double> locateMs;
  std::thread render([&] {
    for (;;) {
      XrTime t;
      {
        std::unique_lock lock(m);
        cv.wait(lock, [&] { return frame.has_value() || done; });
        if (!frame) return;
        t = *std::exchange(frame, std::nullopt);
      }
      app.render(t, locateMs, mainInSync, out.overlapped);
      std::lock_guard lock(m);
      busy = false;
      cv.notify_all();
    }
  });
  std::vector<double> syncMs;
  for (int i = 0; i < frames; ++i) {
    const auto start = Clock::now();
    app.pollEvents();
    {
      std::unique_lock lock(m);
      cv.wait(lock, [&] { return !busy; });
    }
    const XrTime t = app.waitFrame();
    {
      std::lock_guard lock(m);
      frame = t;
      busy = true;
      cv.notify_all();
    }
    mainInSync = true;
    const auto s0 = Clock::now();
    app.sync();
    syncMs.push_back(ms(Clock::now() - s0));
    mainInSync = false;
    std::this_thread::sleep_until(start + kFramePeriod);
  }
  {
    std::unique_lock lock(m);
    cv.wait(lock, [&] { return !busy; });
    done = true;
    cv.notify_all();
  }
  render.join();
  app.gate(0);
  out.locate = percentiles(locateMs);
  out.syncMs = percentiles(syncMs).p50;
  out.ok = true;
  return out;
}

struct Destroys {
  Percentiles callMs;
  double wholeMs = 0;  // the work the destroy stopped, run to its end
  int trials = 0;
};

// Part 2, set-ups: `instance` false destroys the session, true the instance (session alive).
Destroys destroyDuringSetup(const Mesh& mesh, int trials, bool instance) {
  Destroys out;
  {
    App app({});
    if (!app.ok()) return out;
    const auto t0 = Clock::now();
    app.createTarget(mesh, {0, 0, -1});
    while (!app.ready() && Clock::now() - t0 < 300s) std::this_thread::sleep_for(1ms);
    out.wholeMs = ms(Clock::now() - t0);
  }
  std::vector<double> callMs;
  for (int k = 0; k < trials; ++k) {
    App app({});
    if (!app.ok() || !app.createTarget(mesh, {0, 0, -1})) continue;
    // Spread over the first 90 % of the set-up.
    const double at = out.wholeMs * 0.9 * (k + 0.5) / trials;
    std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(at));
    const auto t0 = Clock::now();
    if (instance) {
      xrDestroyInstance(app.instance);
      app.instance = XR_NULL_HANDLE;
      app.session = XR_NULL_HANDLE;
    } else {
      xrDestroySession(app.session);
      app.session = XR_NULL_HANDLE;
    }
    callMs.push_back(ms(Clock::now() - t0));
  }
  out.callMs = percentiles(callMs);
  out.trials = int(callMs.size());
  return out;
}

// Part 2, builds: a `resolution`^3 grab-box build, every node exact, no time bound.
Destroys destroyDuringBuild(int trials, int resolution) {
  Destroys out;
  const std::vector<std::pair<std::string, std::string>> settings = {
      {"SDFG_AUTOGRASP_RESOLUTION", std::to_string(resolution)},
      {"SDFG_AUTOGRASP_SDF_FAR_BAND", "0"},
      {"SDFG_AUTOGRASP_BUILD_TIME_LIMIT_MS", "600000"}};
  const Mesh sphere = spheres(5, 1, {0, 0, 0});
  // Grabbed with the squeeze already on: the build starts at the first sync after the set-up.
  auto grab = [&](App& app) {
    if (!app.ok() || !app.script(scriptSqueezing()) || !app.createTarget(sphere, boxCentre()))
      return false;
    const auto t0 = Clock::now();
    while (!app.ready() && Clock::now() - t0 < 60s) std::this_thread::sleep_for(1ms);
    app.waitFrame();
    app.sync();
    return true;
  };
  {
    App app(settings);
    if (!grab(app)) return out;
    const auto t0 = Clock::now();
    while (!app.state().isGrasping && Clock::now() - t0 < 300s) {
      app.waitFrame();
      app.sync();
      std::this_thread::sleep_for(1ms);
    }
    out.wholeMs = ms(Clock::now() - t0);
  }
  std::vector<double> callMs;
  for (int k = 0; k < trials; ++k) {
    App app(settings);
    if (!grab(app)) continue;
    std::this_thread::sleep_for(
        std::chrono::duration<double, std::milli>(out.wholeMs * 0.9 * (k + 0.5) / trials));
    const auto t0 = Clock::now();
    xrDestroySession(app.session);
    callMs.push_back(ms(Clock::now() - t0));
    app.session = XR_NULL_HANDLE;
  }
  out.callMs = percentiles(callMs);
  out.trials = int(callMs.size());
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  int frames = 600, trials = 10;
  uint32_t delayUs = 4000;
  bool quick = false;
  std::string json;
  const char* const usage =
      "usage: autograsp-threads [--frames N] [--delay-us D] [--trials N] [--quick] "
      "[--json FILE]\n"
      "  --frames N     frames per run, 10..100000 (default 600)\n"
      "  --delay-us D   how long the gated runtime call takes, 1..1000000 us (default 4000)\n"
      "  --trials N     destroys per kind, 1..1000 (default 10)\n"
      "  --quick        a short run (the smoke test)\n"
      "  --json FILE    write the figures as JSON\n";
  CLI::App cli{"", "autograsp-threads"};
  sdfg::tools::cli::addInteger(cli, "--frames", frames, 10, 100000);
  sdfg::tools::cli::addInteger(cli, "--delay-us", delayUs, 1, 1000000);
  sdfg::tools::cli::addInteger(cli, "--trials", trials, 1, 1000);
  cli.add_flag("--quick", quick);
  sdfg::tools::cli::addName(cli, "--json", json, "file name");
  if (auto exit = sdfg::tools::cli::parseOrUsage(cli, argc, argv, "autograsp-threads", usage))
    return *exit;
  if (std::getenv("XR_RUNTIME_JSON") == nullptr)
    setenv("XR_RUNTIME_JSON", SDFG_THREADS_MOCK_RUNTIME_JSON, 1);
  setenv("SDFG_MOCK_HAND_TRACKING", "absent", 1);
  unsetenv(SDFG_THREADS_LAYER_DISABLE_ENV);
  setenv("XR_API_LAYER_PATH", SDFG_THREADS_LAYER_EXPLICIT_DIR, 1);
  setenv("XR_ENABLE_API_LAYERS", "XR_APILAYER_SDFG_autograsp", 1);

  std::printf("two threads, %d frames at 90 Hz each run...\n", frames);
  std::fflush(stdout);
  const TwoThreads normal = twoThreads(frames, 0);
  const TwoThreads slow = twoThreads(frames, delayUs);
  std::printf("destroys, %d trials each...\n", trials);
  std::fflush(stdout);
  // --quick (the smoke test): smaller work, the same code paths.
  const Mesh million = spheres(quick ? 5 : 7, 4, {0, 0, 0});
  const int resolution = quick ? 48 : 128;
  const Destroys sessionSetup = destroyDuringSetup(million, trials, false);
  const Destroys instanceSetup = destroyDuringSetup(million, trials, true);
  const Destroys sessionBuild = destroyDuringBuild(trials, resolution);
  const std::string setupName = std::to_string(million.indices.size() / 3) + " triangles";
  const std::string buildName = std::to_string(resolution) + "^3 exact build";
  if (!normal.ok || !slow.ok) {
    std::fprintf(stderr, "the two-thread runs failed (no grasp?)\n");
    return 1;
  }
  const double ratio = normal.locate.p99 > 0 ? slow.locate.p99 / normal.locate.p99 : 0.0;
  std::printf(
      "\nRender thread's xrLocateHandJointsEXT (ms, both hands' calls) while the main "
      "thread syncs\n\n");
  std::printf(
      "| runtime's xrGetActionStateFloat | main's xrSyncActions p50 | locates | during a "
      "sync | locate p50 | p99 | max |\n|---|---:|---:|---:|---:|---:|---:|\n");
  std::printf("| as fast as it is | %.3f | %zu | %zu | %.4f | %.4f | %.4f |\n", normal.syncMs,
              normal.locate.count, normal.overlapped, normal.locate.p50, normal.locate.p99,
              normal.locate.max);
  std::printf("| %.1f ms a call | %.3f | %zu | %zu | %.4f | %.4f | %.4f |\n", delayUs / 1000.0,
              slow.syncMs, slow.locate.count, slow.overlapped, slow.locate.p50, slow.locate.p99,
              slow.locate.max);
  std::printf("\nlocate p99, slow sync / normal sync: %.2f\n", ratio);
  std::printf(
      "\nDestroy calls while the layer's worker is busy (ms)\n\n| call | during | "
      "trials | p50 | max | the work run whole |\n|---|---|---:|---:|---:|---:|\n");
  const auto row = [](const char* call, const char* during, const Destroys& d) {
    std::printf("| %s | %s | %d | %.2f | %.2f | %.0f |\n", call, during, d.trials, d.callMs.p50,
                d.callMs.max, d.wholeMs);
  };
  row("xrDestroySession", ("set-up of " + setupName).c_str(), sessionSetup);
  row("xrDestroyInstance", ("set-up of " + setupName).c_str(), instanceSetup);
  row("xrDestroySession", buildName.c_str(), sessionBuild);
  if (!json.empty()) {
    using sdfg::tools::Json;
    using sdfg::tools::jsonNumber;
    const auto locate = [](const TwoThreads& o) {
      return Json{{"p50_ms", jsonNumber(o.locate.p50)},
                  {"p99_ms", jsonNumber(o.locate.p99)},
                  {"max_ms", jsonNumber(o.locate.max)},
                  {"during_sync", o.overlapped},
                  {"sync_p50_ms", jsonNumber(o.syncMs)}};
    };
    const auto destroys = [](const Destroys& x) {
      return Json{{"trials", x.trials},
                  {"p50_ms", jsonNumber(x.callMs.p50)},
                  {"max_ms", jsonNumber(x.callMs.max)},
                  {"whole_ms", jsonNumber(x.wholeMs)}};
    };
    const Json out{{"tool", "autograsp-threads"},
                   {"provenance", sdfg::tools::provenanceJson()},
                   {"frames", frames},
                   {"delay_us", delayUs},
                   {"hardware_threads", std::thread::hardware_concurrency()},
                   {"locate_normal", locate(normal)},
                   {"locate_slow_sync", locate(slow)},
                   {"locate_p99_ratio", jsonNumber(ratio)},
                   {"destroys",
                    {{"session_during_setup", destroys(sessionSetup)},
                     {"instance_during_setup", destroys(instanceSetup)},
                     {"session_during_build", destroys(sessionBuild)}}}};
    if (auto error = sdfg::tools::writeJsonFile(json, out)) {
      std::fprintf(stderr, "autograsp-threads: %s\n", error->message.c_str());
      return 1;
    }
    std::printf("\nwrote %s\n", json.c_str());
  }
  return 0;
}
