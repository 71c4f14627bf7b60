// Hand synthesis on a controller-only runtime and grasping end to end (CPU SDF path): scripted
// controller placements, targets registered through XR_SDFG_auto_grasp, joints read back with
// xrLocateHandJointsEXT and checked against the exact distance to the object.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <sstream>

#include <glm/gtc/quaternion.hpp>

#include "grasp_checks.h"
#include "mock_runtime_test.h"
#include "test_scenes.h"
#include "xr_harness.h"

using namespace sdfg::test;

TEST_CASE("On a controller-only runtime the layer synthesizes 26 joints from grip and squeeze",
          "[layer][synthesis]") {
  XrEnv env;
  env.handTracking = "absent";
  const XrPosef grip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};
  env.script = gripLine(0, "right", grip) + squeezeLine(0, "right", 0.0f) +
               squeezeLine(5, "right", 0.0f) + squeezeLine(6, "right", 1.0f);
  applyEnv(env);
  App app({{XR_EXT_HAND_TRACKING_EXTENSION_NAME, XR_EXT_HAND_JOINTS_MOTION_RANGE_EXTENSION_NAME}});
  REQUIRE(app.ok());
  Ext ext(app);

  XrSystemHandTrackingPropertiesEXT ht{XR_TYPE_SYSTEM_HAND_TRACKING_PROPERTIES_EXT};
  XrSystemProperties props{XR_TYPE_SYSTEM_PROPERTIES, &ht};
  REQUIRE(xrGetSystemProperties(app.instance, app.system, &props) == XR_SUCCESS);
  CHECK(ht.supportsHandTracking == XR_TRUE);
  CHECK(props.next == &ht);  // the chain is given back intact

  XrHandTrackerEXT tracker = makeTracker(app, ext, XR_HAND_RIGHT_EXT);
  app.frames(3);
  Joints open;
  REQUIRE(locateJoints(app, tracker, open) == XR_SUCCESS);
  REQUIRE(open.locations.isActive);
  for (const auto& j : open.joints) {
    CHECK((j.locationFlags & XR_SPACE_LOCATION_POSITION_VALID_BIT) != 0);
    CHECK(j.radius > 0.0f);
  }
  // The palm sits near the grip (within a hand's width).
  CHECK(length(sub(open.joints[XR_HAND_JOINT_PALM_EXT].pose.position, grip.position)) < 0.06f);
  app.frames(6);
  Joints fist, conforming;
  REQUIRE(locateJoints(app, tracker, fist) == XR_SUCCESS);
  XrHandJointsMotionRangeInfoEXT mr{XR_TYPE_HAND_JOINTS_MOTION_RANGE_INFO_EXT, nullptr,
                                    XR_HAND_JOINTS_MOTION_RANGE_CONFORMING_TO_CONTROLLER_EXT};
  REQUIRE(locateJoints(app, tracker, conforming, &mr) == XR_SUCCESS);
  auto tipToPalm = [](const Joints& j) {
    return length(sub(j.joints[XR_HAND_JOINT_MIDDLE_TIP_EXT].pose.position,
                      j.joints[XR_HAND_JOINT_PALM_EXT].pose.position));
  };
  // Squeezing closes the hand; conforming to the controller closes it less.
  CHECK(tipToPalm(fist) < tipToPalm(open) - 0.03f);
  CHECK(tipToPalm(conforming) > tipToPalm(fist) + 0.005f);
  CHECK(tipToPalm(conforming) < tipToPalm(open));
  // The app's own squeeze action still reports the controller.
  CHECK(app.appSqueezeValue(1) == Approx(1.0f));
  CHECK(validationLog().empty());
}

TEST_CASE("A squeezed hand closes onto a sphere: fingers touch within 2 mm and never enter it",
          "[layer][grasp]") {
  const XrPosef grip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};
  const XrVector3f centre = boxCentreInLocal(grip, /*right=*/true);
  const float radius = 0.04f;
  GraspOutcome out = graspScene(makeIcosphere(radius, 4), {{0, 0, 0, 1}, centre}, grip);
  checkContacts(out, [&](const XrVector3f& p) { return length(sub(p, centre)) - radius; });
}

