// The layer's own input never changes what the app's input calls return (issue 38), on the mock
// runtime through the loader: an app may attach its action sets whenever it likes, a sync the
// runtime refuses with the layer's set is made again as the app asked, and an app with no
// actions at all still gets the outer hand on the hands the runtime tracks. Joints the runtime
// marks invalid are never drawn on. Every wait is for an outcome, bounded in time.
#include <catch2/catch.hpp>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "grasp_v2.h"
#include "mock_checks.h"
#include "scene/analytic_shape.h"

namespace {

using namespace sdfg;
using namespace sdfg::test;

const XrPosef kGrip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};

// What an app that loads its level first does: makes its action set with a squeeze action,
// suggests Touch bindings and attaches it, all now (frames may have run). The results of the
// suggest and the attach; app.appSet is then synced by every frame.
struct AttachResults {
  XrResult suggest = XR_ERROR_RUNTIME_FAILURE;
  XrResult attach = XR_ERROR_RUNTIME_FAILURE;
};

AttachResults attachAppSet(App& app) {
  AttachResults out;
  XrActionSetCreateInfo asci{XR_TYPE_ACTION_SET_CREATE_INFO};
  std::strcpy(asci.actionSetName, "late_app");
  std::strcpy(asci.localizedActionSetName, "Late app");
  XrActionSet set = XR_NULL_HANDLE;
  REQUIRE(xrCreateActionSet(app.instance, &asci, &set) == XR_SUCCESS);
  XrActionCreateInfo aci{XR_TYPE_ACTION_CREATE_INFO};
  aci.actionType = XR_ACTION_TYPE_FLOAT_INPUT;
  std::strcpy(aci.actionName, "grab");
  std::strcpy(aci.localizedActionName, "Grab");
  aci.countSubactionPaths = 2;
  aci.subactionPaths = app.hands.data();
  XrAction squeeze = XR_NULL_HANDLE;
  REQUIRE(xrCreateAction(set, &aci, &squeeze) == XR_SUCCESS);
  XrPath profile = XR_NULL_PATH, l = XR_NULL_PATH, r = XR_NULL_PATH;
  xrStringToPath(app.instance, "/interaction_profiles/oculus/touch_controller", &profile);
  xrStringToPath(app.instance, "/user/hand/left/input/squeeze/value", &l);
  xrStringToPath(app.instance, "/user/hand/right/input/squeeze/value", &r);
  XrActionSuggestedBinding b[2] = {{squeeze, l}, {squeeze, r}};
  XrInteractionProfileSuggestedBinding sb{XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING};
  sb.interactionProfile = profile;
  sb.countSuggestedBindings = 2;
  sb.suggestedBindings = b;
  out.suggest = xrSuggestInteractionProfileBindings(app.instance, &sb);
  XrSessionActionSetsAttachInfo at{XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO};
  at.countActionSets = 1;
  at.actionSets = &set;
  out.attach = xrAttachSessionActionSets(app.session, &at);
  if (out.attach == XR_SUCCESS) {
    app.appSet = set;
    app.appSqueeze = squeeze;
  }
  return out;
}

// Frames until `done` holds or 60 s pass, 11 ms apart as at 90 Hz.
template <class Done>
bool pacedUntil(App& app, Done done) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!done()) {
    if (std::chrono::steady_clock::now() > end) return false;
    app.frame();
    std::this_thread::sleep_for(std::chrono::microseconds(11111));
  }
  return true;
}

}  // namespace

