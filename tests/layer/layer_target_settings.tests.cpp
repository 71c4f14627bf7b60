// XR_SDFG_auto_grasp version 2 per-target settings: which hands may grasp a target, changed at
// run time, and which of several targets in the grab box a grab takes.
#include <catch2/catch.hpp>

#include <algorithm>
#include <iterator>

#include "grasp_v2.h"

namespace {

using namespace sdfg::test;

const XrPosef kGrip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};

XrVector3f offset(const XrVector3f& p, float dx) {
  return {p.x + dx, p.y, p.z};
}

XrGraspTargetSDFG heldTarget(const GraspRun& run) {
  XrGraspStateSDFG s{XR_TYPE_GRASP_STATE_SDFG};
  if (run.state(s) != XR_SUCCESS || !s.isGrasping) return XR_NULL_HANDLE;
  return s.target;
}

// The squeeze the layer read this frame (the grab input is there).
float squeezeSeen(const GraspRun& run) {
  XrGraspStateSDFG s{XR_TYPE_GRASP_STATE_SDFG};
  return run.state(s) == XR_SUCCESS ? s.squeeze : -1.0f;
}

XrGraspTargetSDFG makeTargetFor(const GraspRun& run, const TestMesh& mesh, const XrPosef& pose,
                                XrGraspHandFlagsSDFG hands) {
  XrGraspTargetVerticesSDFG v{XR_TYPE_GRASP_TARGET_VERTICES_SDFG};
  v.vertexCount = uint32_t(mesh.vertices.size());
  v.vertices = mesh.vertices.data();
  v.indexCount = uint32_t(mesh.indices.size());
  v.indices = mesh.indices.data();
  XrGraspTargetSettingsSDFG settings{XR_TYPE_GRASP_TARGET_SETTINGS_SDFG, &v, hands};
  XrGraspTargetCreateInfoSDFG ci{XR_TYPE_GRASP_TARGET_CREATE_INFO_SDFG, &settings};
  ci.placement = {XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG, nullptr, run.app->local, pose};
  XrGraspTargetSDFG t = XR_NULL_HANDLE;
  REQUIRE(run.ext->create(run.app->session, &ci, &t) == XR_SUCCESS);
  return t;
}

}  // namespace

TEST_CASE("A target the hand may not grasp is not taken until the app allows it",
          "[layer][target_settings]") {
  const XrVector3f centre = boxCentreInLocal(kGrip, /*right=*/true);
  const TestMesh sphere = makeIcosphere(0.04f, 3);
  GraspRun run(sphere, {{0, 0, 0, 1}, offset(centre, 0.3f)}, kGrip);  // out of reach
  auto setSettings = run.app->fn<PFN_xrSetGraspTargetSettingsSDFG>("xrSetGraspTargetSettingsSDFG");
  REQUIRE(setSettings != nullptr);
  const XrGraspTargetSDFG leftOnly =
      makeTargetFor(run, sphere, {{0, 0, 0, 1}, centre}, XR_GRASP_HAND_LEFT_BIT_SDFG);
  // The right hand squeezes with the target in its box, and does not take it.
  REQUIRE(runUntil(*run.app, [&] { return squeezeSeen(run) >= 0.99f; }));
  run.app->frame();
  CHECK(!run.grasping());
  // Allowed from the next xrSyncActions.
  XrGraspTargetSettingsSDFG both{XR_TYPE_GRASP_TARGET_SETTINGS_SDFG, nullptr,
                                 XR_GRASP_HAND_LEFT_BIT_SDFG | XR_GRASP_HAND_RIGHT_BIT_SDFG};
  REQUIRE(setSettings(leftOnly, &both) == XR_SUCCESS);
  REQUIRE(runUntil(*run.app, [&] { return run.grasping(); }));
  CHECK(heldTarget(run) == leftOnly);
  // Not graspable at all for now: the holding hand lets go, with a RELEASED event.
  XrGraspTargetSettingsSDFG none{XR_TYPE_GRASP_TARGET_SETTINGS_SDFG, nullptr, 0};
  REQUIRE(setSettings(leftOnly, &none) == XR_SUCCESS);
  REQUIRE(runUntil(*run.app, [&] { return !run.grasping(); }));
  REQUIRE(runUntil(*run.app, [&] {
    for (const XrEventDataBuffer& e : run.app->events) {
      const auto& g = reinterpret_cast<const XrEventDataGraspChangedSDFG&>(e);
      if (e.type == XR_TYPE_EVENT_DATA_GRASP_CHANGED_SDFG && !g.isGrasping)
        return g.reason == XR_GRASP_CHANGE_REASON_RELEASED_SDFG && g.target == leftOnly;
    }
    return false;
  }));
  CHECK(validationLog().empty());
}

