// The layer's session worker end to end (CPU path, headless): target set-up off the app's thread,
// a held target that moves (the hand keeps its grasp on it in every frame), and destroying
// targets or the session while the worker is busy with them. Every wait is for an outcome, with
// a generous time bound.
#include <catch2/catch.hpp>

#include <chrono>
#include <cmath>
#include <thread>

#include "grasp_checks.h"
#include "test_scenes.h"
#include "xr_harness.h"

namespace {

using namespace sdfg::test;

XrEnv squeezingRight(const XrPosef& grip) {
  XrEnv env;
  env.handTracking = "absent";
  env.script = gripLine(0, "right", grip) + squeezeLine(0, "right", 0.0f) +
               squeezeLine(2, "right", 0.0f) + squeezeLine(3, "right", 1.0f);
  return env;
}

}  // namespace

TEST_CASE("A target is set up off the app's thread and graspable once the set-up says ready",
          "[layer][worker]") {
  const XrPosef grip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};
  applyEnv(squeezingRight(grip));
  App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
  REQUIRE(app.ok());
  Ext ext(app);
  XrGraspTargetsSetupInfoSDFG setup = setupInfo(app, ext);
  CHECK(setup.readyCount + setup.pendingCount + setup.failedCount == 0);
  const XrVector3f centre = boxCentreInLocal(grip, true);
  XrGraspTargetSDFG target = makeTarget(app, ext, makeIcosphere(0.04f, 4), {{0, 0, 0, 1}, centre});
  setup = setupInfo(app, ext);
  CHECK(setup.readyCount + setup.pendingCount == 1);  // ready, or still being set up
  CHECK(setup.failedCount == 0);
  CHECK(untilSetUp(app, ext, [](const auto& setup) { return setup.readyCount == 1; }));
  CHECK(setupInfo(app, ext).readyCount == 1);
  REQUIRE(framesUntilGrasping(app, ext, XR_HAND_RIGHT_EXT));
  REQUIRE(ext.destroy(target) == XR_SUCCESS);
  setup = setupInfo(app, ext);
  CHECK(setup.readyCount + setup.pendingCount + setup.failedCount == 0);
  CHECK(validationLog().empty());
}

TEST_CASE("A held target that moves keeps the grasp shown in every frame, on its surface",
          "[layer][worker]") {
  const XrPosef grip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};
  applyEnv(squeezingRight(grip));
  App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
  REQUIRE(app.ok());
  Ext ext(app);
  XrHandTrackerEXT tracker = makeTracker(app, ext, XR_HAND_RIGHT_EXT);
  const XrVector3f centre = boxCentreInLocal(grip, true);
  const float radius = 0.04f;
  XrGraspTargetSDFG target = makeTarget(app, ext, makeIcosphere(radius, 4), {{0, 0, 0, 1}, centre});
  REQUIRE(framesUntilGrasping(app, ext, XR_HAND_RIGHT_EXT));
  // The sphere drifts 1.2 cm along the palm (0.2 mm a frame) and back; the hand does not move.
  for (int frame = 0; frame < 120; ++frame) {
    CAPTURE(frame);
    const float shift = 0.0002f * float(frame < 60 ? frame : 120 - frame);
    const XrPosef pose{{0, 0, 0, 1}, {centre.x + shift, centre.y, centre.z}};
    XrGraspTargetPlacementSDFG placement{XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG, nullptr, app.local,
                                         pose};
    REQUIRE(ext.place(target, &placement) == XR_SUCCESS);
    app.frame();
    GraspOutcome out;
    REQUIRE(locateJoints(app, tracker, out.joints) == XR_SUCCESS);
    XrGraspStateGetInfoSDFG gi{XR_TYPE_GRASP_STATE_GET_INFO_SDFG, nullptr, XR_HAND_RIGHT_EXT};
    REQUIRE(ext.state(app.session, &gi, &out.state) == XR_SUCCESS);
    // No open-hand flicker while a re-solve runs, and no finger drawn inside the moved sphere
    // or off its surface: the last solve is shown re-posed onto the target.
    REQUIRE(out.state.isGrasping);
    const XrVector3f c = pose.position;
    checkContacts(out, [&](const XrVector3f& p) { return length(sub(p, c)) - radius; });
  }
  CHECK(validationLog().empty());
}

