// XR_EXT_hand_tracking_data_source through the layer: joints it synthesizes from a controller
// say so (CONTROLLER), a hand-tracking runtime's own joints are UNOBSTRUCTED, the requested
// sources are honoured, and bad requests are refused without creating anything.
#include <catch2/catch.hpp>
#include <cstring>
#include <string>
#include <vector>

#include "grasp_v2.h"
// After grasp_v2.h, which brings <openxr/openxr.h>.
#include <openxr/sdfg_hand_tracking_data_source.h>

namespace {

using namespace sdfg::test;

const XrPosef kGrip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};

// The app's view of the layer's extensions (the loader answers from the manifests).
bool offered(const char* name) {
  uint32_t n = 0;
  if (xrEnumerateInstanceExtensionProperties(nullptr, 0, &n, nullptr) != XR_SUCCESS) return false;
  std::vector<XrExtensionProperties> props(n, {XR_TYPE_EXTENSION_PROPERTIES});
  if (xrEnumerateInstanceExtensionProperties(nullptr, n, &n, props.data()) != XR_SUCCESS)
    return false;
  for (const auto& p : props)
    if (std::strcmp(p.extensionName, name) == 0) return true;
  return false;
}

XrResult createTracker(const App& app, const XrHandTrackingDataSourceInfoEXT* sources,
                       XrHandTrackerEXT& out) {
  auto create = app.fn<PFN_xrCreateHandTrackerEXT>("xrCreateHandTrackerEXT");
  XrHandTrackerCreateInfoEXT ci{XR_TYPE_HAND_TRACKER_CREATE_INFO_EXT, sources};
  ci.hand = XR_HAND_RIGHT_EXT;
  ci.handJointSet = XR_HAND_JOINT_SET_DEFAULT_EXT;
  return create(app.session, &ci, &out);
}

struct Located {
  Joints joints;
  XrHandTrackingDataSourceStateEXT state{XR_TYPE_HAND_TRACKING_DATA_SOURCE_STATE_EXT};
};

// locateJoints() with the data-source state chained on the locations, sentinel-filled.
XrResult locate(const App& app, XrHandTrackerEXT tracker, Located& out) {
  auto locate = app.fn<PFN_xrLocateHandJointsEXT>("xrLocateHandJointsEXT");
  XrHandJointsLocateInfoEXT info{XR_TYPE_HAND_JOINTS_LOCATE_INFO_EXT};
  info.baseSpace = app.local;
  info.time = app.lastTime;
  out.state.isActive = 55;
  out.state.dataSource = XrHandTrackingDataSourceEXT(55);
  out.joints.locations = XrHandJointLocationsEXT{XR_TYPE_HAND_JOINT_LOCATIONS_EXT, &out.state};
  out.joints.locations.jointCount = XR_HAND_JOINT_COUNT_EXT;
  out.joints.locations.jointLocations = out.joints.joints.data();
  return locate(tracker, &info, &out.joints.locations);
}

std::unique_ptr<App> makeApp(const char* handTracking) {
  XrEnv env;
  env.handTracking = handTracking;
  env.script = gripLine(0, "right", kGrip) + squeezeLine(0, "right", 0.0f);
  applyEnv(env);
  auto app = std::make_unique<App>(AppOptions{
      {XR_EXT_HAND_TRACKING_EXTENSION_NAME, XR_EXT_HAND_TRACKING_DATA_SOURCE_EXTENSION_NAME}});
  REQUIRE(app->ok());
  // The session is focused and the controller located.
  REQUIRE(runUntil(*app, [&] { return app->framesEnded >= 1; }));
  return app;
}

}  // namespace

TEST_CASE("The layer offers XR_EXT_hand_tracking_data_source", "[layer][data_source]") {
  XrEnv env;
  env.handTracking = "absent";
  applyEnv(env);
  CHECK(offered(XR_EXT_HAND_TRACKING_DATA_SOURCE_EXTENSION_NAME));
}

TEST_CASE("Joints synthesized from a controller report the CONTROLLER data source",
          "[layer][data_source]") {
  auto app = makeApp("absent");
  XrHandTrackingDataSourceEXT both[] = {XR_HAND_TRACKING_DATA_SOURCE_UNOBSTRUCTED_EXT,
                                        XR_HAND_TRACKING_DATA_SOURCE_CONTROLLER_EXT};
  XrHandTrackingDataSourceEXT controllerOnly[] = {XR_HAND_TRACKING_DATA_SOURCE_CONTROLLER_EXT};
  XrHandTrackingDataSourceInfoEXT info{XR_TYPE_HAND_TRACKING_DATA_SOURCE_INFO_EXT};
  const bool requested = GENERATE(false, true);
  const bool onlyController = GENERATE(false, true);
  CAPTURE(requested, onlyController);
  info.requestedDataSourceCount = onlyController ? 1 : 2;
  info.requestedDataSources = onlyController ? controllerOnly : both;
  XrHandTrackerEXT tracker = XR_NULL_HANDLE;
  REQUIRE(createTracker(*app, requested ? &info : nullptr, tracker) == XR_SUCCESS);
  Located l;
  REQUIRE(runUntil(
      *app, [&] { return locate(*app, tracker, l) == XR_SUCCESS && l.joints.locations.isActive; }));
  CHECK(l.state.isActive == XR_TRUE);
  CHECK(l.state.dataSource == XR_HAND_TRACKING_DATA_SOURCE_CONTROLLER_EXT);
  CHECK(validationLog().empty());
}