// A 9 mm bar is thin for the default 1.33 cm voxels: the paper solver's tips end 2.5 to 3.3 mm
// inside the tip radius at 16^3, so this scene asks for a finer grid through the options.
TEST_CASE("A squeezed hand closes onto a mug handle (torus bar) within 2 mm", "[layer][grasp]") {
  const XrPosef grip{{0, 0, 0, 1}, {-0.2f, -0.3f, -0.4f}};
  const XrVector3f centre = boxCentreInLocal(grip, /*right=*/false);
  const float major = 0.04f, minor = 0.009f;
  // The ring's axis is LOCAL +X (across the fingers' curl plane of a hand held level), so the
  // fingers wrap its bar; its upper bar passes just under the palm.
  const XrPosef pose{{0, 0.70710678f, 0, 0.70710678f}, {centre.x, centre.y - 0.005f, centre.z}};
  GraspOutcome out = graspScene(makeTorus(major, minor, 64, 24), pose, grip, "left", 32);
  checkContacts(out, [&](const XrVector3f& p) { return torusDistance(pose, major, minor, p); });
}

// The same bar 2.2 cm to the side of the hand (where the outer hand once showed a hand the bar was
// set up in): the ring finger passes beside the bar, where the field's far nodes are low bounds.
// It stopped there at curl 0.85 and was reported in contact 42 mm from the bar; now the exact
// check's finding of nothing near closes it on (fully), and only fingers on the bar say contact.
TEST_CASE("A finger the field stops beside a mug handle is closed on, not reported in contact",
          "[layer][grasp]") {
  const XrPosef centred{{0, 0, 0, 1}, {-0.2f, -0.3f, -0.4f}};
  const XrVector3f centre = boxCentreInLocal(centred, /*right=*/false);
  const XrPosef grip{{0, 0, 0, 1}, {-0.2f + 0.0222f, -0.3f - 0.0029f, -0.4f}};
  const float major = 0.04f, minor = 0.009f;
  const XrPosef pose{{0, 0.70710678f, 0, 0.70710678f}, {centre.x, centre.y - 0.005f, centre.z}};
  GraspOutcome out = graspScene(makeTorus(major, minor, 64, 24), pose, grip, "left", 32);
  checkContacts(
      out, [&](const XrVector3f& p) { return torusDistance(pose, major, minor, p); },
      /*minContacts=*/1);
  CHECK(out.state.fingers[3].inContact == XR_FALSE);
  CHECK(out.state.fingers[3].curl == Approx(1.0f));
}

// Where the open right hand driven by `grip` is, in LOCAL space: its palm joint, the palm's
// normal (out of the palm) and the axis across its fingers (index knuckle to little knuckle).
struct OpenHand {
  glm::vec3 palm, down, across;
  glm::vec3 knuckles;  // the middle finger's proximal joint (its knuckle)
};

static OpenHand openHandInLocal(const XrPosef& grip) {
  using namespace sdfg;
  const HandModel model = HandModel::defaultAdult(Hand::right);
  const Pose localFromWrist = toPose(grip) * wristFromGrip(model).inverse();
  JointPoses open;
  model.pose(FingerCurls{}, open);
  const Pose& palm = open[int(Joint::palm)];
  const glm::vec3 across =
      open[int(Joint::little_proximal)].position - open[int(Joint::index_proximal)].position;
  return {localFromWrist.transformPoint(palm.position),
          localFromWrist.transformVector(palm.orientation * glm::vec3(0, -1, 0)),
          glm::normalize(localFromWrist.transformVector(across)),
          localFromWrist.transformPoint(open[int(Joint::middle_proximal)].position)};
}

// Places `mesh`, turned by `orientation` and shifted by `shift` from the palm joint, on the palm
// side of the open right hand driven by `grip`: moved along the palm's normal until every sphere
// of the open hand is at least 3 mm clear of it, so the grasp starts from a hand that does not
// already intersect the object.
static XrPosef underOpenPalm(const TestMesh& mesh, const XrPosef& grip,
                             const XrQuaternionf& orientation = {0, 0, 0, 1},
                             const glm::vec3& shift = glm::vec3(0.0f)) {
  using namespace sdfg;
  const HandModel model = HandModel::defaultAdult(Hand::right);
  const Pose localFromWrist = toPose(grip) * wristFromGrip(model).inverse();
  const OpenHand hand = openHandInLocal(grip);
  std::vector<BodySphere> spheres;
  for (int f = 0; f < kFingerCount; ++f) model.phalanxSpheres(Finger(f), 0.0f, spheres);
  JointPoses open;
  model.pose(FingerCurls{}, open);
  spheres.push_back({open[int(Joint::palm)].position, model.jointRadius(Joint::palm), 0});
  const ExactDistance atOrigin(mesh, XrPosef{orientation, {0, 0, 0}});
  for (float s = 0.0f; s < 0.4f; s += 0.002f) {
    const glm::vec3 t = hand.palm + shift + hand.down * s;
    bool clear = true;
    for (const BodySphere& b : spheres) {
      const glm::vec3 p = localFromWrist.transformPoint(b.center) - t;
      if (atOrigin({p.x, p.y, p.z}) < b.radius + 0.003f) {
        clear = false;
        break;
      }
    }
    if (clear) return XrPosef{orientation, {t.x, t.y, t.z}};
  }
  FAIL("no placement under the open palm keeps the hand clear of the mesh");
  return {};
}