TEST_CASE("Destroying a target or the session while the worker sets it up is safe and prompt",
          "[layer][worker]") {
  const XrPosef grip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};
  // About 330k triangles: a set-up of a good fraction of a second, still running below.
  const TestMesh big = makeIcosphere(0.04f, 7);
  const double wholeMs = wholeSetUpMs(squeezingRight(grip), big);
  applyEnv(squeezingRight(grip));
  const XrVector3f centre = boxCentreInLocal(grip, true);
  App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
  REQUIRE(app.ok());
  Ext ext(app);
  app.frame();
  XrGraspTargetSDFG first = makeTarget(app, ext, big, {{0, 0, 0, 1}, centre});
  REQUIRE(ext.destroy(first) == XR_SUCCESS);
  CHECK(ext.destroy(first) == XR_ERROR_HANDLE_INVALID);
  makeTarget(app, ext, big, {{0, 0, 0, 1}, centre});
  app.frames(2);  // the squeeze is on: the frames ask for a grab of a target not ready yet
  REQUIRE(setupInfo(app, ext).pendingCount == 1);  // the second set-up has not finished
  const auto start = std::chrono::steady_clock::now();
  app.destroySession();
  // The worker is joined inside xrDestroySession, its set-up stopped: the call returns in tens of
  // milliseconds (docs/threading.md), not after the set-up, which took `wholeMs` run whole.
  const double destroyMs = msSince(start);
  CAPTURE(wholeMs);
  CHECK(destroyMs < destroyBoundMs(wholeMs));
  CHECK(validationLog().empty());
}

TEST_CASE("New vertices that collapse a triangle of a held target leave its grasp as it was",
          "[layer][worker]") {
  const XrPosef grip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};
  applyEnv(squeezingRight(grip));
  App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
  REQUIRE(app.ok());
  Ext ext(app);
  const XrVector3f centre = boxCentreInLocal(grip, true);
  const TestMesh sphere = makeIcosphere(0.04f, 3);
  XrGraspTargetSDFG target = makeTarget(app, ext, sphere, {{0, 0, 0, 1}, centre});
  REQUIRE(framesUntilGrasping(app, ext, XR_HAND_RIGHT_EXT));
  auto state = [&] {
    XrGraspBuildInfoSDFG build{XR_TYPE_GRASP_BUILD_INFO_SDFG};
    XrGraspStateSDFG st{XR_TYPE_GRASP_STATE_SDFG, &build};
    XrGraspStateGetInfoSDFG gi{XR_TYPE_GRASP_STATE_GET_INFO_SDFG, nullptr, XR_HAND_RIGHT_EXT};
    REQUIRE(ext.state(app.session, &gi, &st) == XR_SUCCESS);
    return std::make_pair(st, build);
  };
  const auto [before, buildsBefore] = state();
  // The sphere shrunk to 3/4, which the fingers would close further on, with its first
  // triangle's corners at one point: the call takes it, the worker refuses it.
  std::vector<XrVector3f> collapsed = sphere.vertices;
  for (XrVector3f& p : collapsed) p = {p.x * 0.75f, p.y * 0.75f, p.z * 0.75f};
  for (int k = 1; k < 3; ++k) collapsed[sphere.indices[size_t(k)]] = collapsed[sphere.indices[0]];
  XrGraspTargetVerticesSDFG v{XR_TYPE_GRASP_TARGET_VERTICES_SDFG,
                              nullptr,
                              uint32_t(collapsed.size()),
                              collapsed.data(),
                              0,
                              nullptr};
  REQUIRE(ext.update(target, &v) == XR_SUCCESS);
  // The outcome: the worker has re-solved the held hand (one more build), on the last shape.
  REQUIRE(app.framesUntil([&] { return state().second.cpuBuildCount > buildsBefore.cpuBuildCount; },
                          std::chrono::seconds(60)));
  app.frames(2);
  const auto [after, buildsAfter] = state();
  REQUIRE(after.isGrasping);
  for (int f = 0; f < XR_GRASP_FINGER_COUNT_SDFG; ++f) {
    CAPTURE(f);
    CHECK(after.fingers[f].curl == Approx(before.fingers[f].curl).margin(1e-5));
    CHECK(after.fingers[f].inContact == before.fingers[f].inContact);
  }
  CHECK(validationLog().empty());
}
