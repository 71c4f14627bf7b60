// What real runtimes and the conformance suite showed (issue 19), on the mock runtime: calls the
// runtime must refuse stay refused through the layer; hands for every app that asks (a system
// without hands, an app without actions); headless sessions with a display time of 0; meshes
// wound clockwise. Every wait is for an outcome, bounded in time, never a fixed frame count.
#include <catch2/catch.hpp>
#include <chrono>
#include <cstring>
#include <functional>
#include <utility>

#include "grasp_checks.h"
#include "mock_checks.h"
#include "test_scenes.h"
#include "xr_harness.h"

namespace {

using namespace sdfg::test;

// Runs frames until `done` holds or `seconds` pass; returns whether it held.
bool framesUntil(App& app, const std::function<bool()>& done, double seconds = 30.0) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    app.frame();
    if (done()) return true;
  }
  return false;
}

TestMesh clockwise(TestMesh m) {
  for (size_t i = 0; i + 2 < m.indices.size(); i += 3)
    std::swap(m.indices[i + 1], m.indices[i + 2]);
  return m;
}

const XrPosef kGrip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};

}  // namespace

TEST_CASE("Calls the runtime refuses as the app made them stay refused with the layer active",
          "[layer][parity]") {
  // The CTS's test_actions.cpp checks: no action sets to attach, no bindings to suggest. The
  // layer would make both valid by adding its own.
  const bool layer = GENERATE(false, true);
  CAPTURE(layer);
  XrEnv env;
  env.layer = layer;
  applyEnv(env);
  AppOptions options;
  // Without the layer the loader would refuse its extension.
  options.extensions = {XR_EXT_HAND_TRACKING_EXTENSION_NAME};
  if (layer) options.extensions.push_back(XR_SDFG_AUTO_GRASP_EXTENSION_NAME);
  options.appActions = false;
  App app(options);
  REQUIRE(app.ok());
  XrPath profile = XR_NULL_PATH;
  REQUIRE(xrStringToPath(app.instance, "/interaction_profiles/oculus/touch_controller", &profile) ==
          XR_SUCCESS);
  XrInteractionProfileSuggestedBinding none{XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING};
  none.interactionProfile = profile;
  CHECK(xrSuggestInteractionProfileBindings(app.instance, &none) == XR_ERROR_VALIDATION_FAILURE);
  XrSessionActionSetsAttachInfo noSets{XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO};
  CHECK(xrAttachSessionActionSets(app.session, &noSets) == XR_ERROR_VALIDATION_FAILURE);
  // A set that is created but never attached cannot be synced, layer or not.
  XrActionSetCreateInfo asci{XR_TYPE_ACTION_SET_CREATE_INFO};
  std::strcpy(asci.actionSetName, "never_attached");
  std::strcpy(asci.localizedActionSetName, "Never attached");
  XrActionSet set = XR_NULL_HANDLE;
  REQUIRE(xrCreateActionSet(app.instance, &asci, &set) == XR_SUCCESS);
  XrActiveActionSet active{set, XR_NULL_PATH};
  XrActionsSyncInfo sync{XR_TYPE_ACTIONS_SYNC_INFO};
  sync.countActiveActionSets = 1;
  sync.activeActionSets = &active;
  CHECK(xrSyncActions(app.session, &sync) == XR_ERROR_ACTIONSET_NOT_ATTACHED);
}

TEST_CASE("A system that lists hand tracking but has no hands gets synthesized hands",
          "[layer][synthesis]") {
  // Monado with controllers only: XR_EXT_hand_tracking listed, supportsHandTracking false.
  const bool askProperties = GENERATE(true, false);
  CAPTURE(askProperties);
  XrEnv env;
  env.handTracking = "0";
  env.script = gripLine(0, "right", kGrip) + squeezeLine(0, "right", 1.0f);
  applyEnv(env);
  App app({{XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
  REQUIRE(app.ok());
  Ext ext(app);
  if (askProperties) {
    XrSystemHandTrackingPropertiesEXT ht{XR_TYPE_SYSTEM_HAND_TRACKING_PROPERTIES_EXT};
    XrSystemProperties props{XR_TYPE_SYSTEM_PROPERTIES, &ht};
    REQUIRE(xrGetSystemProperties(app.instance, app.system, &props) == XR_SUCCESS);
    CHECK(ht.supportsHandTracking == XR_TRUE);
  }
  XrHandTrackerEXT tracker = makeTracker(app, ext, XR_HAND_RIGHT_EXT);
  CHECK(framesUntil(app, [&] { return isActive(app, tracker); }));
  // A second tracker is synthesized too; the layer knew from the system's properties, so the
  // runtime was never asked for a tracker it must refuse.
  XrHandTrackerEXT left = makeTracker(app, ext, XR_HAND_LEFT_EXT);
  CHECK(left != XR_NULL_HANDLE);
  CHECK(mockStats(app).handTrackersRefused == 0u);
  CHECK(app.appSqueezeValue(1) == Approx(1.0f));
  CHECK(validationLog().empty());
}

TEST_CASE("A runtime's refusal of the layer's own hand trackers is not retried every frame",
          "[layer][grasp]") {
  XrEnv env;
  env.handTracking = "0";
  env.script = gripLine(0, "right", kGrip) + squeezeLine(0, "right", 1.0f);
  applyEnv(env);
  App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME}});
  REQUIRE(app.ok());
  REQUIRE(framesUntil(app, [&] { return mockStats(app).syncCount >= 30; }));
  // At most once per hand in 30 synced frames (it was twice per frame).
  CHECK(mockStats(app).handTrackersRefused <= 2u);
  CHECK(validationLog().empty());
}