TEST_CASE("An app that accepts only unobstructed hands gets no controller-synthesized joints",
          "[layer][data_source]") {
  auto app = makeApp("absent");
  XrHandTrackingDataSourceEXT unobstructed[] = {XR_HAND_TRACKING_DATA_SOURCE_UNOBSTRUCTED_EXT};
  XrHandTrackingDataSourceInfoEXT info{XR_TYPE_HAND_TRACKING_DATA_SOURCE_INFO_EXT, nullptr, 1,
                                       unobstructed};
  XrHandTrackerEXT tracker = XR_NULL_HANDLE;
  REQUIRE(createTracker(*app, &info, tracker) == XR_SUCCESS);
  // A tracker accepting the controller, beside it, is active: the grip is there.
  XrHandTrackerEXT other = XR_NULL_HANDLE;
  REQUIRE(createTracker(*app, nullptr, other) == XR_SUCCESS);
  Located l, o;
  REQUIRE(runUntil(
      *app, [&] { return locate(*app, other, o) == XR_SUCCESS && o.joints.locations.isActive; }));
  REQUIRE(locate(*app, tracker, l) == XR_SUCCESS);
  CHECK(l.joints.locations.isActive == XR_FALSE);
  for (const auto& j : l.joints.joints) CHECK(j.locationFlags == 0);
  CHECK(l.state.isActive == XR_FALSE);
  CHECK(validationLog().empty());
}

TEST_CASE("A hand-tracking runtime's joints pass through as UNOBSTRUCTED", "[layer][data_source]") {
  auto app = makeApp("1");
  XrHandTrackingDataSourceEXT both[] = {XR_HAND_TRACKING_DATA_SOURCE_CONTROLLER_EXT,
                                        XR_HAND_TRACKING_DATA_SOURCE_UNOBSTRUCTED_EXT};
  XrHandTrackingDataSourceInfoEXT info{XR_TYPE_HAND_TRACKING_DATA_SOURCE_INFO_EXT, nullptr, 2,
                                       both};
  XrHandTrackerEXT tracker = XR_NULL_HANDLE;
  // The mock runtime lacks the extension: its struct is taken out of the chains it sees (core
  // validation, below the layer, would report it), and put back for the app.
  REQUIRE(createTracker(*app, &info, tracker) == XR_SUCCESS);
  CHECK(info.next == nullptr);
  Located l;
  REQUIRE(runUntil(
      *app, [&] { return locate(*app, tracker, l) == XR_SUCCESS && l.joints.locations.isActive; }));
  CHECK(l.joints.locations.next == &l.state);
  CHECK(l.state.isActive == XR_TRUE);
  CHECK(l.state.dataSource == XR_HAND_TRACKING_DATA_SOURCE_UNOBSTRUCTED_EXT);
  CHECK(validationLog().empty());
}

TEST_CASE("Bad data-source requests are refused and create no tracker", "[layer][data_source]") {
  const char* runtime = GENERATE("absent", "1");
  CAPTURE(runtime);
  auto app = makeApp(runtime);
  XrHandTrackingDataSourceEXT twice[] = {XR_HAND_TRACKING_DATA_SOURCE_CONTROLLER_EXT,
                                         XR_HAND_TRACKING_DATA_SOURCE_CONTROLLER_EXT};
  XrHandTrackingDataSourceEXT unknown[] = {XrHandTrackingDataSourceEXT(7)};
  XrHandTrackingDataSourceInfoEXT info{XR_TYPE_HAND_TRACKING_DATA_SOURCE_INFO_EXT};
  SECTION("no source") {
    info.requestedDataSourceCount = 0;
    info.requestedDataSources = twice;
  }
  SECTION("a null array") {
    info.requestedDataSourceCount = 1;
    info.requestedDataSources = nullptr;
  }
  SECTION("a source twice") {
    info.requestedDataSourceCount = 2;
    info.requestedDataSources = twice;
  }
  SECTION("a value that is no source") {
    info.requestedDataSourceCount = 1;
    info.requestedDataSources = unknown;
  }
  XrHandTrackerEXT tracker = reinterpret_cast<XrHandTrackerEXT>(uintptr_t(55));
  CHECK(createTracker(*app, &info, tracker) == XR_ERROR_VALIDATION_FAILURE);
  CHECK(tracker == reinterpret_cast<XrHandTrackerEXT>(uintptr_t(55)));
  CHECK(validationLog().empty());
}