TEST_CASE("A target the hand may not grasp stops its fingers, and is taken once it may",
          "[layer][target_settings]") {
  // Version 3: two targets in the grab box; the nearer one, under the fingers, is the other
  // hand's. The right hand's fingers stop on it and never take it; allowed, it is taken.
  const XrVector3f centre = boxCentreInLocal(kGrip, /*right=*/true);
  const TestMesh small = makeIcosphere(0.02f, 3);
  GraspRun run(small, {{0, 0, 0, 1}, offset(centre, -0.04f)}, kGrip);
  const XrPosef under = belowOpenRightPalm(small, kGrip, {0, 0, 0, 1});
  const XrGraspTargetSDFG leftOnly = makeTargetFor(run, small, under, XR_GRASP_HAND_LEFT_BIT_SDFG);
  REQUIRE(untilSetUp(*run.app, *run.ext, [](const auto& setup) { return setup.readyCount >= 2; }));
  XrGraspTouchesSDFG touches{XR_TYPE_GRASP_TOUCHES_SDFG};
  XrGraspStateSDFG st{XR_TYPE_GRASP_STATE_SDFG, &touches};
  REQUIRE(runUntil(*run.app, [&] {
    return run.state(st) == XR_SUCCESS && touches.isClosed == XR_TRUE &&
           std::count(std::begin(touches.touched), std::end(touches.touched), leftOnly) > 0;
  }));
  CHECK(heldTarget(run) != leftOnly);
  auto setSettings = run.app->fn<PFN_xrSetGraspTargetSettingsSDFG>("xrSetGraspTargetSettingsSDFG");
  XrGraspTargetSettingsSDFG both{XR_TYPE_GRASP_TARGET_SETTINGS_SDFG, nullptr,
                                 XR_GRASP_HAND_LEFT_BIT_SDFG | XR_GRASP_HAND_RIGHT_BIT_SDFG};
  // Unless the hand already took the other one, it takes this one once allowed (the fingers on
  // it, the squeeze held).
  if (heldTarget(run) == XR_NULL_HANDLE) {
    REQUIRE(setSettings(leftOnly, &both) == XR_SUCCESS);
    REQUIRE(runUntil(*run.app, [&] { return heldTarget(run) == leftOnly; }));
  }
  CHECK(validationLog().empty());
}

TEST_CASE("Bad target settings are refused and change nothing", "[layer][target_settings]") {
  const XrVector3f centre = boxCentreInLocal(kGrip, /*right=*/true);
  const TestMesh sphere = makeIcosphere(0.04f, 3);
  GraspRun run(sphere, {{0, 0, 0, 1}, centre}, kGrip);
  auto setSettings = run.app->fn<PFN_xrSetGraspTargetSettingsSDFG>("xrSetGraspTargetSettingsSDFG");
  REQUIRE(setSettings != nullptr);
  XrGraspTargetSettingsSDFG none{XR_TYPE_GRASP_TARGET_SETTINGS_SDFG, nullptr, 0};
  SECTION("on set") {
    XrGraspTargetSettingsSDFG s = none;
    CHECK(setSettings(run.target, nullptr) == XR_ERROR_VALIDATION_FAILURE);
    s.type = XR_TYPE_GRASP_OPTIONS_SDFG;
    CHECK(setSettings(run.target, &s) == XR_ERROR_VALIDATION_FAILURE);
    s = none;
    s.graspableBy = 0x4;
    CHECK(setSettings(run.target, &s) == XR_ERROR_VALIDATION_FAILURE);
    CHECK(setSettings(XR_NULL_HANDLE, &none) == XR_ERROR_HANDLE_INVALID);
    CHECK(setSettings(reinterpret_cast<XrGraspTargetSDFG>(uintptr_t(55)), &none) ==
          XR_ERROR_HANDLE_INVALID);
  }
  SECTION("on create") {
    XrGraspTargetVerticesSDFG v{XR_TYPE_GRASP_TARGET_VERTICES_SDFG};
    v.vertexCount = uint32_t(sphere.vertices.size());
    v.vertices = sphere.vertices.data();
    v.indexCount = uint32_t(sphere.indices.size());
    v.indices = sphere.indices.data();
    XrGraspTargetSettingsSDFG bad{XR_TYPE_GRASP_TARGET_SETTINGS_SDFG, &v,
                                  XR_GRASP_HAND_RIGHT_BIT_SDFG | 0x100};
    XrGraspTargetCreateInfoSDFG ci{XR_TYPE_GRASP_TARGET_CREATE_INFO_SDFG, &bad};
    ci.placement = {XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG,
                    nullptr,
                    run.app->local,
                    {{0, 0, 0, 1}, offset(centre, 0.3f)}};
    XrGraspTargetSDFG t = reinterpret_cast<XrGraspTargetSDFG>(uintptr_t(55));
    CHECK(run.ext->create(run.app->session, &ci, &t) == XR_ERROR_VALIDATION_FAILURE);
    CHECK(t == reinterpret_cast<XrGraspTargetSDFG>(uintptr_t(55)));
  }
  // The target is still graspable by the right hand: the refused calls changed nothing.
  REQUIRE(runUntil(*run.app, [&] { return run.grasping(); }));
  CHECK(heldTarget(run) == run.target);
}
