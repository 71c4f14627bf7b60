// The hand never starts inside (issue 21), end to end through the loader: a controller-driven
// hand squeezed with its palm scripted inside the mug's wall or the thin plate ends with every
// part of it (palm, metacarpals, phalanges) clear of the object, moved by the offset the layer
// reports in XrGraspHandOffsetSDFG; the offset blends in at the grab and out at the release.
#include <catch2/catch.hpp>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <string>

#include <glm/gtc/quaternion.hpp>

#include "grasp_checks.h"
#include "test_scenes.h"
#include "xr_harness.h"

namespace {

using namespace sdfg::test;

// The open right hand driven by `grip`, in LOCAL space: palm joint, palm normal (out of the
// palm), the axis across the fingers, and the wrist pose.
struct OpenPalm {
  glm::vec3 palm, down, across;
  sdfg::Pose wrist;
};

OpenPalm openPalmInLocal(const XrPosef& grip) {
  using namespace sdfg;
  const HandModel model = HandModel::defaultAdult(Hand::right);
  const Pose localFromWrist = toPose(grip) * wristFromGrip(model).inverse();
  JointPoses open;
  model.pose(FingerCurls{}, open);
  const Pose& palm = open[int(Joint::palm)];
  const glm::vec3 across =
      open[int(Joint::little_proximal)].position - open[int(Joint::index_proximal)].position;
  return {localFromWrist.transformPoint(palm.position),
          glm::normalize(localFromWrist.transformVector(palm.orientation * glm::vec3(0, -1, 0))),
          glm::normalize(localFromWrist.transformVector(across)), localFromWrist};
}

struct Reading {
  Joints joints;
  XrGraspStateSDFG state{XR_TYPE_GRASP_STATE_SDFG};
  XrGraspHandOffsetSDFG offset{XR_TYPE_GRASP_HAND_OFFSET_SDFG};
};

void read(App& app, const Ext& ext, XrHandTrackerEXT tracker, Reading& r) {
  REQUIRE(locateJoints(app, tracker, r.joints) == XR_SUCCESS);
  r.offset = XrGraspHandOffsetSDFG{XR_TYPE_GRASP_HAND_OFFSET_SDFG};
  r.state = XrGraspStateSDFG{XR_TYPE_GRASP_STATE_SDFG, &r.offset};
  XrGraspStateGetInfoSDFG gi{XR_TYPE_GRASP_STATE_GET_INFO_SDFG, nullptr, XR_HAND_RIGHT_EXT};
  REQUIRE(ext.state(app.session, &gi, &r.state) == XR_SUCCESS);
}

// Grabs `mesh` at `pose` with the right hand at `grip` (squeeze from frame 6, released once the
// offset has blended in), and checks the hand ends clear, moved by the reported offset, blended
// both ways. Frames run until each outcome, with a time bound: the layer solves on its session's
// worker, so how many frames a grasp takes depends on the machine.
// With `neighbour` (a second object, registered too): the hand starts clear of it and ends clear
// of both (the clearance moves it out of the one it grabs without moving it into the other).
struct Neighbour {
  TestMesh mesh;
  XrPosef pose;
};

// The outer hand is off: this is the grasp's own clearance (with it on, a hand that appears inside
// is shown at the nearest clear pose before any squeeze: layer_outer_hand.tests.cpp).
void grabFromInside(const TestMesh& mesh, const XrPosef& pose, const XrPosef& grip,
                    const Neighbour* neighbour = nullptr) {
  XrEnv env;
  env.handTracking = "absent";
  env.extra = {{"SDFG_AUTOGRASP_OUTER_HAND", "false"}};
  env.script =
      gripLine(0, "right", grip) + squeezeLine(0, "right", 0.0f) + squeezeLine(6, "right", 1.0f);
  applyEnv(env);
  App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
  REQUIRE(app.ok());
  Ext ext(app);
  XrHandTrackerEXT tracker = makeTracker(app, ext, XR_HAND_RIGHT_EXT);
  makeTarget(app, ext, mesh, pose);
  const ExactDistance exact(mesh, pose);
  const auto distance = [&](const XrVector3f& p) { return exact(p); };
  std::unique_ptr<ExactDistance> other;
  if (neighbour != nullptr) {
    makeTarget(app, ext, neighbour->mesh, neighbour->pose);
    other = std::make_unique<ExactDistance>(neighbour->mesh, neighbour->pose);
  }
  const auto otherDistance = [&](const XrVector3f& p) { return (*other)(p); };

  // The open hand, before the grab, is partly inside the object.
  Reading r;
  // Both set up before the squeeze: the grab solves with the neighbour in its scene.
  REQUIRE(untilSetUp(app, ext, [&](const auto& s) { return s.readyCount >= (other ? 2u : 1u); }));
  app.frames(2);
  read(app, ext, tracker, r);
  REQUIRE(r.state.isGrasping == XR_FALSE);
  REQUIRE(wholeHandClearance(r.joints, distance) < -0.003f);
  if (other) REQUIRE(wholeHandClearance(r.joints, otherDistance) > 0.0f);

  // Held, with the offset blended in fully: polled, not a fixed frame count.
  bool partial = false;
  app.framesUntil([&] {
    read(app, ext, tracker, r);
    if (r.offset.blend > 0.0f && r.offset.blend < 1.0f) partial = true;
    return r.state.isGrasping && r.offset.blend >= 1.0f;
  });
  REQUIRE(r.state.isGrasping == XR_TRUE);
  REQUIRE(r.offset.blend == 1.0f);
  CHECK(partial);  // it took more than one frame: no pop
  CHECK(r.offset.openClearance < -0.003f);
  CHECK(r.offset.exceeded == XR_FALSE);
  CHECK(r.offset.displacement > 0.003f);
  CHECK(r.offset.displacement <= 0.03f);
  // The shown offset is the solved one, and the wrist moved by exactly it.
  const sdfg::Pose offset = toPose(r.offset.offset);
  CHECK(glm::length(offset.position - toPose(r.offset.solvedOffset).position) < 1e-6f);
  const OpenPalm hand = openPalmInLocal(grip);
  const sdfg::Pose wrist = toPose(r.joints.joints[XR_HAND_JOINT_WRIST_EXT].pose);
  CHECK(glm::length(wrist.position - (hand.wrist * offset).position) < 1e-4f);
  // Every part of the hand is clear of the object (within the exact check's tolerance).
  CHECK(wholeHandClearance(r.joints, distance) > -5e-4f);
  if (other) CHECK(wholeHandClearance(r.joints, otherDistance) > -5e-4f);
  int contacts = 0;
  for (const XrGraspFingerStateSDFG& f : r.state.fingers) contacts += f.inContact ? 1 : 0;
  CHECK(contacts >= 2);
  CHECK(validationLog().empty());

  // Released: the offset blends back out to the controller's own pose, again over frames.
  const uint64_t release = app.framesEnded + 1;
  REQUIRE(app.setScript(gripLine(0, "right", grip) + squeezeLine(0, "right", 1.0f) +
                        squeezeLine(release, "right", 0.0f)) == XR_SUCCESS);
  partial = false;
  app.framesUntil([&] {
    read(app, ext, tracker, r);
    if (r.offset.blend > 0.0f && r.offset.blend < 1.0f) partial = true;
    return app.framesEnded > release && r.offset.blend <= 0.0f;
  });
  CHECK(r.state.isGrasping == XR_FALSE);
  CHECK(r.offset.blend == 0.0f);
  CHECK(partial);
  const sdfg::Pose released = toPose(r.joints.joints[XR_HAND_JOINT_WRIST_EXT].pose);
  CHECK(glm::length(released.position - hand.wrist.position) < 1e-5f);
}

}  // namespace

