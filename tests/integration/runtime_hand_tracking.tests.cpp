// XR_EXT_hand_tracking on the mock runtime: supported with default and scripted joints,
// switched off (offered but unsupported), and absent (a runtime with controllers only).
#include <catch2/catch.hpp>

#include <cstring>
#include <sstream>

#include "xr_test_support.h"

using sdfg::test::XrHarness;

namespace {

sdfg::test::InstanceOptions handOptions(const char* mode) {
  sdfg::test::InstanceOptions o;
  o.extensions = {XR_MND_HEADLESS_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME};
  if (mode != nullptr) o.env = {{SDFG_MOCK_ENV_HAND_TRACKING, mode}};
  return o;
}

XrBool32 supportsHandTracking(const XrHarness& xr) {
  XrSystemHandTrackingPropertiesEXT hand{XR_TYPE_SYSTEM_HAND_TRACKING_PROPERTIES_EXT};
  hand.supportsHandTracking = 55;  // sentinel: the runtime must write it
  XrSystemProperties props{XR_TYPE_SYSTEM_PROPERTIES};
  props.next = &hand;
  REQUIRE(xrGetSystemProperties(xr.instance(), xr.system(), &props) == XR_SUCCESS);
  return hand.supportsHandTracking;
}

struct Hands {
  PFN_xrCreateHandTrackerEXT create = nullptr;
  PFN_xrDestroyHandTrackerEXT destroy = nullptr;
  PFN_xrLocateHandJointsEXT locate = nullptr;
};

Hands handFunctions(const XrHarness& xr) {
  Hands h;
  h.create = xr.proc<PFN_xrCreateHandTrackerEXT>("xrCreateHandTrackerEXT");
  h.destroy = xr.proc<PFN_xrDestroyHandTrackerEXT>("xrDestroyHandTrackerEXT");
  h.locate = xr.proc<PFN_xrLocateHandJointsEXT>("xrLocateHandJointsEXT");
  return h;
}

XrResult createTracker(const Hands& h, XrSession session, XrHandEXT hand, XrHandTrackerEXT* out) {
  XrHandTrackerCreateInfoEXT info{XR_TYPE_HAND_TRACKER_CREATE_INFO_EXT};
  info.hand = hand;
  info.handJointSet = XR_HAND_JOINT_SET_DEFAULT_EXT;
  return h.create(session, &info, out);
}

// A script line giving every joint of one hand: joint j at (base + j * 0.01, 0, -0.3), identity
// orientation, radius 0.005 + j * 0.0001.
std::string jointsLine(uint64_t frame, const char* hand, float base) {
  std::ostringstream s;
  s << frame << " " << hand << " joints";
  for (int j = 0; j < XR_HAND_JOINT_COUNT_EXT; ++j)
    s << " \\\n  " << base + j * 0.01f << " 0 -0.3 0 0 0 1 " << 0.005f + j * 0.0001f;
  s << "\n";
  return s.str();
}

}  // namespace