TEST_CASE(
    "An app that attaches its action set after its first frames is answered as without "
    "the layer",
    "[layer][input]") {
  // Frames before the attach: the first frame (where the layer once attached its own set alone)
  // and a level's loading. Runtimes without hands and with a system that cannot track them.
  const int framesBefore = GENERATE(1, 10);
  const std::string handTracking = GENERATE(std::string("absent"), std::string("0"));
  CAPTURE(framesBefore, handTracking);
  const bool layer = GENERATE(false, true);
  CAPTURE(layer);
  XrEnv env;
  env.layer = layer;
  env.handTracking = handTracking;
  env.script = gripLine(0, "right", kGrip) + squeezeLine(0, "right", 0.75f);
  applyEnv(env);
  AppOptions options;
  // Without the layer the runtime offers no hand tracking to enable.
  if (layer) options.extensions = {XR_EXT_HAND_TRACKING_EXTENSION_NAME};
  options.appActions = false;
  App app(options);
  REQUIRE(app.ok());
  XrHandTrackerEXT tracker = XR_NULL_HANDLE;
  if (layer) {
    Ext ext(app);
    tracker = makeTracker(app, ext, XR_HAND_RIGHT_EXT);
  }
  REQUIRE(pacedUntil(app, [&] { return app.framesEnded >= uint64_t(framesBefore); }));
  // Waiting for the app's attach: hands synthesized from the controllers are not active yet.
  if (layer) CHECK_FALSE(isActive(app, tracker));
  const AttachResults r = attachAppSet(app);
  CHECK(r.suggest == XR_SUCCESS);
  CHECK(r.attach == XR_SUCCESS);
  REQUIRE(r.attach == XR_SUCCESS);
  // Every sync after it succeeds and the app's own action reads its controller.
  const uint64_t syncsBefore = mockStats(app).syncCount;
  REQUIRE(pacedUntil(app, [&] { return mockStats(app).syncCount >= syncsBefore + 5; }));
  CHECK(app.lastSync == XR_SUCCESS);
  CHECK(app.appSqueezeValue(1) == Approx(0.75f));
  // With the layer, its set went with the app's: the synthesized hand follows the controller.
  if (layer) {
    CHECK(pacedUntil(app, [&] { return isActive(app, tracker); }));
    Joints j;
    REQUIRE(locateJoints(app, tracker, j) == XR_SUCCESS);
    CHECK(length(sub(j.joints[XR_HAND_JOINT_PALM_EXT].pose.position, kGrip.position)) < 0.06f);
  }
  CHECK(validationLog().empty());
}

TEST_CASE(
    "An app that never attaches action sets gets every call answered and inactive "
    "synthesized hands",
    "[layer][input]") {
  XrEnv env;
  env.handTracking = "absent";
  env.script = gripLine(0, "right", kGrip) + squeezeLine(0, "right", 1.0f);
  applyEnv(env);
  AppOptions options;
  options.extensions = {XR_EXT_HAND_TRACKING_EXTENSION_NAME};
  options.appActions = false;
  App app(options);
  REQUIRE(app.ok());
  Ext ext(app);
  XrHandTrackerEXT tracker = makeTracker(app, ext, XR_HAND_RIGHT_EXT);
  REQUIRE(pacedUntil(app, [&] { return app.framesEnded >= 30; }));
  // Nothing attached on the runtime: no profile in use, no sync made by anyone.
  const XrMockRuntimeStatsSDFG stats = mockStats(app);
  CHECK(stats.currentProfile == XR_NULL_PATH);
  CHECK(stats.syncCount == 0u);
  // No controller to read without an action set: the hand says so, as the specification allows.
  Joints j;
  CHECK(locateJoints(app, tracker, j) == XR_SUCCESS);
  CHECK_FALSE(j.locations.isActive);
  // The app may still attach on frame 30.
  CHECK(attachAppSet(app).attach == XR_SUCCESS);
  CHECK(pacedUntil(app, [&] { return isActive(app, tracker); }));
  CHECK(validationLog().empty());
}

TEST_CASE("attach_alone attaches the layer's set for an app with none and then refuses its attach",
          "[layer][input]") {
  XrEnv env;
  env.handTracking = "absent";
  env.script = gripLine(0, "right", kGrip);
  env.extra = {{"SDFG_AUTOGRASP_ATTACH_ALONE", "true"}};
  applyEnv(env);
  AppOptions options;
  options.extensions = {XR_EXT_HAND_TRACKING_EXTENSION_NAME};
  options.appActions = false;
  App app(options);
  REQUIRE(app.ok());
  Ext ext(app);
  XrHandTrackerEXT tracker = makeTracker(app, ext, XR_HAND_RIGHT_EXT);
  CHECK(pacedUntil(app, [&] { return isActive(app, tracker); }));
  // The documented price of the option: an attach after that is the runtime's to refuse.
  CHECK(attachAppSet(app).attach == XR_ERROR_ACTIONSETS_ALREADY_ATTACHED);
}

