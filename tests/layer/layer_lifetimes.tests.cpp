// Lifetimes of what the layer holds: a target whose space the app destroys (never passed down
// again, with the Khronos core validation layer below to say so), destroying a session or
// instance while the layer's worker is busy (returns well before the work would have ended), and a
// failure of the layer after the runtime made an object (the object is given back).
#include <catch2/catch.hpp>

#include <chrono>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "grasp_checks.h"
#include "mock_checks.h"
#include "test_scenes.h"
#include "xr_harness.h"

namespace {

using namespace sdfg::test;
using namespace std::chrono_literals;

const XrPosef kGrip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};

XrEnv squeezingRight(std::vector<std::pair<std::string, std::string>> extra = {}) {
  XrEnv env;
  env.handTracking = "absent";
  env.script = gripLine(0, "right", kGrip) + squeezeLine(0, "right", 0.0f) +
               squeezeLine(2, "right", 0.0f) + squeezeLine(3, "right", 1.0f);
  env.extra = std::move(extra);
  return env;
}

XrGraspTargetStateSDFG targetState(const App& app, XrGraspTargetSDFG target,
                                   XrResult* result = nullptr) {
  auto get = app.fn<PFN_xrGetGraspTargetStateSDFG>("xrGetGraspTargetStateSDFG");
  REQUIRE(get != nullptr);
  XrGraspTargetStateSDFG st{XR_TYPE_GRASP_TARGET_STATE_SDFG};
  const XrResult r = get(target, &st);
  if (result != nullptr)
    *result = r;
  else
    REQUIRE(r == XR_SUCCESS);
  return st;
}

XrGraspStateSDFG graspState(const App& app, const Ext& ext) {
  XrGraspStateGetInfoSDFG gi{XR_TYPE_GRASP_STATE_GET_INFO_SDFG, nullptr, XR_HAND_RIGHT_EXT};
  XrGraspStateSDFG st{XR_TYPE_GRASP_STATE_SDFG};
  REQUIRE(ext.state(app.session, &gi, &st) == XR_SUCCESS);
  return st;
}

// One 327,680-triangle sphere.
const TestMesh& quarterMillionTriangles() {
  static const TestMesh mesh = makeIcosphere(0.04f, 7);
  return mesh;
}

// Four of those side by side (1.3 million triangles): a set-up of seconds on the 2-core machine,
// far longer under the sanitizers.
const TestMesh& millionTriangles() {
  static const TestMesh mesh = [] {
    const TestMesh& one = quarterMillionTriangles();
    TestMesh all;
    for (int k = 0; k < 4; ++k) {
      const uint32_t base = uint32_t(all.vertices.size());
      for (const XrVector3f& v : one.vertices) all.vertices.push_back({v.x + 0.09f * k, v.y, v.z});
      for (uint32_t i : one.indices) all.indices.push_back(base + i);
    }
    return all;
  }();
  return mesh;
}

// What the set-up of millionTriangles() takes run whole, for destroyBoundMs(): four times the
// set-up of one of its spheres (a set-up is at least linear in the triangles), measured once per
// process, a quarter of the cost of running the whole.
double wholeMillionSetUpMs() {
  static const double ms = 4 * wholeSetUpMs(squeezingRight(), quarterMillionTriangles());
  return ms;
}

// How long a grab of `mesh` at `pose` takes from the squeeze to the grasp shown, in a session of
// its own made with `env`: its grab-box build and solve run whole (destroyBoundMs()).
double wholeGrabMs(const XrEnv& env, const TestMesh& mesh, const XrPosef& pose) {
  applyEnv(env);
  App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
  REQUIRE(app.ok());
  Ext ext(app);
  makeTarget(app, ext, mesh, pose);
  REQUIRE(untilSetUp(
      app, ext, [](const auto& s) { return s.readyCount == 1; }, std::chrono::minutes(10)));
  const auto start = std::chrono::steady_clock::now();
  REQUIRE(framesUntilGrasping(app, ext, XR_HAND_RIGHT_EXT, true, std::chrono::minutes(10)));
  return msSince(start);
}

}  // namespace