// The procedural mug (shapes.h: one closed genus-1 surface, handle on its +X side) turned so the
// handle points at the palm and its outer bar (along the mug's Y) runs across the fingers, then
// brought under the open hand: the fingers close over the handle onto the cup.
TEST_CASE("A squeezed hand closes over the mug's handle onto the cup within 2 mm",
          "[layer][grasp]") {
  const XrPosef grip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};
  const TestMesh mug = toTestMesh(sdfg::makeMug());
  const OpenHand hand = openHandInLocal(grip);
  const glm::vec3 x = -hand.down;
  const glm::vec3 y = glm::normalize(hand.across - glm::dot(hand.across, x) * x);
  const glm::quat q = glm::quat_cast(glm::mat3(x, y, glm::cross(x, y)));
  // The bar lies across the base of the fingers, as in a hand holding a mug by its handle: under
  // the knuckles, less the bar's centre-line offset from the mug's axis (about 6.9 cm along x).
  glm::vec3 toKnuckles = hand.knuckles - hand.palm;
  toKnuckles -= glm::dot(toKnuckles, hand.down) * hand.down;
  const XrPosef pose = underOpenPalm(mug, grip, {q.x, q.y, q.z, q.w}, toKnuckles);
  GraspOutcome out = graspScene(mug, pose, grip);
  ExactDistance exact(mug, pose);
  checkContacts(out, [&](const XrVector3f& p) { return exact(p); });
  // The handle is in the closed hand: the bar under the knuckles (3 mm clear at the start) and
  // the fingers over it, down to the cup's wall beyond it (the 2 cm hole is too small for a
  // finger curling from above), the thumb on the cup's other side.
  const glm::vec3 handle = toPose(pose).transformPoint(glm::vec3(0.069f, 0.0f, 0.0f));
  CHECK(glm::length(handle - hand.knuckles) < 0.03f);
  int onWall = 0;
  for (const XrGraspFingerStateSDFG& f : out.state.fingers)
    if (f.inContact && std::hypot(f.contactPoint.x, f.contactPoint.z) < 0.05f) ++onWall;
  CHECK(onWall >= 3);
}

TEST_CASE("A squeezed hand closes onto the Stanford bunny within 2 mm", "[layer][grasp]") {
  TestMesh bunny;
  if (!loadSharedObj("stanford-bunny.obj", bunny)) {
    SDFG_SKIP("../shared/meshes/stanford-bunny.obj not found");
  }
  const XrPosef grip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};
  centreMesh(bunny);
  const XrPosef pose = underOpenPalm(bunny, grip);
  GraspOutcome out = graspScene(bunny, pose, grip);
  ExactDistance exact(bunny, pose);
  const auto distance = [&](const XrVector3f& p) { return exact(p); };
  checkContacts(out, distance);
  // The default strategy (ours, exact_check on) checks each stop on the mesh itself, so its
  // contacts are far tighter than the 2 mm the 16^3 field alone allows.
  for (int f = 0; f < 5; ++f) {
    if (!out.state.fingers[f].inContact) continue;
    CAPTURE(f);
    CHECK(std::abs(fingerClearance(out, f, distance)) <= 0.0002f);
  }
}