TEST_CASE("A sync the runtime refuses with the layer's set is made again as the app asked",
          "[layer][input]") {
  XrEnv env;
  env.handTracking = "absent";
  env.script = gripLine(0, "right", kGrip) + squeezeLine(0, "right", 0.5f);
  env.extra = {{"SDFG_MOCK_FAULT", "sync_one_set"}};
  applyEnv(env);
  App app({{XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
  REQUIRE(app.ok());
  REQUIRE(pacedUntil(app, [&] { return mockStats(app).syncCount >= 5; }));
  CHECK(app.lastSync == XR_SUCCESS);
  CHECK(app.appSqueezeValue(1) == Approx(0.5f));
  CHECK(validationLog().empty());
}

namespace {

// An app with runtime hand tracking and no action sets: a table (role SCENE) under the open right
// hand, the hand (the grip, which the mock runtime's tracked hand follows with its wrist) lowered
// 2 mm a frame from 6 cm above the synthesized hand's place through it. The deepest the located
// joints go into the table per frame.
std::vector<float> lowerTrackedHandIntoTable(bool layer, const std::string& fault) {
  const XrVector3f half{0.3f, 0.02f, 0.3f};
  const XrPosef table = boxUnderPalm(kGrip, half);
  const AnalyticShape shape{ShapeKind::box, glm::vec3(half.x, half.y, half.z)};
  const glm::vec3 down = openRightHand(kGrip).down;
  // 8 cm down: the tracked hand goes 2 cm and more into the table, and moves less than the
  // outer hand's release distance (10 cm) past where it touched.
  constexpr int kFrames = 40;
  std::vector<XrPosef> grips;
  for (int k = 0; k < kFrames; ++k) {
    const glm::vec3 d = down * (-0.06f + 0.002f * float(k));
    XrPosef g = kGrip;
    g.position = {g.position.x + d.x, g.position.y + d.y, g.position.z + d.z};
    grips.push_back(g);
  }
  XrEnv env;
  env.layer = layer;
  env.handTracking = "1";
  if (!fault.empty()) env.extra = {{"SDFG_MOCK_FAULT", fault}};
  env.script = gripLine(0, "right", grips.front());  // clear of the table from the start
  applyEnv(env);
  AppOptions options;
  options.extensions = {XR_EXT_HAND_TRACKING_EXTENSION_NAME};
  if (layer) options.extensions.push_back(XR_SDFG_AUTO_GRASP_EXTENSION_NAME);
  options.appActions = false;
  App app(options);
  REQUIRE(app.ok());
  XrHandTrackerCreateInfoEXT ci{XR_TYPE_HAND_TRACKER_CREATE_INFO_EXT};
  ci.hand = XR_HAND_RIGHT_EXT;
  ci.handJointSet = XR_HAND_JOINT_SET_DEFAULT_EXT;
  auto create = app.fn<PFN_xrCreateHandTrackerEXT>("xrCreateHandTrackerEXT");
  REQUIRE(create != nullptr);
  XrHandTrackerEXT tracker = XR_NULL_HANDLE;
  REQUIRE(create(app.session, &ci, &tracker) == XR_SUCCESS);
  if (layer) {
    Ext ext(app);
    makeShapeTarget(app, ext, XR_GRASP_SHAPE_TYPE_BOX_SDFG, half, table,
                    XR_GRASP_TARGET_ROLE_SCENE_SDFG);
  }
  REQUIRE(pacedUntil(app, [&] { return app.framesEnded >= 3; }));
  std::string script;
  const uint64_t first = app.framesEnded + 1;
  for (int k = 0; k < kFrames; ++k) script += gripLine(first + uint64_t(k), "right", grips[k]);
  REQUIRE(app.setScript(script) == XR_SUCCESS);
  std::vector<float> depth;
  auto next = std::chrono::steady_clock::now();
  for (int k = 0; k < kFrames; ++k) {
    next += std::chrono::microseconds(11111);
    std::this_thread::sleep_until(next);
    Joints j;
    XrResult located = XR_ERROR_RUNTIME_FAILURE;
    const uint64_t ended = app.framesEnded;
    app.frame([&] { located = locateJoints(app, tracker, j); });
    REQUIRE(app.framesEnded == ended + 1);
    REQUIRE(located == XR_SUCCESS);
    REQUIRE(j.locations.isActive);
    // A joint the runtime marks invalid has no position to measure.
    Joints valid = j;
    for (XrHandJointLocationEXT& l : valid.joints)
      if ((l.locationFlags & XR_SPACE_LOCATION_POSITION_VALID_BIT) == 0) l = valid.joints[0];
    depth.push_back(depthInBox(valid, shape, table));
  }
  CHECK(validationLog().empty());
  return depth;
}

}  // namespace

TEST_CASE("An app with runtime hand tracking and no actions gets the outer hand",
          "[layer][input]") {
  const std::vector<float> tracked = lowerTrackedHandIntoTable(false, "");
  const std::vector<float> shown = lowerTrackedHandIntoTable(true, "");
  REQUIRE(tracked.size() == shown.size());
  // The runtime's hand starts clear and ends 2 cm or more inside the table...
  CHECK(tracked.front() < -0.01f);
  CHECK(*std::max_element(tracked.begin(), tracked.end()) > 0.02f);
  // ...the hand the app is shown stays on it (the update runs at every frame without a sync).
  CHECK(*std::max_element(shown.begin(), shown.end()) <= 0.001f);
}

TEST_CASE("A tracked hand with a joint the runtime marks invalid is shown as the runtime gives it",
          "[layer][input]") {
  const std::vector<float> tracked = lowerTrackedHandIntoTable(false, "invalid_joint");
  const std::vector<float> shown = lowerTrackedHandIntoTable(true, "invalid_joint");
  REQUIRE(tracked.size() == shown.size());
  CHECK(*std::max_element(tracked.begin(), tracked.end()) > 0.02f);
  // No outer hand on joints it cannot vouch for: every frame is the runtime's.
  for (size_t k = 0; k < tracked.size(); ++k) {
    CAPTURE(k);
    CHECK(shown[k] == tracked[k]);
  }
}

TEST_CASE("Any runtime call of the grab update may fail: the app's calls and destroys go on",
          "[layer][input]") {
  // Each call the layer makes in its grab update, refused by the runtime every time.
  const std::string call =
      GENERATE(std::string("xrGetActionStateFloat"), std::string("xrLocateSpace"),
               std::string("xrLocateHandJointsEXT"), std::string("xrCreateHandTrackerEXT"),
               std::string("xrCreateActionSpace"));
  const std::string handTracking = GENERATE(std::string("1"), std::string("absent"));
  CAPTURE(call, handTracking);
  XrEnv env;
  env.handTracking = handTracking;
  env.extra = {{"SDFG_MOCK_FAULT", "fail:" + call}};
  env.script =
      gripLine(0, "right", kGrip) + squeezeLine(0, "right", 0.0f) + squeezeLine(4, "right", 1.0f);
  applyEnv(env);
  App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
  REQUIRE(app.ok());
  Ext ext(app);
  XrHandTrackerCreateInfoEXT tci{XR_TYPE_HAND_TRACKER_CREATE_INFO_EXT};
  tci.hand = XR_HAND_RIGHT_EXT;
  tci.handJointSet = XR_HAND_JOINT_SET_DEFAULT_EXT;
  XrHandTrackerEXT tracker = XR_NULL_HANDLE;
  // The runtime's own trackers are refused with xrCreateHandTrackerEXT failing: as without the
  // layer, the app has none then.
  const XrResult made = ext.createTracker(app.session, &tci, &tracker);
  CHECK((made == XR_SUCCESS || (call == "xrCreateHandTrackerEXT" && handTracking == "1" &&
                                made == XR_ERROR_RUNTIME_FAILURE)));
  // A sphere in a space of its own, under the hand.
  XrReferenceSpaceCreateInfo rs{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
  rs.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_LOCAL;
  rs.poseInReferenceSpace.orientation.w = 1;
  XrSpace space = XR_NULL_HANDLE;
  REQUIRE(xrCreateReferenceSpace(app.session, &rs, &space) == XR_SUCCESS);
  const XrVector3f centre = boxCentreInLocal(kGrip, /*right=*/true);
  const TestMesh sphere = makeIcosphere(0.04f, 3);
  XrGraspTargetVerticesSDFG v{XR_TYPE_GRASP_TARGET_VERTICES_SDFG};
  v.vertexCount = uint32_t(sphere.vertices.size());
  v.vertices = sphere.vertices.data();
  v.indexCount = uint32_t(sphere.indices.size());
  v.indices = sphere.indices.data();
  XrGraspTargetCreateInfoSDFG ci{XR_TYPE_GRASP_TARGET_CREATE_INFO_SDFG, &v};
  ci.placement = {XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG, nullptr, space, {{0, 0, 0, 1}, centre}};
  XrGraspTargetSDFG target = XR_NULL_HANDLE;
  REQUIRE(ext.create(app.session, &ci, &target) == XR_SUCCESS);
  int located = 0;
  const bool ran = pacedUntil(app, [&] {
    if (tracker != XR_NULL_HANDLE && app.lastTime > 0) {
      // The runtime's answer where the runtime answers (its tracker with its locate failing).
      Joints j;
      const bool refused = call == "xrLocateHandJointsEXT" && handTracking == "1";
      CHECK(locateJoints(app, tracker, j) == (refused ? XR_ERROR_RUNTIME_FAILURE : XR_SUCCESS));
    }
    return ++located >= 40;
  });
  CHECK(ran);
  CHECK(app.framesEnded >= 39u);
  CHECK(app.lastSync == XR_SUCCESS);
  XrGraspStateSDFG state{XR_TYPE_GRASP_STATE_SDFG};
  XrGraspStateGetInfoSDFG gi{XR_TYPE_GRASP_STATE_GET_INFO_SDFG, nullptr, XR_HAND_RIGHT_EXT};
  CHECK(ext.state(app.session, &gi, &state) == XR_SUCCESS);
  // The destroys the layer waits in return, and go down.
  CHECK(xrDestroySpace(space) == XR_SUCCESS);
  CHECK(ext.destroy(target) == XR_SUCCESS);
  app.frames(3);
  CHECK(mockStats(app).framesEnded == app.framesEnded);
  app.destroySession();
  CHECK(validationLog().empty());
}
