// XR_SDFG_auto_grasp version 2 events: xrPollEvent returns XrEventDataGraspChangedSDFG when a
// grasp starts or ends, interleaved with the runtime's events by time.
#include <catch2/catch.hpp>
#include <chrono>
#include <thread>
#include <vector>

#include "grasp_v2.h"

namespace {

using namespace sdfg::test;

std::vector<XrEventDataGraspChangedSDFG> graspEvents(const App& app) {
  std::vector<XrEventDataGraspChangedSDFG> out;
  for (const XrEventDataBuffer& e : app.events) {
    if (e.type == XR_TYPE_EVENT_DATA_GRASP_CHANGED_SDFG)
      out.push_back(reinterpret_cast<const XrEventDataGraspChangedSDFG&>(e));
  }
  return out;
}

XrTime nowXr() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return XrTime(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

// Index in app.events of the first session-state change to `state`, or -1.
int stateIndex(const App& app, XrSessionState state) {
  for (size_t i = 0; i < app.events.size(); ++i) {
    const XrEventDataBuffer& e = app.events[i];
    if (e.type == XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED &&
        reinterpret_cast<const XrEventDataSessionStateChanged&>(e).state == state)
      return int(i);
  }
  return -1;
}

int graspIndex(const App& app, XrBool32 grasping) {
  for (size_t i = 0; i < app.events.size(); ++i) {
    const XrEventDataBuffer& e = app.events[i];
    if (e.type == XR_TYPE_EVENT_DATA_GRASP_CHANGED_SDFG &&
        reinterpret_cast<const XrEventDataGraspChangedSDFG&>(e).isGrasping == grasping)
      return int(i);
  }
  return -1;
}

const XrPosef kGrip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};

}  // namespace

TEST_CASE("Grab, hold and release each give one grasp event, in time order", "[layer][events]") {
  const XrVector3f centre = boxCentreInLocal(kGrip, /*right=*/true);
  GraspRun run(makeIcosphere(0.04f, 4), {{0, 0, 0, 1}, centre}, kGrip);
  App& app = *run.app;
  XrTime grabbedAt = 0;
  REQUIRE(runUntil(app, [&] {
    grabbedAt = app.lastTime;
    return run.grasping();
  }));
  // Held for a few frames (no event besides the grab's), then released: scripted once the grasp
  // is shown, since how many frames the grab takes depends on the machine.
  app.frames(5);
  REQUIRE(app.setScript(gripLine(0, "right", kGrip) + squeezeLine(0, "right", 0.0f)) == XR_SUCCESS);
  REQUIRE(runUntil(app, [&] { return !run.grasping(); }));
  XrTime releasedAt = app.lastTime;
  REQUIRE(runUntil(app, [&] { return graspEvents(app).size() >= 2; }));
  const auto events = graspEvents(app);
  REQUIRE(events.size() == 2);
  CHECK(events[0].isGrasping == XR_TRUE);
  CHECK(events[0].reason == XR_GRASP_CHANGE_REASON_GRABBED_SDFG);
  CHECK(events[0].time == grabbedAt);
  CHECK(events[1].isGrasping == XR_FALSE);
  CHECK(events[1].reason == XR_GRASP_CHANGE_REASON_RELEASED_SDFG);
  CHECK(events[1].time == releasedAt);
  for (const auto& e : events) {
    CHECK(e.session == app.session);
    CHECK(e.hand == XR_HAND_RIGHT_EXT);
    CHECK(e.target == run.target);
    CHECK(e.next == nullptr);
  }
  // Interleaved with the runtime's session-state events by time.
  XrTime last = 0;
  for (const XrEventDataBuffer& e : app.events) {
    XrTime t = -1;
    if (e.type == XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED)
      t = reinterpret_cast<const XrEventDataSessionStateChanged&>(e).time;
    if (e.type == XR_TYPE_EVENT_DATA_GRASP_CHANGED_SDFG)
      t = reinterpret_cast<const XrEventDataGraspChangedSDFG&>(e).time;
    if (t < 0) continue;
    CHECK(t >= last);
    last = t;
  }
  CHECK(validationLog().empty());
}

