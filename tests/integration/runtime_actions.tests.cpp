// Actions on the mock runtime with each simulated controller profile: the scripted squeeze /
// select values and grip poses reach the app through xrSyncActions, xrGetActionState* and
// xrLocateSpace at the frame the script names; tracking loss and haptics are visible too.
#include <catch2/catch.hpp>

#include <string>

#include "xr_test_support.h"

using sdfg::test::XrHarness;

namespace {

// An app-side action set: a float (squeeze or select), a boolean, a pose and a haptic output on
// both hands, bound for one profile, attached to a running, focused headless session.
struct ActionApp {
  XrActionSet set = XR_NULL_HANDLE;
  XrAction grab = XR_NULL_HANDLE, press = XR_NULL_HANDLE, pose = XR_NULL_HANDLE,
           buzz = XR_NULL_HANDLE, stick = XR_NULL_HANDLE;
  XrPath hands[2] = {XR_NULL_PATH, XR_NULL_PATH};
  XrSpace handSpace[2] = {XR_NULL_HANDLE, XR_NULL_HANDLE};
  XrSpace local = XR_NULL_HANDLE;
  XrSession session = XR_NULL_HANDLE;
};

XrAction makeAction(XrActionSet set, const char* name, XrActionType type, const XrPath* hands) {
  XrActionCreateInfo info{XR_TYPE_ACTION_CREATE_INFO};
  std::snprintf(info.actionName, sizeof info.actionName, "%s", name);
  std::snprintf(info.localizedActionName, sizeof info.localizedActionName, "%s", name);
  info.actionType = type;
  info.countSubactionPaths = 2;
  info.subactionPaths = hands;
  XrAction action = XR_NULL_HANDLE;
  return xrCreateAction(set, &info, &action) == XR_SUCCESS ? action : XR_NULL_HANDLE;
}

struct ProfileCase {
  const char* profile;
  const char* floatInput;  // bound to the float action
  const char* boolInput;   // bound to the boolean action
  const char* stickInput;  // bound to the vector2f action, or null
};

ActionApp setUp(const XrHarness& xr, const ProfileCase& pc) {
  ActionApp app;
  app.hands[0] = xr.path("/user/hand/left");
  app.hands[1] = xr.path("/user/hand/right");
  XrActionSetCreateInfo setInfo{XR_TYPE_ACTION_SET_CREATE_INFO};
  std::snprintf(setInfo.actionSetName, sizeof setInfo.actionSetName, "gameplay");
  std::snprintf(setInfo.localizedActionSetName, sizeof setInfo.localizedActionSetName, "Gameplay");
  REQUIRE(xrCreateActionSet(xr.instance(), &setInfo, &app.set) == XR_SUCCESS);
  app.grab = makeAction(app.set, "grab", XR_ACTION_TYPE_FLOAT_INPUT, app.hands);
  app.press = makeAction(app.set, "press", XR_ACTION_TYPE_BOOLEAN_INPUT, app.hands);
  app.pose = makeAction(app.set, "hand_pose", XR_ACTION_TYPE_POSE_INPUT, app.hands);
  app.buzz = makeAction(app.set, "buzz", XR_ACTION_TYPE_VIBRATION_OUTPUT, app.hands);
  app.stick = makeAction(app.set, "move", XR_ACTION_TYPE_VECTOR2F_INPUT, app.hands);
  REQUIRE(app.grab != XR_NULL_HANDLE);
  REQUIRE(app.stick != XR_NULL_HANDLE);

  std::vector<XrActionSuggestedBinding> bindings;
  for (const char* hand : {"/user/hand/left", "/user/hand/right"}) {
    const std::string h = hand;
    bindings.push_back({app.grab, xr.path((h + pc.floatInput).c_str())});
    bindings.push_back({app.press, xr.path((h + pc.boolInput).c_str())});
    bindings.push_back({app.pose, xr.path((h + "/input/grip/pose").c_str())});
    bindings.push_back({app.buzz, xr.path((h + "/output/haptic").c_str())});
    if (pc.stickInput != nullptr)
      bindings.push_back({app.stick, xr.path((h + pc.stickInput).c_str())});
  }
  XrInteractionProfileSuggestedBinding suggested{XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING};
  suggested.interactionProfile = xr.path(pc.profile);
  suggested.countSuggestedBindings = uint32_t(bindings.size());
  suggested.suggestedBindings = bindings.data();
  REQUIRE(xrSuggestInteractionProfileBindings(xr.instance(), &suggested) == XR_SUCCESS);

  auto session = xr.createHeadlessSession();
  REQUIRE(session);
  app.session = *session;
  for (int h = 0; h < 2; ++h) {
    XrActionSpaceCreateInfo info{XR_TYPE_ACTION_SPACE_CREATE_INFO};
    info.action = app.pose;
    info.subactionPath = app.hands[h];
    info.poseInActionSpace.orientation.w = 1;
    REQUIRE(xrCreateActionSpace(app.session, &info, &app.handSpace[h]) == XR_SUCCESS);
  }
  XrReferenceSpaceCreateInfo local{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
  local.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_LOCAL;
  local.poseInReferenceSpace.orientation.w = 1;
  REQUIRE(xrCreateReferenceSpace(app.session, &local, &app.local) == XR_SUCCESS);
  XrSessionActionSetsAttachInfo attach{XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO};
  attach.countActionSets = 1;
  attach.actionSets = &app.set;
  REQUIRE(xrAttachSessionActionSets(app.session, &attach) == XR_SUCCESS);
  xr.pollStates();
  REQUIRE(xr.begin(app.session) == XR_SUCCESS);
  REQUIRE(xr.frame(app.session) == XR_SUCCESS);  // frame 0 -> 1; the session is now FOCUSED
  return app;
}

void runTo(const XrHarness& xr, const ActionApp& app, uint64_t frame) {
  while (xr.stats(app.session).framesEnded < frame) REQUIRE(xr.frame(app.session) == XR_SUCCESS);
}

XrResult sync(const ActionApp& app) {
  XrActiveActionSet active{app.set, XR_NULL_PATH};
  XrActionsSyncInfo info{XR_TYPE_ACTIONS_SYNC_INFO};
  info.countActiveActionSets = 1;
  info.activeActionSets = &active;
  return xrSyncActions(app.session, &info);
}

XrActionStateFloat floatState(const ActionApp& app, XrPath hand) {
  XrActionStateGetInfo get{XR_TYPE_ACTION_STATE_GET_INFO};
  get.action = app.grab;
  get.subactionPath = hand;
  XrActionStateFloat state{XR_TYPE_ACTION_STATE_FLOAT};
  REQUIRE(xrGetActionStateFloat(app.session, &get, &state) == XR_SUCCESS);
  return state;
}

XrSpaceLocation locate(const ActionApp& app, int hand) {
  XrSpaceLocation location{XR_TYPE_SPACE_LOCATION};
  REQUIRE(xrLocateSpace(app.handSpace[hand], app.local, 1, &location) == XR_SUCCESS);
  return location;
}

}  // namespace

TEST_CASE("Scripted controller input reaches the app with each interaction profile",
          "[runtime][actions]") {
  const ProfileCase pc =
      GENERATE(ProfileCase{"/interaction_profiles/khr/simple_controller", "/input/select/click",
                           "/input/menu/click", nullptr},
               ProfileCase{"/interaction_profiles/oculus/touch_controller", "/input/squeeze/value",
                           "/input/trigger/value", "/input/thumbstick"},
               ProfileCase{"/interaction_profiles/valve/index_controller", "/input/squeeze/value",
                           "/input/a/click", "/input/thumbstick"});
  CAPTURE(pc.profile);
  const std::string floatChannel = std::string(pc.floatInput).substr(7);  // "squeeze/value"
  const std::string boolChannel = std::string(pc.boolInput).substr(7);
  sdfg::test::InstanceOptions options;
  options.env = {{SDFG_MOCK_ENV_PROFILE, pc.profile}};
  XrHarness xr(options);
  REQUIRE(xr.createResult() == XR_SUCCESS);
  // Left squeeze ramps 0 -> 1 over frames 2..6; the right one is pressed from frame 4 on; the
  // left grip moves 0.4 m along x between frames 2 and 6; the left hand is lost at frame 8.
  REQUIRE(xr.setScript("2 left " + floatChannel + " 0\n" + "6 left " + floatChannel + " 1\n" +
                       "0 right " + floatChannel + " 0\n" + "4 right " + floatChannel + " 1\n" +
                       "4 right " + boolChannel + " 0\n" + "5 right " + boolChannel + " 1\n" +
                       "2 left grip -0.2 -0.3 -0.4 0 0 0 1\n" +
                       "6 left grip 0.2 -0.3 -0.4 0 0 0 1\n" + "5 left thumbstick 0.6 -0.8\n" +
                       "8 left tracked 0\n") == XR_SUCCESS);
  const ActionApp app = setUp(xr, pc);

  SECTION("The profile in use is the simulated one, for both hands") {
    XrInteractionProfileState state{XR_TYPE_INTERACTION_PROFILE_STATE};
    REQUIRE(xrGetCurrentInteractionProfile(app.session, app.hands[0], &state) == XR_SUCCESS);
    CHECK(state.interactionProfile == xr.path(pc.profile));
    CHECK(xr.stats(app.session).currentProfile == xr.path(pc.profile));
  }
  SECTION("A float input follows the script, interpolated between keyframes") {
    runTo(xr, app, 4);
    REQUIRE(sync(app) == XR_SUCCESS);
    const XrActionStateFloat left = floatState(app, app.hands[0]);
    CHECK(left.isActive == XR_TRUE);
    // Click inputs (simple controller) read a ramp as pressed above 0.5; values interpolate.
    const bool click = floatChannel.find("/click") != std::string::npos;
    CHECK(left.currentState == Approx(click ? 0.0f : 0.5f).margin(1e-5));
    CHECK(floatState(app, app.hands[1]).currentState == Approx(1.0f).margin(1e-6));
    // XR_NULL_PATH reads both hands: the larger value wins.
    CHECK(floatState(app, XR_NULL_PATH).currentState == Approx(1.0f).margin(1e-6));
    runTo(xr, app, 6);
    REQUIRE(sync(app) == XR_SUCCESS);
    const XrActionStateFloat later = floatState(app, app.hands[0]);
    CHECK(later.currentState == Approx(1.0f).margin(1e-6));
    CHECK(later.changedSinceLastSync == XR_TRUE);
  }
  SECTION("A boolean input turns on at its keyframe") {
    XrActionStateGetInfo get{XR_TYPE_ACTION_STATE_GET_INFO};
    get.action = app.press;
    get.subactionPath = app.hands[1];
    XrActionStateBoolean state{XR_TYPE_ACTION_STATE_BOOLEAN};
    runTo(xr, app, 4);
    REQUIRE(sync(app) == XR_SUCCESS);
    REQUIRE(xrGetActionStateBoolean(app.session, &get, &state) == XR_SUCCESS);
    CHECK(state.isActive == XR_TRUE);
    CHECK(state.currentState == XR_FALSE);
    runTo(xr, app, 5);
    REQUIRE(sync(app) == XR_SUCCESS);
    REQUIRE(xrGetActionStateBoolean(app.session, &get, &state) == XR_SUCCESS);
    CHECK(state.currentState == XR_TRUE);
    CHECK(state.changedSinceLastSync == XR_TRUE);
  }
  SECTION("A vector2f input reads the thumbstick where the profile has one") {
    runTo(xr, app, 5);
    REQUIRE(sync(app) == XR_SUCCESS);
    XrActionStateGetInfo get{XR_TYPE_ACTION_STATE_GET_INFO};
    get.action = app.stick;
    get.subactionPath = app.hands[0];
    XrActionStateVector2f state{XR_TYPE_ACTION_STATE_VECTOR2F};
    REQUIRE(xrGetActionStateVector2f(app.session, &get, &state) == XR_SUCCESS);
    CHECK(state.isActive == (pc.stickInput != nullptr ? XR_TRUE : XR_FALSE));
    if (pc.stickInput != nullptr) {
      CHECK(state.currentState.x == Approx(0.6f).margin(1e-6));
      CHECK(state.currentState.y == Approx(-0.8f).margin(1e-6));
    }
  }
  SECTION("The grip pose is the scripted one at the scripted frame, until tracking is lost") {
    runTo(xr, app, 2);
    REQUIRE(sync(app) == XR_SUCCESS);
    XrSpaceLocation at2 = locate(app, 0);
    REQUIRE((at2.locationFlags & XR_SPACE_LOCATION_POSITION_VALID_BIT) != 0);
    CHECK(at2.pose.position.x == Approx(-0.2f).margin(1e-5));
    CHECK(at2.pose.position.z == Approx(-0.4f).margin(1e-5));
    runTo(xr, app, 5);
    const XrSpaceLocation at5 = locate(app, 0);
    CHECK(at5.pose.position.x == Approx(0.1f).margin(1e-5));
    XrActionStateGetInfo get{XR_TYPE_ACTION_STATE_GET_INFO};
    get.action = app.pose;
    get.subactionPath = app.hands[0];
    XrActionStatePose pose{XR_TYPE_ACTION_STATE_POSE};
    REQUIRE(xrGetActionStatePose(app.session, &get, &pose) == XR_SUCCESS);
    CHECK(pose.isActive == XR_TRUE);
    runTo(xr, app, 8);
    CHECK(locate(app, 0).locationFlags == 0);
    CHECK((locate(app, 1).locationFlags & XR_SPACE_LOCATION_ORIENTATION_TRACKED_BIT) != 0);
  }
  SECTION("Haptic pulses are counted per hand") {
    XrHapticActionInfo info{XR_TYPE_HAPTIC_ACTION_INFO};
    info.action = app.buzz;
    info.subactionPath = app.hands[1];
    XrHapticVibration vibration{XR_TYPE_HAPTIC_VIBRATION};
    vibration.amplitude = 0.75f;
    vibration.duration = XR_MIN_HAPTIC_DURATION;
    REQUIRE(sync(app) == XR_SUCCESS);
    REQUIRE(xrApplyHapticFeedback(app.session, &info,
                                  reinterpret_cast<const XrHapticBaseHeader*>(&vibration)) ==
            XR_SUCCESS);
    const XrMockRuntimeStatsSDFG stats = xr.stats(app.session);
    CHECK(stats.hapticCount[0] == 0);
    CHECK(stats.hapticCount[1] == 1);
    CHECK(stats.lastHapticAmplitude[1] == Approx(0.75f));
  }
  SECTION("Bound sources name the profile's paths") {
    XrBoundSourcesForActionEnumerateInfo info{XR_TYPE_BOUND_SOURCES_FOR_ACTION_ENUMERATE_INFO};
    info.action = app.grab;
    uint32_t count = 0;
    REQUIRE(xrEnumerateBoundSourcesForAction(app.session, &info, 0, &count, nullptr) == XR_SUCCESS);
    CHECK(count == 2);
  }
  CHECK(xr.validationMessages().empty());
}

TEST_CASE("Actions are inactive when the app did not suggest bindings for the simulated profile",
          "[runtime][actions]") {
  sdfg::test::InstanceOptions options;
  options.env = {{SDFG_MOCK_ENV_PROFILE, "/interaction_profiles/valve/index_controller"}};
  XrHarness xr(options);
  REQUIRE(xr.createResult() == XR_SUCCESS);
  // The app binds only oculus/touch_controller; a real Index runtime without a binding for it
  // and without simple_controller suggestions leaves the actions unbound.
  const ActionApp app = setUp(xr, {"/interaction_profiles/oculus/touch_controller",
                                   "/input/squeeze/value", "/input/trigger/value", nullptr});
  REQUIRE(sync(app) == XR_SUCCESS);
  CHECK(floatState(app, app.hands[0]).isActive == XR_FALSE);
  CHECK(xr.stats(app.session).currentProfile == XR_NULL_PATH);
  CHECK(xr.validationMessages().empty());
}

TEST_CASE("Every core OpenXR 1.0 profile takes its own bindings and refuses others'",
          "[runtime][actions]") {
  XrHarness xr;
  REQUIRE(xr.createResult() == XR_SUCCESS);
  XrActionSetCreateInfo setInfo{XR_TYPE_ACTION_SET_CREATE_INFO};
  std::snprintf(setInfo.actionSetName, sizeof setInfo.actionSetName, "profiles");
  std::snprintf(setInfo.localizedActionSetName, sizeof setInfo.localizedActionSetName, "Profiles");
  XrActionSet set = XR_NULL_HANDLE;
  REQUIRE(xrCreateActionSet(xr.instance(), &setInfo, &set) == XR_SUCCESS);
  XrActionCreateInfo info{XR_TYPE_ACTION_CREATE_INFO};
  std::snprintf(info.actionName, sizeof info.actionName, "press");
  std::snprintf(info.localizedActionName, sizeof info.localizedActionName, "Press");
  info.actionType = XR_ACTION_TYPE_BOOLEAN_INPUT;
  XrAction press = XR_NULL_HANDLE;
  REQUIRE(xrCreateAction(set, &info, &press) == XR_SUCCESS);
  auto suggest = [&](const char* profile, const char* binding) {
    const XrActionSuggestedBinding b{press, xr.path(binding)};
    XrInteractionProfileSuggestedBinding s{XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING};
    s.interactionProfile = xr.path(profile);
    s.countSuggestedBindings = 1;
    s.suggestedBindings = &b;
    return xrSuggestInteractionProfileBindings(xr.instance(), &s);
  };
  // The four the mock cannot simulate as controllers, with their own top-level paths.
  CHECK(suggest("/interaction_profiles/htc/vive_pro", "/user/head/input/system/click") ==
        XR_SUCCESS);
  CHECK(suggest("/interaction_profiles/microsoft/xbox_controller", "/user/gamepad/input/a/click") ==
        XR_SUCCESS);
  CHECK(suggest("/interaction_profiles/google/daydream_controller",
                "/user/hand/right/input/trackpad/click") == XR_SUCCESS);
  CHECK(suggest("/interaction_profiles/oculus/go_controller", "/user/hand/left/input/back/click") ==
        XR_SUCCESS);
  // Paths of another profile, or of no profile.
  CHECK(suggest("/interaction_profiles/microsoft/xbox_controller",
                "/user/hand/left/input/a/click") == XR_ERROR_PATH_UNSUPPORTED);
  CHECK(suggest("/interaction_profiles/htc/vive_pro", "/user/gamepad/input/a/click") ==
        XR_ERROR_PATH_UNSUPPORTED);
  CHECK(suggest("/interaction_profiles/oculus/go_controller",
                "/user/hand/left/input/squeeze/click") == XR_ERROR_PATH_UNSUPPORTED);
  CHECK(xr.validationMessages().empty());
}

TEST_CASE("A profile without hands cannot be the simulated controllers'", "[runtime][actions]") {
  for (const char* profile :
       {"/interaction_profiles/htc/vive_pro", "/interaction_profiles/microsoft/xbox_controller",
        "/interaction_profiles/nowhere/none"}) {
    CAPTURE(profile);
    sdfg::test::InstanceOptions options;
    options.env = {{SDFG_MOCK_ENV_PROFILE, profile}};
    XrHarness xr(options);
    // The mock refuses with XR_ERROR_VALIDATION_FAILURE; the loader reports the failed chain.
    CHECK(XR_FAILED(xr.createResult()));
  }
}