TEST_CASE("A palm squeezed inside the mug's wall is moved out before the fingers close",
          "[layer][grasp][clearance]") {
  const XrPosef grip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};
  const OpenPalm hand = openPalmInLocal(grip);
  // The mug stands across the fingers (its axis, local Y, along the knuckles) with the side
  // opposite its handle (local -X) toward the palm, and the palm's lowest point 1 cm inside
  // the cup's outer wall (radius 4 cm).
  const glm::vec3 x = hand.down;
  const glm::vec3 y = glm::normalize(hand.across - glm::dot(hand.across, x) * x);
  const glm::quat q = glm::quat_cast(glm::mat3(x, y, glm::cross(x, y)));
  const glm::vec3 c = hand.palm + hand.down * (0.015f + 0.04f - 0.01f);
  const TestMesh mug = toTestMesh(sdfg::makeMug());
  const XrPosef pose{{q.x, q.y, q.z, q.w}, {c.x, c.y, c.z}};
  SECTION("alone") {
    grabFromInside(mug, pose, grip);
  }
  SECTION("a second mug 1 cm from it, beside the palm") {
    // Along the palm's side (the mugs' bodies are 8 cm across): the hand's way out is beside it.
    const glm::vec3 side = glm::cross(x, y);
    const glm::vec3 c2 = c + side * (0.08f + 0.01f);
    const Neighbour second{mug, {{q.x, q.y, q.z, q.w}, {c2.x, c2.y, c2.z}}};
    grabFromInside(mug, pose, grip, &second);
  }
}