TEST_CASE("A grasp event waits for earlier runtime events and goes before later ones",
          "[layer][events]") {
  const XrVector3f centre = boxCentreInLocal(kGrip, /*right=*/true);
  GraspRun run(makeIcosphere(0.04f, 4), {{0, 0, 0, 1}, centre}, kGrip);
  App& app = *run.app;
  XrTime grabbedAt = 0;
  REQUIRE(runUntil(app, [&] {
    grabbedAt = app.lastTime;
    return run.grasping();
  }));
  const bool later = GENERATE(false, true);
  CAPTURE(later);
  // The grab's event is queued (for the frame's predicted display time, ahead of the clock) and
  // not yet polled. The runtime's STOPPING change is stamped with the clock when exit is asked.
  if (later) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
    while (nowXr() <= grabbedAt + 1000000 && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    REQUIRE(nowXr() > grabbedAt);
  }
  REQUIRE(xrRequestExitSession(app.session) == XR_SUCCESS);
  const XrTime askedAt = nowXr();
  REQUIRE(runUntil(app, [&] { return graspIndex(app, XR_TRUE) >= 0; }));
  const int stopping = stateIndex(app, XR_SESSION_STATE_STOPPING);
  const int grabbed = graspIndex(app, XR_TRUE);
  REQUIRE(stopping >= 0);
  const XrTime stoppingTime =
      reinterpret_cast<const XrEventDataSessionStateChanged&>(app.events[stopping]).time;
  CAPTURE(stoppingTime, grabbedAt, askedAt);
  if (stoppingTime < grabbedAt)
    CHECK(stopping < grabbed);
  else
    CHECK(grabbed < stopping);
  if (later) CHECK(grabbed < stopping);
  CHECK(validationLog().empty());
}

TEST_CASE("Destroying a held target gives a released event naming it", "[layer][events]") {
  const XrVector3f centre = boxCentreInLocal(kGrip, /*right=*/true);
  GraspRun run(makeIcosphere(0.04f, 4), {{0, 0, 0, 1}, centre}, kGrip);
  App& app = *run.app;
  REQUIRE(runUntil(app, [&] { return run.grasping(); }));
  REQUIRE(run.ext->destroy(run.target) == XR_SUCCESS);
  REQUIRE(runUntil(app, [&] { return graspEvents(app).size() >= 2; }));
  const auto events = graspEvents(app);
  REQUIRE(events.size() == 2);
  CHECK(events[0].isGrasping == XR_TRUE);
  CHECK(events[1].isGrasping == XR_FALSE);
  CHECK(events[1].reason == XR_GRASP_CHANGE_REASON_TARGET_DESTROYED_SDFG);
  CHECK(events[1].target == run.target);
  CHECK(!run.grasping());
  CHECK(validationLog().empty());
}

TEST_CASE("xrPollEvent with a grasp event waiting rejects bad input and keeps the event",
          "[layer][events]") {
  const XrVector3f centre = boxCentreInLocal(kGrip, /*right=*/true);
  GraspRun run(makeIcosphere(0.04f, 4), {{0, 0, 0, 1}, centre}, kGrip);
  App& app = *run.app;
  REQUIRE(runUntil(app, [&] { return run.grasping(); }));
  // The grab's event is queued and not yet polled.
  SECTION("a null buffer") {
    CHECK(xrPollEvent(app.instance, nullptr) == XR_ERROR_VALIDATION_FAILURE);
  }
  SECTION("a buffer of the wrong type") {
    XrEventDataBuffer e{XR_TYPE_EVENT_DATA_GRASP_CHANGED_SDFG};
    CHECK(xrPollEvent(app.instance, &e) == XR_ERROR_VALIDATION_FAILURE);
    CHECK(e.type == XR_TYPE_EVENT_DATA_GRASP_CHANGED_SDFG);
  }
  REQUIRE(runUntil(app, [&] { return !graspEvents(app).empty(); }));
  const auto events = graspEvents(app);
  REQUIRE(events.size() == 1);
  CHECK(events[0].isGrasping == XR_TRUE);
  CHECK(validationLog().empty());
}
