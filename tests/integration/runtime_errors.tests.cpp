// Wrong use of the mock runtime gets the error code the OpenXR spec names, never a crash.
// These tests run without the core validation layer, which would otherwise answer first.
#include <catch2/catch.hpp>

#include <cstring>

#include "xr_test_support.h"

using sdfg::test::XrHarness;

namespace {

sdfg::test::InstanceOptions unvalidated() {
  sdfg::test::InstanceOptions o;
  o.coreValidation = false;
  o.extensions = {XR_MND_HEADLESS_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME};
  return o;
}

XrActionSet makeSet(const XrHarness& xr, const char* name) {
  XrActionSetCreateInfo info{XR_TYPE_ACTION_SET_CREATE_INFO};
  std::snprintf(info.actionSetName, sizeof info.actionSetName, "%s", name);
  std::snprintf(info.localizedActionSetName, sizeof info.localizedActionSetName, "%s", name);
  XrActionSet set = XR_NULL_HANDLE;
  REQUIRE(xrCreateActionSet(xr.instance(), &info, &set) == XR_SUCCESS);
  return set;
}

XrAction makeAction(XrActionSet set, const char* name, XrActionType type) {
  XrActionCreateInfo info{XR_TYPE_ACTION_CREATE_INFO};
  std::snprintf(info.actionName, sizeof info.actionName, "%s", name);
  std::snprintf(info.localizedActionName, sizeof info.localizedActionName, "%s", name);
  info.actionType = type;
  XrAction action = XR_NULL_HANDLE;
  REQUIRE(xrCreateAction(set, &info, &action) == XR_SUCCESS);
  return action;
}

}  // namespace