TEST_CASE(
    "A target whose space the app destroys is never located again and is grasped once "
    "placed again",
    "[layer][lifetimes]") {
  applyEnv(squeezingRight());
  App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
  REQUIRE(app.ok());
  Ext ext(app);
  makeTracker(app, ext, XR_HAND_RIGHT_EXT);
  // The target sits in a space of its own, which the app destroys while a hand holds it.
  XrSpace anchor = XR_NULL_HANDLE;
  XrReferenceSpaceCreateInfo rs{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
  rs.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_LOCAL;
  rs.poseInReferenceSpace.orientation.w = 1;
  REQUIRE(xrCreateReferenceSpace(app.session, &rs, &anchor) == XR_SUCCESS);
  const XrVector3f centre = boxCentreInLocal(kGrip, true);
  XrGraspTargetVerticesSDFG v{XR_TYPE_GRASP_TARGET_VERTICES_SDFG};
  const TestMesh sphere = makeIcosphere(0.04f, 3);
  v.vertexCount = uint32_t(sphere.vertices.size());
  v.vertices = sphere.vertices.data();
  v.indexCount = uint32_t(sphere.indices.size());
  v.indices = sphere.indices.data();
  XrGraspTargetCreateInfoSDFG ci{XR_TYPE_GRASP_TARGET_CREATE_INFO_SDFG, &v};
  ci.placement = {XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG, nullptr, anchor, {{0, 0, 0, 1}, centre}};
  XrGraspTargetSDFG target = XR_NULL_HANDLE;
  REQUIRE(ext.create(app.session, &ci, &target) == XR_SUCCESS);
  REQUIRE(framesUntilGrasping(app, ext, XR_HAND_RIGHT_EXT));
  CHECK(targetState(app, target).isPlaced == XR_TRUE);

  REQUIRE(xrDestroySpace(anchor) == XR_SUCCESS);
  // The hand lets go at once, and the target says why it takes no part.
  CHECK_FALSE(graspState(app, ext).isGrasping);
  CHECK(targetState(app, target).isPlaced == XR_FALSE);
  // Frames go on with the squeeze held: the target is never grabbed, and never located in the
  // destroyed space (core validation below the layer would log VUID-xrLocateSpace-space-parameter
  // once a frame if it were).
  app.frames(60);
  CHECK_FALSE(graspState(app, ext).isGrasping);
  CHECK(targetState(app, target).isPlaced == XR_FALSE);
  CHECK(validationLog().empty());
  bool released = false;
  for (const XrEventDataBuffer& e : app.events) {
    if (e.type != XR_TYPE_EVENT_DATA_GRASP_CHANGED_SDFG) continue;
    const auto& g = reinterpret_cast<const XrEventDataGraspChangedSDFG&>(e);
    if (g.target == target && !g.isGrasping) {
      released = true;
      CHECK(g.reason == XR_GRASP_CHANGE_REASON_RELEASED_SDFG);
    }
  }
  CHECK(released);
  // The destroyed space is refused as a placement; a live one places the target again.
  XrGraspTargetPlacementSDFG dead{
      XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG, nullptr, anchor, {{0, 0, 0, 1}, centre}};
  CHECK(ext.place(target, &dead) == XR_ERROR_HANDLE_INVALID);
  CHECK(targetState(app, target).isPlaced == XR_FALSE);
  XrGraspTargetPlacementSDFG live{
      XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG, nullptr, app.local, {{0, 0, 0, 1}, centre}};
  const XrTime placedAt = app.lastTime;
  REQUIRE(ext.place(target, &live) == XR_SUCCESS);
  CHECK(targetState(app, target).isPlaced == XR_TRUE);
  CHECK(framesUntilGrasping(app, ext, XR_HAND_RIGHT_EXT));
  // The 60 frames showed no grab only as far as the worker had answered by then. It has answered
  // this placement's grab now, so a grab wrongly asked for while the target was not placed would
  // have shown first: as a grab event older than the placement.
  const auto grabsSinceRelease = [&] {
    std::vector<XrTime> times;
    bool released = false;
    for (const XrEventDataBuffer& e : app.events) {
      if (e.type != XR_TYPE_EVENT_DATA_GRASP_CHANGED_SDFG) continue;
      const auto& g = reinterpret_cast<const XrEventDataGraspChangedSDFG&>(e);
      if (g.target != target) continue;
      if (!g.isGrasping) released = true;
      if (g.isGrasping && released) times.push_back(g.time);
    }
    return times;
  };
  REQUIRE(app.framesUntil([&] { return !grabsSinceRelease().empty(); }));
  for (const XrTime t : grabsSinceRelease()) CHECK(t > placedAt);
  CHECK(validationLog().empty());
}

TEST_CASE("xrGetGraspTargetStateSDFG refuses bad input and changes nothing", "[layer][lifetimes]") {
  applyEnv(squeezingRight());
  App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
  REQUIRE(app.ok());
  Ext ext(app);
  auto get = app.fn<PFN_xrGetGraspTargetStateSDFG>("xrGetGraspTargetStateSDFG");
  REQUIRE(get != nullptr);
  const XrGraspTargetSDFG target =
      makeTarget(app, ext, makeIcosphere(0.04f, 2), {{0, 0, 0, 1}, {0, 0, -1}});
  XrGraspTargetStateSDFG st{XR_TYPE_GRASP_TARGET_STATE_SDFG};
  st.isPlaced = 55;  // a sentinel: a refused call must not write it
  CHECK(get(target, nullptr) == XR_ERROR_VALIDATION_FAILURE);
  XrGraspTargetStateSDFG wrong{XR_TYPE_GRASP_STATE_SDFG};
  wrong.isPlaced = 55;
  CHECK(get(target, &wrong) == XR_ERROR_VALIDATION_FAILURE);
  CHECK(wrong.isPlaced == 55u);
  XrGraspTargetStateSDFG cyclic{XR_TYPE_GRASP_TARGET_STATE_SDFG, &cyclic};
  CHECK(get(target, &cyclic) == XR_ERROR_VALIDATION_FAILURE);
  CHECK(get(XR_NULL_HANDLE, &st) == XR_ERROR_HANDLE_INVALID);
  CHECK(get(reinterpret_cast<XrGraspTargetSDFG>(app.session), &st) == XR_ERROR_HANDLE_INVALID);
  CHECK(st.isPlaced == 55u);
  REQUIRE(ext.destroy(target) == XR_SUCCESS);
  CHECK(get(target, &st) == XR_ERROR_HANDLE_INVALID);
  CHECK(st.isPlaced == 55u);
  CHECK(validationLog().empty());
}

TEST_CASE("Destroying a session or an instance while its worker is busy returns within a bound",
          "[layer][lifetimes]") {
  SECTION("the session, during the set-up of 1.3 million triangles") {
    const double wholeMs = wholeMillionSetUpMs();
    applyEnv(squeezingRight());
    App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
    REQUIRE(app.ok());
    Ext ext(app);
    makeTarget(app, ext, millionTriangles(), {{0, 0, 0, 1}, {0, 0, -1}});
    app.frames(2);
    REQUIRE(setupInfo(app, ext).pendingCount == 1);  // not finished: seconds of work left
    const auto start = std::chrono::steady_clock::now();
    app.destroySession();
    const double destroyMs = msSince(start);
    CAPTURE(wholeMs);
    CHECK(destroyMs < destroyBoundMs(wholeMs));
    CHECK(validationLog().empty());
  }
  SECTION("the instance, its session still alive, during the set-up") {
    const double wholeMs = wholeMillionSetUpMs();
    applyEnv(squeezingRight());
    App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
    REQUIRE(app.ok());
    Ext ext(app);
    makeTarget(app, ext, millionTriangles(), {{0, 0, 0, 1}, {0, 0, -1}});
    app.frames(2);
    REQUIRE(setupInfo(app, ext).pendingCount == 1);
    const auto start = std::chrono::steady_clock::now();
    app.destroyInstance();
    const double destroyMs = msSince(start);
    CAPTURE(wholeMs);
    CHECK(destroyMs < destroyBoundMs(wholeMs));
  }
  SECTION("the session, during a 128^3 grab-box build") {
    // With no time bound to end it first (10 minutes), the build of 2 million exact nodes runs
    // for seconds; the grab starts it as soon as the set-up is ready and the squeeze is on.
    const XrEnv env = squeezingRight({{"SDFG_AUTOGRASP_BUILD_TIME_LIMIT_MS", "600000"},
                                      {"SDFG_AUTOGRASP_RESOLUTION", "128"},
                                      {"SDFG_AUTOGRASP_SDF_FAR_BAND", "0"}});
    const TestMesh ball = makeIcosphere(0.04f, 5);
    const XrPosef pose{{0, 0, 0, 1}, boxCentreInLocal(kGrip, true)};
    // What the grab's build takes run whole, for destroyBoundMs(): eight times a 64^3 grab (an
    // eighth of the nodes, each an exact distance; its solve and the frames count eight times
    // over, which only widens the bound), at an eighth of the cost of running the whole.
    XrEnv coarse = env;
    for (auto& [name, value] : coarse.extra)
      if (name == "SDFG_AUTOGRASP_RESOLUTION") value = "64";
    const double wholeMs = 8 * wholeGrabMs(coarse, ball, pose);
    applyEnv(env);
    App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
    REQUIRE(app.ok());
    Ext ext(app);
    makeTarget(app, ext, ball, pose);
    REQUIRE(untilSetUp(app, ext, [](const auto& s) { return s.readyCount == 1; }));
    app.frames(5);  // the squeeze is on from frame 3: the grab's job is on the worker
    std::this_thread::sleep_for(100ms);
    REQUIRE_FALSE(graspState(app, ext).isGrasping);  // its build has not finished
    const auto start = std::chrono::steady_clock::now();
    app.destroySession();
    const double destroyMs = msSince(start);
    CAPTURE(wholeMs);
    CHECK(destroyMs < destroyBoundMs(wholeMs));
    CHECK(validationLog().empty());
  }
}

TEST_CASE("A failure of the layer after the runtime made an object gives it back",
          "[layer][lifetimes]") {
  // test_layer_fault makes the layer's test build throw right after the call down succeeded (the
  // shipped library has no such key: layer/test_fault.h). The mock runtime takes one instance and
  // one session at a time: a second attempt that gets the layer's error again (not
  // XR_ERROR_LIMIT_REACHED) shows the first object was destroyed.
  const auto fault = [](const char* point, const char* tracking = "absent") {
    XrEnv env = squeezingRight({{"SDFG_AUTOGRASP_TEST_LAYER_FAULT", point}});
    env.testBuild = true;
    env.handTracking = tracking;
    applyEnv(env);
  };
  SECTION("an instance") {
    fault("after_create_instance");
    const char* exts[] = {XR_MND_HEADLESS_EXTENSION_NAME, XR_SDFG_AUTO_GRASP_EXTENSION_NAME};
    XrInstanceCreateInfo ci{XR_TYPE_INSTANCE_CREATE_INFO};
    std::strcpy(ci.applicationInfo.applicationName, "sdfg layer test");
    ci.applicationInfo.apiVersion = XR_MAKE_VERSION(1, 0, 0);
    ci.enabledExtensionCount = 2;
    ci.enabledExtensionNames = exts;
    for (int attempt = 0; attempt < 2; ++attempt) {
      CAPTURE(attempt);
      XrInstance instance = XR_NULL_HANDLE;
      CHECK(xrCreateInstance(&ci, &instance) == XR_ERROR_RUNTIME_FAILURE);
      CHECK(instance == XR_NULL_HANDLE);
    }
    fault("none");
    XrInstance instance = XR_NULL_HANDLE;
    REQUIRE(xrCreateInstance(&ci, &instance) == XR_SUCCESS);
    CHECK(xrDestroyInstance(instance) == XR_SUCCESS);
    CHECK(validationLog().empty());
  }
  SECTION("a session") {
    fault("after_create_session");
    App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
    REQUIRE_FALSE(app.ok());
    CHECK(app.session == XR_NULL_HANDLE);
    XrSessionCreateInfo sci{XR_TYPE_SESSION_CREATE_INFO};
    sci.systemId = app.system;
    XrSession again = XR_NULL_HANDLE;
    CHECK(xrCreateSession(app.instance, &sci, &again) == XR_ERROR_RUNTIME_FAILURE);
    CHECK(again == XR_NULL_HANDLE);
  }
  SECTION("a reference space") {
    fault("after_create_space");
    App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
    REQUIRE_FALSE(app.ok());  // its LOCAL space failed
    REQUIRE(app.session != XR_NULL_HANDLE);
    CHECK(app.local == XR_NULL_HANDLE);
    CHECK(mockStats(app).liveSpaces == 0);
    XrReferenceSpaceCreateInfo rs{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
    rs.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_LOCAL;
    rs.poseInReferenceSpace.orientation.w = 1;
    XrSpace space = XR_NULL_HANDLE;
    CHECK(xrCreateReferenceSpace(app.session, &rs, &space) == XR_ERROR_RUNTIME_FAILURE);
    CHECK(space == XR_NULL_HANDLE);
    CHECK(mockStats(app).liveSpaces == 0);
  }
  SECTION("a hand tracker of the runtime") {
    fault("after_create_tracker", "1");
    App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
    REQUIRE(app.ok());
    Ext ext(app);
    XrHandTrackerCreateInfoEXT ci{XR_TYPE_HAND_TRACKER_CREATE_INFO_EXT};
    ci.hand = XR_HAND_RIGHT_EXT;
    ci.handJointSet = XR_HAND_JOINT_SET_DEFAULT_EXT;
    XrHandTrackerEXT tracker = XR_NULL_HANDLE;
    CHECK(ext.createTracker(app.session, &ci, &tracker) == XR_ERROR_RUNTIME_FAILURE);
    CHECK(tracker == XR_NULL_HANDLE);
    // No frame ran, so the layer made no tracker of its own either.
    CHECK(mockStats(app).liveHandTrackers == 0);
  }
}

// [shipped]: left out under Wine, whose loader tests load the layer's test build
// (tests/windows/CMakeLists.txt).
TEST_CASE("The shipped layer has no test fault: test_layer_fault changes nothing",
          "[layer][lifetimes][shipped]") {
  // The variable that makes the test build fail at each point, given to the shipped library: the
  // app gets its instance, session, LOCAL space and tracker, from a layer that is there (the
  // app's enabled XR_SDFG_auto_grasp is the layer's own).
  for (const char* point : {"after_create_instance", "after_create_session", "after_create_space",
                            "after_create_tracker"}) {
    CAPTURE(point);
    XrEnv env = squeezingRight({{"SDFG_AUTOGRASP_TEST_LAYER_FAULT", point}});
    env.handTracking = "1";
    applyEnv(env);
    App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
    REQUIRE(app.ok());
    Ext ext(app);
    REQUIRE(ext.ok());
    makeTracker(app, ext, XR_HAND_RIGHT_EXT);
    CHECK(validationLog().empty());
  }
}
