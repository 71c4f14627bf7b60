// Destroys on other threads while the app's main thread syncs (issue 38): two threads create
// spaces and grasp targets placed in them and destroy both again, over and over, while the main
// thread runs frames whose grab update locates those spaces. Every call must answer as the
// runtime does, nothing may hang, and under ThreadSanitizer (the tsan preset) nothing may race.
// Failures on the worker threads are counted there and asserted on the main thread after the
// join: Catch2's assertions are not thread-safe.
#include <catch2/catch.hpp>

#include <atomic>
#include <chrono>
#include <string>
#include <thread>

#include "grasp_checks.h"
#include "test_scenes.h"
#include "xr_harness.h"

namespace {

using namespace sdfg::test;

const XrPosef kGrip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};

// One thread's churn: `rounds` times a space, a target placed in it under the hand, a few
// milliseconds for the main thread's grab update to locate it, then the space destroyed before
// the target (the order that leaves a placed target without its space) or after it.
struct Churn {
  std::atomic<int> done{0};
  std::atomic<int> failures{0};
  std::string firstFailure;  // written once, by the thread that counted the first failure
};

void churn(const App& app, const Ext& ext, const TestMesh& mesh, int rounds, bool spaceFirst,
           Churn& out) {
  const XrVector3f centre = boxCentreInLocal(kGrip, /*right=*/true);
  auto fail = [&](const char* what, XrResult r) {
    if (out.failures.fetch_add(1) == 0)
      out.firstFailure = std::string(what) + " " + std::to_string(r);
  };
  for (int i = 0; i < rounds; ++i) {
    XrReferenceSpaceCreateInfo rs{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
    rs.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_LOCAL;
    rs.poseInReferenceSpace.orientation.w = 1;
    XrSpace space = XR_NULL_HANDLE;
    if (XrResult r = xrCreateReferenceSpace(app.session, &rs, &space); r != XR_SUCCESS) {
      fail("xrCreateReferenceSpace", r);
      continue;
    }
    XrGraspTargetVerticesSDFG v{XR_TYPE_GRASP_TARGET_VERTICES_SDFG};
    v.vertexCount = uint32_t(mesh.vertices.size());
    v.vertices = mesh.vertices.data();
    v.indexCount = uint32_t(mesh.indices.size());
    v.indices = mesh.indices.data();
    XrGraspTargetCreateInfoSDFG ci{XR_TYPE_GRASP_TARGET_CREATE_INFO_SDFG, &v};
    ci.placement = {XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG, nullptr, space, {{0, 0, 0, 1}, centre}};
    XrGraspTargetSDFG target = XR_NULL_HANDLE;
    if (XrResult r = ext.create(app.session, &ci, &target); r != XR_SUCCESS) fail("create", r);
    std::this_thread::sleep_for(std::chrono::milliseconds(3));
    auto destroyTarget = [&] {
      if (target == XR_NULL_HANDLE) return;
      if (XrResult r = ext.destroy(target); r != XR_SUCCESS) fail("xrDestroyGraspTargetSDFG", r);
    };
    if (!spaceFirst) destroyTarget();
    if (XrResult r = xrDestroySpace(space); r != XR_SUCCESS) fail("xrDestroySpace", r);
    if (spaceFirst) destroyTarget();
    out.done.fetch_add(1);
  }
}

}  // namespace

TEST_CASE("Two threads destroy spaces and targets while a third syncs and grasps",
          "[layer][threads]") {
  XrEnv env;
  env.handTracking = "absent";
  env.script =
      gripLine(0, "right", kGrip) + squeezeLine(0, "right", 0.0f) + squeezeLine(3, "right", 1.0f);
  applyEnv(env);
  App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
  REQUIRE(app.ok());
  Ext ext(app);
  const XrHandTrackerEXT right = makeTracker(app, ext, XR_HAND_RIGHT_EXT);
  const TestMesh mesh = makeIcosphere(0.04f, 2);
  constexpr int kRounds = 60;
  Churn a, b;
  std::thread first(churn, std::cref(app), std::cref(ext), std::cref(mesh), kRounds, true,
                    std::ref(a));
  std::thread second(churn, std::cref(app), std::cref(ext), std::cref(mesh), kRounds, false,
                     std::ref(b));
  // The main thread: frames (sync, the grab update, a locate) until both threads are through, at
  // most 120 s; the threads are joined whatever happened.
  int locateFailures = 0;
  const bool through = app.framesUntil(
      [&] {
        if (app.lastTime > 0) {
          Joints j;
          if (locateJoints(app, right, j) != XR_SUCCESS) ++locateFailures;
        }
        return a.done.load() + a.failures.load() >= kRounds &&
               b.done.load() + b.failures.load() >= kRounds;
      },
      std::chrono::seconds(120));
  first.join();
  second.join();
  CHECK(through);
  CAPTURE(a.firstFailure, b.firstFailure);
  CHECK(a.failures.load() == 0);
  CHECK(b.failures.load() == 0);
  CHECK(a.done.load() == kRounds);
  CHECK(b.done.load() == kRounds);
  CHECK(locateFailures == 0);
  CHECK(app.lastSync == XR_SUCCESS);
  CHECK(validationLog().empty());
}