TEST_CASE("An app that attaches no actions gets active synthesized hands with attach_alone",
          "[layer][synthesis]") {
  // The CTS's "Query joint locations": trackers and a frame loop, no action sets at all. By
  // default the layer waits for an attach that never comes (layer_input.tests.cpp); configured to,
  // it attaches its own set alone.
  const std::string handTracking = GENERATE(std::string("absent"), std::string("0"));
  CAPTURE(handTracking);
  XrEnv env;
  env.handTracking = handTracking;
  env.extra = {{"SDFG_AUTOGRASP_ATTACH_ALONE", "true"}};
  env.script = gripLine(0, "right", kGrip) + gripLine(0, "left", kGrip);
  applyEnv(env);
  AppOptions options;
  options.extensions = {XR_EXT_HAND_TRACKING_EXTENSION_NAME};
  options.appActions = false;
  App app(options);
  REQUIRE(app.ok());
  Ext ext(app);
  XrHandTrackerEXT right = makeTracker(app, ext, XR_HAND_RIGHT_EXT);
  XrHandTrackerEXT left = makeTracker(app, ext, XR_HAND_LEFT_EXT);
  CHECK(framesUntil(app, [&] { return isActive(app, right) && isActive(app, left); }));
  Joints j;
  REQUIRE(locateJoints(app, right, j) == XR_SUCCESS);
  // The palm sits near the grip (within a hand's width).
  CHECK(length(sub(j.joints[XR_HAND_JOINT_PALM_EXT].pose.position, kGrip.position)) < 0.06f);
  CHECK(validationLog().empty());
}

TEST_CASE("A headless session whose runtime predicts a display time of 0 still grasps",
          "[layer][grasp]") {
  // Monado's XR_MND_headless sessions: xrWaitFrame's predictedDisplayTime is 0.
  XrEnv env;
  env.handTracking = "absent";
  env.script =
      gripLine(0, "right", kGrip) + squeezeLine(0, "right", 0.0f) + squeezeLine(4, "right", 1.0f);
  env.extra = {{"SDFG_MOCK_FAULT", "zero_display_time"}};
  applyEnv(env);
  App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
  REQUIRE(app.ok());
  Ext ext(app);
  const XrVector3f centre = boxCentreInLocal(kGrip, /*right=*/true);
  makeTarget(app, ext, makeIcosphere(0.04f, 4), {{0, 0, 0, 1}, centre});
  XrGraspStateSDFG state{XR_TYPE_GRASP_STATE_SDFG};
  XrGraspStateGetInfoSDFG gi{XR_TYPE_GRASP_STATE_GET_INFO_SDFG, nullptr, XR_HAND_RIGHT_EXT};
  const bool held = framesUntil(
      app, [&] { return ext.state(app.session, &gi, &state) == XR_SUCCESS && state.isGrasping; });
  REQUIRE(app.framesEnded > 0);
  CHECK(app.lastTime == 0);  // the runtime really gave no time
  CHECK(held);
  int contacts = 0;
  for (const auto& f : state.fingers) contacts += f.inContact ? 1 : 0;
  CHECK(contacts >= 3);
}

TEST_CASE("A sphere wound clockwise is grasped like the same sphere wound outward",
          "[layer][grasp]") {
  const bool inverted = GENERATE(false, true);
  CAPTURE(inverted);
  XrEnv env;
  env.handTracking = "absent";
  env.script =
      gripLine(0, "right", kGrip) + squeezeLine(0, "right", 0.0f) + squeezeLine(4, "right", 1.0f);
  applyEnv(env);
  App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
  REQUIRE(app.ok());
  Ext ext(app);
  XrHandTrackerEXT tracker = makeTracker(app, ext, XR_HAND_RIGHT_EXT);
  const XrVector3f centre = boxCentreInLocal(kGrip, /*right=*/true);
  const float radius = 0.04f;
  const TestMesh sphere = makeIcosphere(radius, 4);
  makeTarget(app, ext, inverted ? clockwise(sphere) : sphere, {{0, 0, 0, 1}, centre});
  GraspOutcome out;
  XrGraspStateGetInfoSDFG gi{XR_TYPE_GRASP_STATE_GET_INFO_SDFG, nullptr, XR_HAND_RIGHT_EXT};
  // Held, and every finger settled: in contact or fully closed.
  const bool settled = framesUntil(app, [&] {
    if (ext.state(app.session, &gi, &out.state) != XR_SUCCESS || !out.state.isGrasping)
      return false;
    int contacts = 0;
    for (const auto& f : out.state.fingers) contacts += f.inContact ? 1 : 0;
    return contacts >= 3;
  });
  REQUIRE(settled);
  REQUIRE(locateJoints(app, tracker, out.joints) == XR_SUCCESS);
  checkContacts(out, [&](const XrVector3f& p) { return length(sub(p, centre)) - radius; });
  CHECK(validationLog().empty());
}