TEST_CASE("Destroying a held target lets the hand go back to the user's pose", "[layer][grasp]") {
  XrEnv env;
  env.handTracking = "absent";
  const XrPosef grip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};
  env.script = gripLine(0, "right", grip) + squeezeLine(0, "right", 0.0f) +
               squeezeLine(4, "right", 0.0f) + squeezeLine(6, "right", 1.0f);
  applyEnv(env);
  App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
  REQUIRE(app.ok());
  Ext ext(app);
  XrHandTrackerEXT tracker = makeTracker(app, ext, XR_HAND_RIGHT_EXT);
  const XrVector3f centre = boxCentreInLocal(grip, true);
  XrGraspTargetSDFG target = makeTarget(app, ext, makeIcosphere(0.04f, 3), {{0, 0, 0, 1}, centre});
  REQUIRE(framesUntilGrasping(app, ext, XR_HAND_RIGHT_EXT));
  XrGraspStateGetInfoSDFG gi{XR_TYPE_GRASP_STATE_GET_INFO_SDFG, nullptr, XR_HAND_RIGHT_EXT};
  XrGraspStateSDFG st{XR_TYPE_GRASP_STATE_SDFG};
  REQUIRE(ext.state(app.session, &gi, &st) == XR_SUCCESS);
  REQUIRE(st.isGrasping);
  CHECK(st.target == target);
  Joints held, released;
  REQUIRE(locateJoints(app, tracker, held) == XR_SUCCESS);
  REQUIRE(ext.destroy(target) == XR_SUCCESS);
  REQUIRE(ext.state(app.session, &gi, &st) == XR_SUCCESS);
  CHECK_FALSE(st.isGrasping);
  CHECK(st.target == XR_NULL_HANDLE);
  REQUIRE(locateJoints(app, tracker, released) == XR_SUCCESS);
  // Back to the user's fist: the middle tip is closer to the palm than while holding.
  auto tipToPalm = [](const Joints& j) {
    return length(sub(j.joints[XR_HAND_JOINT_MIDDLE_TIP_EXT].pose.position,
                      j.joints[XR_HAND_JOINT_PALM_EXT].pose.position));
  };
  CHECK(tipToPalm(released) < tipToPalm(held) - 0.005f);
  app.frames(2);  // frames go on with the target gone
  CHECK(validationLog().empty());
}

TEST_CASE("Two hands grab two objects at once", "[layer][grasp]") {
  XrEnv env;
  env.handTracking = "absent";
  const XrPosef left{{0, 0, 0, 1}, {-0.25f, -0.3f, -0.4f}};
  const XrPosef right{{0, 0, 0, 1}, {0.25f, -0.3f, -0.4f}};
  env.script = gripLine(0, "left", left) + gripLine(0, "right", right) + squeezeLine(0, "left", 0) +
               squeezeLine(4, "left", 0) + squeezeLine(6, "left", 1) + squeezeLine(0, "right", 0) +
               squeezeLine(4, "right", 0) + squeezeLine(6, "right", 1);
  applyEnv(env);
  App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
  REQUIRE(app.ok());
  Ext ext(app);
  const XrVector3f cl = boxCentreInLocal(left, false), cr = boxCentreInLocal(right, true);
  XrGraspTargetSDFG tl = makeTarget(app, ext, makeIcosphere(0.035f, 3), {{0, 0, 0, 1}, cl});
  XrGraspTargetSDFG tr = makeTarget(app, ext, makeIcosphere(0.045f, 3), {{0, 0, 0, 1}, cr});
  REQUIRE(framesUntilGrasping(app, ext, XR_HAND_LEFT_EXT));
  REQUIRE(framesUntilGrasping(app, ext, XR_HAND_RIGHT_EXT));
  for (auto [hand, target] : {std::pair{XR_HAND_LEFT_EXT, tl}, std::pair{XR_HAND_RIGHT_EXT, tr}}) {
    XrGraspStateGetInfoSDFG gi{XR_TYPE_GRASP_STATE_GET_INFO_SDFG, nullptr, hand};
    XrGraspStateSDFG st{XR_TYPE_GRASP_STATE_SDFG};
    REQUIRE(ext.state(app.session, &gi, &st) == XR_SUCCESS);
    CHECK(st.isGrasping);
    CHECK(st.target == target);
  }
  CHECK(validationLog().empty());
}

TEST_CASE("Releasing the squeeze ends the grasp", "[layer][grasp]") {
  XrEnv env;
  env.handTracking = "absent";
  const XrPosef grip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};
  env.script = gripLine(0, "right", grip) + squeezeLine(0, "right", 0.0f) +
               squeezeLine(4, "right", 0.0f) + squeezeLine(6, "right", 1.0f);
  applyEnv(env);
  App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME}});
  REQUIRE(app.ok());
  Ext ext(app);
  makeTarget(app, ext, makeIcosphere(0.04f, 3), {{0, 0, 0, 1}, boxCentreInLocal(grip, true)});
  REQUIRE(framesUntilGrasping(app, ext, XR_HAND_RIGHT_EXT));
  // The grasp is shown: now the user lets go (the timeline is frame-numbered, so the release is
  // scripted from the frame reached).
  auto setScript = app.fn<PFN_xrMockRuntimeSetScriptSDFG>("xrMockRuntimeSetScriptSDFG");
  REQUIRE(setScript != nullptr);
  const uint64_t now = app.framesEnded;
  const std::string release = gripLine(0, "right", grip) + squeezeLine(now, "right", 1.0f) +
                              squeezeLine(now + 1, "right", 0.0f);
  REQUIRE(setScript(app.instance, release.c_str()) == XR_SUCCESS);
  CHECK(framesUntilGrasping(app, ext, XR_HAND_RIGHT_EXT, false));
  CHECK(validationLog().empty());
}