TEST_CASE("Null pointers, wrong structure types and bad handles are rejected",
          "[runtime][errors]") {
  XrHarness xr(unvalidated());
  REQUIRE(xr.createResult() == XR_SUCCESS);

  SECTION("Null output pointers") {
    XrSystemGetInfo info{XR_TYPE_SYSTEM_GET_INFO};
    info.formFactor = XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY;
    CHECK(xrGetSystem(xr.instance(), &info, nullptr) == XR_ERROR_VALIDATION_FAILURE);
    CHECK(xrGetSystem(xr.instance(), nullptr, nullptr) == XR_ERROR_VALIDATION_FAILURE);
    CHECK(xrStringToPath(xr.instance(), nullptr, nullptr) == XR_ERROR_VALIDATION_FAILURE);
    CHECK(xrPollEvent(xr.instance(), nullptr) == XR_ERROR_VALIDATION_FAILURE);
  }
  SECTION("A structure with the wrong type") {
    XrSystemGetInfo info{XR_TYPE_SYSTEM_PROPERTIES};  // wrong type on purpose
    info.formFactor = XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY;
    XrSystemId id = 55;
    CHECK(xrGetSystem(xr.instance(), &info, &id) == XR_ERROR_VALIDATION_FAILURE);
    CHECK(id == 55);
    XrSystemProperties props{XR_TYPE_INSTANCE_PROPERTIES};
    CHECK(xrGetSystemProperties(xr.instance(), xr.system(), &props) == XR_ERROR_VALIDATION_FAILURE);
  }
  SECTION("Unsupported form factor and bad system id") {
    XrSystemGetInfo info{XR_TYPE_SYSTEM_GET_INFO};
    info.formFactor = XR_FORM_FACTOR_HANDHELD_DISPLAY;
    XrSystemId id = 0;
    CHECK(xrGetSystem(xr.instance(), &info, &id) == XR_ERROR_FORM_FACTOR_UNSUPPORTED);
    XrSystemProperties props{XR_TYPE_SYSTEM_PROPERTIES};
    CHECK(xrGetSystemProperties(xr.instance(), xr.system() + 7, &props) == XR_ERROR_SYSTEM_INVALID);
  }
  SECTION("Handles that were never created, or were destroyed") {
    auto session = xr.createHeadlessSession();
    REQUIRE(session);
    CHECK(xrBeginSession(reinterpret_cast<XrSession>(uintptr_t(0xdead0)), nullptr) ==
          XR_ERROR_HANDLE_INVALID);
    XrSpace space = XR_NULL_HANDLE;
    XrReferenceSpaceCreateInfo info{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
    info.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_LOCAL;
    info.poseInReferenceSpace.orientation.w = 1;
    REQUIRE(xrCreateReferenceSpace(*session, &info, &space) == XR_SUCCESS);
    REQUIRE(xrDestroySpace(space) == XR_SUCCESS);
    CHECK(xrDestroySpace(space) == XR_ERROR_HANDLE_INVALID);
    XrSpaceLocation location{XR_TYPE_SPACE_LOCATION};
    CHECK(xrLocateSpace(space, space, 1, &location) == XR_ERROR_HANDLE_INVALID);
    // A session handle passed where a space is expected is not a space.
    CHECK(xrDestroySpace(reinterpret_cast<XrSpace>(*session)) == XR_ERROR_HANDLE_INVALID);
    REQUIRE(xrDestroySession(*session) == XR_SUCCESS);
    CHECK(xrDestroySession(*session) == XR_ERROR_HANDLE_INVALID);
  }
  SECTION("Malformed paths and non-unit poses") {
    XrPath p = 0;
    CHECK(xrStringToPath(xr.instance(), "no/leading/slash", &p) == XR_ERROR_PATH_FORMAT_INVALID);
    CHECK(xrStringToPath(xr.instance(), "/Upper/Case", &p) == XR_ERROR_PATH_FORMAT_INVALID);
    CHECK(xrStringToPath(xr.instance(), "/a//b", &p) == XR_ERROR_PATH_FORMAT_INVALID);
    char buffer[8];
    uint32_t n = 0;
    CHECK(xrPathToString(xr.instance(), 987654, sizeof buffer, &n, buffer) ==
          XR_ERROR_PATH_INVALID);
    CHECK(xrPathToString(xr.instance(), xr.path("/user/hand/left"), 4, &n, buffer) ==
          XR_ERROR_SIZE_INSUFFICIENT);
    auto session = xr.createHeadlessSession();
    REQUIRE(session);
    XrReferenceSpaceCreateInfo info{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
    info.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_LOCAL;
    info.poseInReferenceSpace.orientation = {0, 0, 0, 2};  // not unit length
    XrSpace space = XR_NULL_HANDLE;
    CHECK(xrCreateReferenceSpace(*session, &info, &space) == XR_ERROR_POSE_INVALID);
    info.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_UNBOUNDED_MSFT;
    info.poseInReferenceSpace.orientation = {0, 0, 0, 1};
    CHECK(xrCreateReferenceSpace(*session, &info, &space) == XR_ERROR_REFERENCE_SPACE_UNSUPPORTED);
  }
  SECTION("Unknown results still get a name") {
    char buffer[XR_MAX_RESULT_STRING_SIZE];
    REQUIRE(xrResultToString(xr.instance(), XrResult(-987654), buffer) == XR_SUCCESS);
    CHECK(std::string(buffer) == "XR_UNKNOWN_FAILURE_-987654");
  }
  SECTION("A second instance is refused") {
    XrHarness second(unvalidated());
    CHECK(second.createResult() == XR_ERROR_LIMIT_REACHED);
  }
}

TEST_CASE("Session and frame calls in the wrong state get the spec's errors", "[runtime][errors]") {
  XrHarness xr(unvalidated());
  REQUIRE(xr.createResult() == XR_SUCCESS);
  SECTION("A session needs a graphics binding unless XR_MND_headless is enabled") {
    xr.destroy();
    sdfg::test::InstanceOptions o = unvalidated();
    o.extensions = {};
    XrHarness plain(o);
    REQUIRE(plain.createResult() == XR_SUCCESS);
    XrSessionCreateInfo info{XR_TYPE_SESSION_CREATE_INFO};
    info.systemId = plain.system();
    XrSession s = XR_NULL_HANDLE;
    CHECK(xrCreateSession(plain.instance(), &info, &s) == XR_ERROR_GRAPHICS_DEVICE_INVALID);
    return;
  }
  auto session = xr.createHeadlessSession();
  REQUIRE(session);
  XrFrameState state{XR_TYPE_FRAME_STATE};
  XrFrameEndInfo end{XR_TYPE_FRAME_END_INFO};
  end.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
  end.displayTime = 1;

  SECTION("Before xrBeginSession") {
    CHECK(xrWaitFrame(*session, nullptr, &state) == XR_ERROR_SESSION_NOT_RUNNING);
    CHECK(xrEndSession(*session) == XR_ERROR_SESSION_NOT_RUNNING);
    CHECK(xrRequestExitSession(*session) == XR_ERROR_SESSION_NOT_RUNNING);
    XrSessionBeginInfo mono{XR_TYPE_SESSION_BEGIN_INFO};
    mono.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_MONO;
    CHECK(xrBeginSession(*session, &mono) == XR_ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED);
  }
  SECTION("While running") {
    REQUIRE(xr.begin(*session) == XR_SUCCESS);
    CHECK(xr.begin(*session) == XR_ERROR_SESSION_RUNNING);
    CHECK(xrEndSession(*session) == XR_ERROR_SESSION_NOT_STOPPING);
    CHECK(xrBeginFrame(*session, nullptr) == XR_ERROR_CALL_ORDER_INVALID);
    CHECK(xrEndFrame(*session, &end) == XR_ERROR_CALL_ORDER_INVALID);
    REQUIRE(xrWaitFrame(*session, nullptr, &state) == XR_SUCCESS);
    REQUIRE(xrBeginFrame(*session, nullptr) == XR_SUCCESS);
    end.displayTime = 0;
    CHECK(xrEndFrame(*session, &end) == XR_ERROR_TIME_INVALID);
    end.displayTime = state.predictedDisplayTime;
    end.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_ADDITIVE;
    CHECK(xrEndFrame(*session, &end) == XR_ERROR_ENVIRONMENT_BLEND_MODE_UNSUPPORTED);
    end.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
    const XrCompositionLayerBaseHeader* nullLayer = nullptr;
    end.layerCount = 1;
    end.layers = &nullLayer;
    CHECK(xrEndFrame(*session, &end) == XR_ERROR_LAYER_INVALID);
    end.layerCount = 0;
    CHECK(xrEndFrame(*session, &end) == XR_SUCCESS);
    // Two xrBeginFrame calls after one wait: the second has no wait of its own.
    REQUIRE(xrWaitFrame(*session, nullptr, &state) == XR_SUCCESS);
    REQUIRE(xrBeginFrame(*session, nullptr) == XR_SUCCESS);
    REQUIRE(xrWaitFrame(*session, nullptr, &state) == XR_SUCCESS);
    CHECK(xrBeginFrame(*session, nullptr) == XR_FRAME_DISCARDED);
  }
  SECTION("A headless session offers no swapchain formats and makes no swapchains") {
    uint32_t count = 55;
    REQUIRE(xrEnumerateSwapchainFormats(*session, 0, &count, nullptr) == XR_SUCCESS);
    CHECK(count == 0);
    XrSwapchainCreateInfo info{XR_TYPE_SWAPCHAIN_CREATE_INFO};
    info.format = 43;
    info.width = info.height = 64;
    info.sampleCount = info.faceCount = info.arraySize = info.mipCount = 1;
    info.usageFlags = XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT;
    XrSwapchain sc = XR_NULL_HANDLE;
    CHECK(xrCreateSwapchain(*session, &info, &sc) == XR_ERROR_SWAPCHAIN_FORMAT_UNSUPPORTED);
  }
  SECTION("A second session is refused while one exists") {
    CHECK(!xr.createHeadlessSession().has_value());
  }
}

TEST_CASE("Action misuse gets the spec's errors", "[runtime][errors]") {
  XrHarness xr(unvalidated());
  REQUIRE(xr.createResult() == XR_SUCCESS);
  const XrActionSet set = makeSet(xr, "set");
  const XrAction squeeze = makeAction(set, "squeeze", XR_ACTION_TYPE_FLOAT_INPUT);
  auto session = xr.createHeadlessSession();
  REQUIRE(session);

  SECTION("Names: empty, invalid characters, duplicates") {
    XrActionSetCreateInfo info{XR_TYPE_ACTION_SET_CREATE_INFO};
    std::snprintf(info.localizedActionSetName, sizeof info.localizedActionSetName, "Other");
    XrActionSet other = XR_NULL_HANDLE;
    CHECK(xrCreateActionSet(xr.instance(), &info, &other) == XR_ERROR_NAME_INVALID);
    std::snprintf(info.actionSetName, sizeof info.actionSetName, "Bad Name");
    CHECK(xrCreateActionSet(xr.instance(), &info, &other) == XR_ERROR_PATH_FORMAT_INVALID);
    std::snprintf(info.actionSetName, sizeof info.actionSetName, "set");
    CHECK(xrCreateActionSet(xr.instance(), &info, &other) == XR_ERROR_NAME_DUPLICATED);
  }
  SECTION("Bindings the profile does not have") {
    XrActionSuggestedBinding binding{squeeze, xr.path("/user/hand/left/input/no_such/value")};
    XrInteractionProfileSuggestedBinding suggested{XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING};
    suggested.interactionProfile = xr.path("/interaction_profiles/oculus/touch_controller");
    suggested.countSuggestedBindings = 1;
    suggested.suggestedBindings = &binding;
    CHECK(xrSuggestInteractionProfileBindings(xr.instance(), &suggested) ==
          XR_ERROR_PATH_UNSUPPORTED);
    binding.binding = xr.path("/user/hand/left/input/squeeze/value");
    suggested.interactionProfile = xr.path("/interaction_profiles/acme/unknown_controller");
    CHECK(xrSuggestInteractionProfileBindings(xr.instance(), &suggested) ==
          XR_ERROR_PATH_UNSUPPORTED);
  }
  SECTION("State of an action whose set is not attached, or of the wrong type") {
    XrActionStateGetInfo get{XR_TYPE_ACTION_STATE_GET_INFO};
    get.action = squeeze;
    XrActionStateFloat f{XR_TYPE_ACTION_STATE_FLOAT};
    CHECK(xrGetActionStateFloat(*session, &get, &f) == XR_ERROR_ACTIONSET_NOT_ATTACHED);
    XrSessionActionSetsAttachInfo attach{XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO};
    attach.countActionSets = 1;
    attach.actionSets = &set;
    REQUIRE(xrAttachSessionActionSets(*session, &attach) == XR_SUCCESS);
    CHECK(xrAttachSessionActionSets(*session, &attach) == XR_ERROR_ACTIONSETS_ALREADY_ATTACHED);
    XrActionStateBoolean b{XR_TYPE_ACTION_STATE_BOOLEAN};
    CHECK(xrGetActionStateBoolean(*session, &get, &b) == XR_ERROR_ACTION_TYPE_MISMATCH);
    get.subactionPath = xr.path("/user/hand/left");  // not declared at creation
    CHECK(xrGetActionStateFloat(*session, &get, &f) == XR_ERROR_PATH_UNSUPPORTED);
    XrActionCreateInfo late{XR_TYPE_ACTION_CREATE_INFO};
    std::snprintf(late.actionName, sizeof late.actionName, "late");
    std::snprintf(late.localizedActionName, sizeof late.localizedActionName, "Late");
    late.actionType = XR_ACTION_TYPE_BOOLEAN_INPUT;
    XrAction action = XR_NULL_HANDLE;
    CHECK(xrCreateAction(set, &late, &action) == XR_ERROR_ACTIONSETS_ALREADY_ATTACHED);
    // Syncing a set that was never attached.
    const XrActionSet other = makeSet(xr, "other");
    XrActiveActionSet active{other, XR_NULL_PATH};
    XrActionsSyncInfo sync{XR_TYPE_ACTIONS_SYNC_INFO};
    sync.countActiveActionSets = 1;
    sync.activeActionSets = &active;
    CHECK(xrSyncActions(*session, &sync) == XR_ERROR_ACTIONSET_NOT_ATTACHED);
    // An attached set synced while not focused: success code, all inactive.
    active.actionSet = set;
    CHECK(xrSyncActions(*session, &sync) == XR_SESSION_NOT_FOCUSED);
  }
  SECTION("An action space needs a pose action") {
    XrActionSpaceCreateInfo info{XR_TYPE_ACTION_SPACE_CREATE_INFO};
    info.action = squeeze;
    info.poseInActionSpace.orientation.w = 1;
    XrSpace space = XR_NULL_HANDLE;
    CHECK(xrCreateActionSpace(*session, &info, &space) == XR_ERROR_ACTION_TYPE_MISMATCH);
  }
}

TEST_CASE("Hand tracker misuse and bad scripts get the spec's errors", "[runtime][errors]") {
  XrHarness xr(unvalidated());
  REQUIRE(xr.createResult() == XR_SUCCESS);
  auto create = xr.proc<PFN_xrCreateHandTrackerEXT>("xrCreateHandTrackerEXT");
  auto locate = xr.proc<PFN_xrLocateHandJointsEXT>("xrLocateHandJointsEXT");
  REQUIRE(create != nullptr);
  REQUIRE(locate != nullptr);
  auto session = xr.createHeadlessSession();
  REQUIRE(session);

  SECTION("A tracker for no hand, and joint arrays of the wrong size") {
    XrHandTrackerCreateInfoEXT info{XR_TYPE_HAND_TRACKER_CREATE_INFO_EXT};
    info.hand = XrHandEXT(7);
    XrHandTrackerEXT tracker = XR_NULL_HANDLE;
    CHECK(create(*session, &info, &tracker) == XR_ERROR_VALIDATION_FAILURE);
    info.hand = XR_HAND_LEFT_EXT;
    REQUIRE(create(*session, &info, &tracker) == XR_SUCCESS);
    XrSpace local = XR_NULL_HANDLE;
    XrReferenceSpaceCreateInfo localInfo{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
    localInfo.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_LOCAL;
    localInfo.poseInReferenceSpace.orientation.w = 1;
    REQUIRE(xrCreateReferenceSpace(*session, &localInfo, &local) == XR_SUCCESS);
    XrHandJointLocationEXT joints[XR_HAND_JOINT_COUNT_EXT];
    XrHandJointLocationsEXT locations{XR_TYPE_HAND_JOINT_LOCATIONS_EXT};
    locations.jointCount = 20;
    locations.jointLocations = joints;
    XrHandJointsLocateInfoEXT where{XR_TYPE_HAND_JOINTS_LOCATE_INFO_EXT};
    where.baseSpace = local;
    where.time = 1;
    CHECK(locate(tracker, &where, &locations) == XR_ERROR_VALIDATION_FAILURE);
    locations.jointCount = XR_HAND_JOINT_COUNT_EXT;
    where.time = 0;
    CHECK(locate(tracker, &where, &locations) == XR_ERROR_TIME_INVALID);
  }
  SECTION("A script that does not parse is refused and the old one stays") {
    CHECK(xr.setScript("3 left squeeze 0.5 0.7\n") == XR_ERROR_VALIDATION_FAILURE);
    CHECK(xr.setScript("3 elbow squeeze 0.5\n") == XR_ERROR_VALIDATION_FAILURE);
    CHECK(xr.setScript("3 left grip 0 0 0 0 0 0 0\n") == XR_ERROR_VALIDATION_FAILURE);
    CHECK(xr.setScript("3 left squeeze nan\n") == XR_ERROR_VALIDATION_FAILURE);
    CHECK(xr.setScript("profile /interaction_profiles/acme/unknown\n") ==
          XR_ERROR_VALIDATION_FAILURE);
    CHECK(xr.setScript("# only a comment\n\n") == XR_SUCCESS);
  }
}