TEST_CASE("A palm squeezed through the thin plate is moved out before the fingers close",
          "[layer][grasp][clearance]") {
  const XrPosef grip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};
  const OpenPalm hand = openPalmInLocal(grip);
  // The 4 mm plate (thickness along its Y) under the palm, parallel to it, its mid-plane 4 mm
  // above the palm's lowest point: it passes through the palm and the open fingers.
  const glm::vec3 y = -hand.down;
  const glm::vec3 x = glm::normalize(hand.across - glm::dot(hand.across, y) * y);
  const glm::quat q = glm::quat_cast(glm::mat3(x, y, glm::cross(x, y)));
  const glm::vec3 c = hand.palm + hand.down * (0.015f - 0.004f);
  grabFromInside(toTestMesh(sdfg::makeThinPlate()), {{q.x, q.y, q.z, q.w}, {c.x, c.y, c.z}}, grip);
}

TEST_CASE("A tracked hand squeezed through the thin plate is moved out whole, never curled further",
          "[layer][grasp][clearance]") {
  // The mock runtime's tracked hand is flat and open (the user's curl 0), its wrist at the grip.
  const XrPosef grip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};
  XrEnv env;
  env.extra = {{"SDFG_AUTOGRASP_OUTER_HAND", "false"}};  // the grasp's own clearance
  env.script =
      gripLine(0, "right", grip) + squeezeLine(0, "right", 0.0f) + squeezeLine(6, "right", 1.0f);
  applyEnv(env);
  App app({{XR_EXT_HAND_TRACKING_EXTENSION_NAME, XR_SDFG_AUTO_GRASP_EXTENSION_NAME}});
  REQUIRE(app.ok());
  Ext ext(app);
  XrHandTrackerEXT tracker = makeTracker(app, ext, XR_HAND_RIGHT_EXT);
  app.frames(2);
  Reading before;
  read(app, ext, tracker, before);
  // The plate through the tracked palm, parallel to it, 4 mm above the palm's lowest point.
  const XrHandJointLocationEXT& palm = before.joints.joints[XR_HAND_JOINT_PALM_EXT];
  const sdfg::Pose palmPose = toPose(palm.pose);
  const glm::vec3 down = palmPose.transformVector(glm::vec3(0, -1, 0));
  const glm::vec3 y = -down;
  const glm::vec3 x = glm::normalize(palmPose.transformVector(glm::vec3(1, 0, 0)));
  const glm::quat q = glm::quat_cast(glm::mat3(x, y, glm::cross(x, y)));
  const glm::vec3 c = palmPose.position + down * (palm.radius - 0.004f);
  const TestMesh plate = toTestMesh(sdfg::makeThinPlate());
  const XrPosef pose{{q.x, q.y, q.z, q.w}, {c.x, c.y, c.z}};
  makeTarget(app, ext, plate, pose);
  const ExactDistance exact(plate, pose);
  const auto distance = [&](const XrVector3f& p) { return exact(p); };
  REQUIRE(wholeHandClearance(before.joints, distance) < -0.003f);

  Reading r;
  app.framesUntil([&] {
    read(app, ext, tracker, r);
    return r.state.isGrasping && r.offset.blend >= 1.0f;
  });
  REQUIRE(r.state.isGrasping == XR_TRUE);
  REQUIRE(r.offset.blend == 1.0f);
  CHECK(r.offset.displacement > 0.003f);
  CHECK(wholeHandClearance(r.joints, distance) > -5e-4f);
  // Every joint is the user's own moved by the reported offset in the wrist frame: the open
  // fingers are not curled (the user's curl is 0), only the whole hand moved.
  const sdfg::Pose wrist = toPose(before.joints.joints[XR_HAND_JOINT_WRIST_EXT].pose);
  const sdfg::Pose move = wrist * toPose(r.offset.offset) * wrist.inverse();
  for (int j = 0; j < XR_HAND_JOINT_COUNT_EXT; ++j) {
    CAPTURE(j);
    const glm::vec3 expected = move.transformPoint(toPose(before.joints.joints[j].pose).position);
    CHECK(glm::length(toPose(r.joints.joints[j].pose).position - expected) < 1e-4f);
  }
  CHECK(validationLog().empty());
}