TEST_CASE("With runtime hand tracking, a grasp never moves a finger the user holds more open",
          "[layer][grasp][passthrough]") {
  // The mock runtime's tracked hand is flat and open, its wrist at the grip pose: the user's
  // curl (0) is below every contact curl, so the held grasp leaves every joint untouched.
  const XrPosef grip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};
  XrEnv env;
  env.script = gripLine(0, "right", grip) + squeezeLine(0, "right", 0.0f) +
               squeezeLine(4, "right", 0.0f) + squeezeLine(6, "right", 1.0f);
  env.layer = false;
  applyEnv(env);
  auto run = [&](bool withTarget, XrGraspStateSDFG* state) {
    App app({withTarget ? std::vector<std::string>{XR_EXT_HAND_TRACKING_EXTENSION_NAME,
                                                   XR_SDFG_AUTO_GRASP_EXTENSION_NAME}
                        : std::vector<std::string>{XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
    REQUIRE(app.ok());
    Ext ext(app);
    XrHandTrackerEXT tracker = makeTracker(app, ext, XR_HAND_RIGHT_EXT);
    if (withTarget) {
      // The grab box of a tracked hand hangs below its wrist joint (hand space (0, -7.5, -8.1) cm).
      const XrVector3f c{grip.position.x, grip.position.y - 0.075f, grip.position.z - 0.081f};
      makeTarget(app, ext, makeIcosphere(0.04f, 3), {{0, 0, 0, 1}, c});
      REQUIRE(framesUntilGrasping(app, ext, XR_HAND_RIGHT_EXT));
    } else {
      app.frames(12);  // no grasp to wait for: the runtime's open hand, the same every frame
    }
    Joints j;
    REQUIRE(locateJoints(app, tracker, j) == XR_SUCCESS);
    if (withTarget) {
      XrGraspStateGetInfoSDFG gi{XR_TYPE_GRASP_STATE_GET_INFO_SDFG, nullptr, XR_HAND_RIGHT_EXT};
      REQUIRE(ext.state(app.session, &gi, state) == XR_SUCCESS);
    }
    return j;
  };
  XrGraspStateSDFG state{XR_TYPE_GRASP_STATE_SDFG};
  const Joints runtime = run(false, nullptr);
  env.layer = true;
  applyEnv(env);
  const Joints layered = run(true, &state);
  CHECK(state.isGrasping);  // a grasp is held...
  // ...and the open fingers are the runtime's, bit for bit.
  CHECK(std::memcmp(runtime.joints.data(), layered.joints.data(), sizeof(runtime.joints)) == 0);
  CHECK(validationLog().empty());
}

TEST_CASE("Destroying the session while a hand holds a target releases everything",
          "[layer][grasp]") {
  XrEnv env;
  env.handTracking = "absent";
  const XrPosef grip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};
  env.script = gripLine(0, "right", grip) + squeezeLine(0, "right", 0.0f) +
               squeezeLine(4, "right", 0.0f) + squeezeLine(6, "right", 1.0f);
  applyEnv(env);
  App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
  REQUIRE(app.ok());
  Ext ext(app);
  XrHandTrackerEXT tracker = makeTracker(app, ext, XR_HAND_RIGHT_EXT);
  XrGraspTargetSDFG target =
      makeTarget(app, ext, makeIcosphere(0.04f, 3), {{0, 0, 0, 1}, boxCentreInLocal(grip, true)});
  REQUIRE(framesUntilGrasping(app, ext, XR_HAND_RIGHT_EXT));
  XrGraspStateGetInfoSDFG gi{XR_TYPE_GRASP_STATE_GET_INFO_SDFG, nullptr, XR_HAND_RIGHT_EXT};
  XrGraspStateSDFG st{XR_TYPE_GRASP_STATE_SDFG};
  REQUIRE(ext.state(app.session, &gi, &st) == XR_SUCCESS);
  REQUIRE(st.isGrasping);
  const XrSession old = app.session;
  app.destroySession();
  // The session's children went with it.
  CHECK(ext.destroy(target) == XR_ERROR_HANDLE_INVALID);
  CHECK(ext.state(old, &gi, &st) == XR_ERROR_HANDLE_INVALID);
  Joints j;
  CHECK(locateJoints(app, tracker, j) == XR_ERROR_HANDLE_INVALID);
  CHECK(validationLog().empty());
}