TEST_CASE("Hand tracking reports default and scripted joints", "[runtime][hand_tracking]") {
  XrHarness xr(handOptions(nullptr));
  REQUIRE(xr.createResult() == XR_SUCCESS);
  CHECK(supportsHandTracking(xr) == XR_TRUE);
  const Hands h = handFunctions(xr);
  REQUIRE(h.create != nullptr);
  REQUIRE(xr.setScript(jointsLine(2, "right", 0.0f) + jointsLine(6, "right", 0.4f) +
                       "7 right hand_tracked 0\n") == XR_SUCCESS);
  auto session = xr.createHeadlessSession();
  REQUIRE(session);
  XrSpace local = XR_NULL_HANDLE;
  XrReferenceSpaceCreateInfo localInfo{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
  localInfo.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_LOCAL;
  localInfo.poseInReferenceSpace.orientation.w = 1;
  REQUIRE(xrCreateReferenceSpace(*session, &localInfo, &local) == XR_SUCCESS);
  XrHandTrackerEXT left = XR_NULL_HANDLE, right = XR_NULL_HANDLE;
  REQUIRE(createTracker(h, *session, XR_HAND_LEFT_EXT, &left) == XR_SUCCESS);
  REQUIRE(createTracker(h, *session, XR_HAND_RIGHT_EXT, &right) == XR_SUCCESS);

  XrHandJointLocationEXT joints[XR_HAND_JOINT_COUNT_EXT];
  XrHandJointLocationsEXT locations{XR_TYPE_HAND_JOINT_LOCATIONS_EXT};
  locations.jointCount = XR_HAND_JOINT_COUNT_EXT;
  locations.jointLocations = joints;
  XrHandJointsLocateInfoEXT locate{XR_TYPE_HAND_JOINTS_LOCATE_INFO_EXT};
  locate.baseSpace = local;
  locate.time = 1;

  SECTION("Before the session is focused no hand is active") {
    REQUIRE(h.locate(left, &locate, &locations) == XR_SUCCESS);
    CHECK(locations.isActive == XR_FALSE);
    CHECK(joints[XR_HAND_JOINT_PALM_EXT].locationFlags == 0);
  }
  xr.pollStates();
  REQUIRE(xr.begin(*session) == XR_SUCCESS);
  REQUIRE(xr.frame(*session) == XR_SUCCESS);

  SECTION("Without a script the hand is an open hand at the grip pose, every joint valid") {
    REQUIRE(h.locate(left, &locate, &locations) == XR_SUCCESS);
    CHECK(locations.isActive == XR_TRUE);
    for (const auto& j : joints) {
      CHECK((j.locationFlags & XR_SPACE_LOCATION_POSITION_VALID_BIT) != 0);
      CHECK(j.radius > 0.0f);
    }
    // Fingers point along -Z from the wrist.
    CHECK(joints[XR_HAND_JOINT_MIDDLE_TIP_EXT].pose.position.z <
          joints[XR_HAND_JOINT_WRIST_EXT].pose.position.z);
  }
  SECTION("Scripted joints come back exactly at a keyframe and interpolated between") {
    while (xr.stats(*session).framesEnded < 2) REQUIRE(xr.frame(*session) == XR_SUCCESS);
    REQUIRE(h.locate(right, &locate, &locations) == XR_SUCCESS);
    REQUIRE(locations.isActive == XR_TRUE);
    CHECK(joints[3].pose.position.x == Approx(0.03f).margin(1e-6));
    CHECK(joints[3].pose.position.z == Approx(-0.3f).margin(1e-6));
    CHECK(joints[3].radius == Approx(0.0053f).margin(1e-6));
    while (xr.stats(*session).framesEnded < 4) REQUIRE(xr.frame(*session) == XR_SUCCESS);
    REQUIRE(h.locate(right, &locate, &locations) == XR_SUCCESS);
    CHECK(joints[3].pose.position.x == Approx(0.23f).margin(1e-5));
  }
  SECTION("Velocities chained on the locations are written, flagged invalid") {
    XrHandJointVelocityEXT v[XR_HAND_JOINT_COUNT_EXT];
    v[0].velocityFlags = 55;
    XrHandJointVelocitiesEXT velocities{XR_TYPE_HAND_JOINT_VELOCITIES_EXT};
    velocities.jointCount = XR_HAND_JOINT_COUNT_EXT;
    velocities.jointVelocities = v;
    locations.next = &velocities;
    REQUIRE(h.locate(left, &locate, &locations) == XR_SUCCESS);
    CHECK(v[0].velocityFlags == 0);
  }
  SECTION("A scripted loss makes the hand inactive") {
    while (xr.stats(*session).framesEnded < 7) REQUIRE(xr.frame(*session) == XR_SUCCESS);
    REQUIRE(h.locate(right, &locate, &locations) == XR_SUCCESS);
    CHECK(locations.isActive == XR_FALSE);
    REQUIRE(h.locate(left, &locate, &locations) == XR_SUCCESS);
    CHECK(locations.isActive == XR_TRUE);
  }
  CHECK(h.destroy(left) == XR_SUCCESS);
  CHECK(xr.validationMessages().empty());
}

TEST_CASE("Hand tracking switched off: offered, but the system says no and trackers fail",
          "[runtime][hand_tracking]") {
  XrHarness xr(handOptions("0"));
  REQUIRE(xr.createResult() == XR_SUCCESS);
  CHECK(supportsHandTracking(xr) == XR_FALSE);
  const Hands h = handFunctions(xr);
  REQUIRE(h.create != nullptr);
  auto session = xr.createHeadlessSession();
  REQUIRE(session);
  XrHandTrackerEXT tracker = XR_NULL_HANDLE;
  CHECK(createTracker(h, *session, XR_HAND_LEFT_EXT, &tracker) == XR_ERROR_FEATURE_UNSUPPORTED);
  CHECK(xr.validationMessages().empty());
}

TEST_CASE("Hand tracking absent: the extension is not offered and cannot be enabled",
          "[runtime][hand_tracking]") {
  XrHarness xr(handOptions("absent"));
  CHECK(xr.createResult() == XR_ERROR_EXTENSION_NOT_PRESENT);
  sdfg::test::InstanceOptions plain;
  plain.env = {{SDFG_MOCK_ENV_HAND_TRACKING, "absent"}};
  plain.coreValidation = false;  // it would hand out its own entry point for any known name
  XrHarness without(plain);
  REQUIRE(without.createResult() == XR_SUCCESS);
  PFN_xrVoidFunction f = nullptr;
  CHECK(xrGetInstanceProcAddr(without.instance(), "xrCreateHandTrackerEXT", &f) ==
        XR_ERROR_FUNCTION_UNSUPPORTED);
  CHECK(f == nullptr);
}
