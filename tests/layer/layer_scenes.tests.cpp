// XR_SDFG_auto_grasp version 3, scenes, through the loader: every target in the grab box takes
// part, roles (graspable, scene geometry, ignored), analytic shapes, which target a grab takes
// (the rule in the header), and what each finger touches.
#include <catch2/catch.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <thread>
#include <utility>

#include "grasp_v2.h"
#include "scene/analytic_shape.h"

namespace {

using namespace sdfg;
using namespace sdfg::test;

const XrPosef kGrip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};

XrGraspTargetSDFG makeShape(const GraspRun& run, XrGraspShapeTypeSDFG type, const XrVector3f& half,
                            const XrPosef& pose, XrGraspTargetRoleSDFG role) {
  return makeShapeTarget(*run.app, *run.ext, type, half, pose, role);
}

void setRole(const GraspRun& run, XrGraspTargetSDFG target, XrGraspTargetRoleSDFG role,
             XrGraspHandFlagsSDFG hands = XR_GRASP_HAND_LEFT_BIT_SDFG |
                                          XR_GRASP_HAND_RIGHT_BIT_SDFG) {
  auto set = run.app->fn<PFN_xrSetGraspTargetSettingsSDFG>("xrSetGraspTargetSettingsSDFG");
  REQUIRE(set != nullptr);
  XrGraspTargetRoleInfoSDFG r{XR_TYPE_GRASP_TARGET_ROLE_SDFG, nullptr, role};
  XrGraspTargetSettingsSDFG s{XR_TYPE_GRASP_TARGET_SETTINGS_SDFG, &r, hands};
  REQUIRE(set(target, &s) == XR_SUCCESS);
}

struct Touches {
  XrGraspStateSDFG state{XR_TYPE_GRASP_STATE_SDFG};
  XrGraspTouchesSDFG touches{XR_TYPE_GRASP_TOUCHES_SDFG};
};

Touches touchesOf(const GraspRun& run) {
  Touches t;
  t.state.next = &t.touches;
  REQUIRE(run.state(t.state) == XR_SUCCESS);
  return t;
}

// Fingers per touched target.
std::map<XrGraspTargetSDFG, int> fingersOn(const XrGraspTouchesSDFG& t) {
  std::map<XrGraspTargetSDFG, int> out;
  for (XrGraspTargetSDFG target : t.touched)
    if (target != XR_NULL_HANDLE) ++out[target];
  return out;
}

// A table top (a box) whose top face is just under the open right hand's palm side, 3 mm clear of
// it, centred under the palm: the pose of its centre, its half extents.
struct Table {
  XrPosef pose;
  XrVector3f half{0.3f, 0.02f, 0.3f};
};

Table tableUnderPalm(const XrPosef& grip) {
  Table t;
  t.pose = boxUnderPalm(grip, t.half);
  return t;
}

// `p` moved by `d` along the open right palm's normal (away from the palm).
XrPosef awayFromPalm(const XrPosef& grip, XrPosef p, float d) {
  const glm::vec3 down = openRightHand(grip).down;
  p.position = {p.position.x + down.x * d, p.position.y + down.y * d, p.position.z + down.z * d};
  return p;
}

}  // namespace

TEST_CASE("A squeeze with only scene geometry in reach closes on it and holds nothing",
          "[layer][scenes]") {
  const TestMesh far = makeIcosphere(0.02f, 2);
  GraspRun run(far, {{0, 0, 0, 1}, {5.0f, 0.0f, 0.0f}}, kGrip);  // the run's target out of reach
  const Table table = tableUnderPalm(kGrip);
  const XrGraspTargetSDFG top = makeShape(run, XR_GRASP_SHAPE_TYPE_BOX_SDFG, table.half, table.pose,
                                          XR_GRASP_TARGET_ROLE_SCENE_SDFG);
  REQUIRE(runUntil(*run.app, [&] { return touchesOf(run).touches.isClosed == XR_TRUE; }));
  const Touches t = touchesOf(run);
  CHECK_FALSE(t.state.isGrasping);
  CHECK(t.state.target == XR_NULL_HANDLE);
  // The fingers that touch anything touch the table.
  const auto on = fingersOn(t.touches);
  REQUIRE_FALSE(on.empty());
  CHECK(on.count(top) == 1);
  CHECK(on.size() == 1);
  Joints joints;
  REQUIRE(locateJoints(*run.app, run.tracker, joints) == XR_SUCCESS);
  CHECK(depthInBox(joints, {ShapeKind::box, {table.half.x, table.half.y, table.half.z}},
                   table.pose) <= 0.001f);
  CHECK(validationLog().empty());
}

TEST_CASE("A plane registered without a role is scene geometry: a squeeze on a floor takes nothing",
          "[layer][scenes]") {
  const TestMesh far = makeIcosphere(0.02f, 2);
  GraspRun run(far, {{0, 0, 0, 1}, {5.0f, 0.0f, 0.0f}}, kGrip);
  // The floor's surface where tableUnderPalm() puts the table's top: 3 mm under the open hand.
  const Table table = tableUnderPalm(kGrip);
  const XrPosef floorPose = awayFromPalm(kGrip, table.pose, -table.half.y);
  const bool graspable = GENERATE(false, true);
  CAPTURE(graspable);
  XrGraspTargetShapeSDFG plane{
      XR_TYPE_GRASP_TARGET_SHAPE_SDFG, nullptr, XR_GRASP_SHAPE_TYPE_PLANE_SDFG, {0, 0, 0}};
  // An app may still make a plane graspable by saying so.
  XrGraspTargetRoleInfoSDFG role{XR_TYPE_GRASP_TARGET_ROLE_SDFG, &plane,
                                 XR_GRASP_TARGET_ROLE_GRASPABLE_SDFG};
  XrGraspTargetCreateInfoSDFG ci{XR_TYPE_GRASP_TARGET_CREATE_INFO_SDFG,
                                 graspable ? static_cast<const void*>(&role) : &plane};
  ci.placement = {XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG, nullptr, run.app->local, floorPose};
  XrGraspTargetSDFG floor = XR_NULL_HANDLE;
  REQUIRE(run.ext->create(run.app->session, &ci, &floor) == XR_SUCCESS);
  REQUIRE(runUntil(*run.app, [&] { return touchesOf(run).touches.isClosed == XR_TRUE; }));
  const Touches t = touchesOf(run);
  CHECK(fingersOn(t.touches).count(floor) == 1);
  if (graspable) {
    CHECK(t.state.isGrasping);
    CHECK(t.state.target == floor);
  } else {
    CHECK_FALSE(t.state.isGrasping);
    CHECK(t.state.target == XR_NULL_HANDLE);
    for (const XrGraspFingerStateSDFG& f : t.state.fingers) CHECK_FALSE(f.inContact);
  }
  CHECK(validationLog().empty());
}

TEST_CASE("A flat object on a table: the grab takes the object, no hand part enters the table",
          "[layer][scenes]") {
  // A flat bar (a comb's size: 12 x 0.8 x 3 cm) lying on the table under the palm.
  const TestMesh bar = toTestMesh(makeBox(glm::vec3(0.12f, 0.008f, 0.03f)));
  const XrPosef barPose = belowOpenRightPalm(bar, kGrip, facingPalm(kGrip));
  const bool tableGraspable = GENERATE(false, true);
  CAPTURE(tableGraspable);
  GraspRun run(bar, barPose, kGrip);
  // The table's top just under the bar (the bar rests on it).
  Table table;
  table.pose = awayFromPalm(kGrip, barPose, 0.004f + table.half.y);
  const XrGraspTargetSDFG top = makeShape(
      run, XR_GRASP_SHAPE_TYPE_BOX_SDFG, table.half, table.pose,
      tableGraspable ? XR_GRASP_TARGET_ROLE_GRASPABLE_SDFG : XR_GRASP_TARGET_ROLE_SCENE_SDFG);
  REQUIRE(untilSetUp(*run.app, *run.ext, [](const auto& s) { return s.readyCount >= 2; }));
  REQUIRE(runUntil(*run.app, [&] { return touchesOf(run).touches.isClosed == XR_TRUE; }));
  const Touches t = touchesOf(run);
  const auto on = fingersOn(t.touches);
  if (!tableGraspable) {
    // Scene geometry is never taken: the bar, under the palm (the fingers may close past it
    // onto the table; the palm touching it counts).
    CHECK(t.state.isGrasping);
    CHECK(t.state.target == run.target);
  } else {
    // The documented rule: the graspable target the palm faces, though the fingers closed past
    // it onto the (graspable) table.
    REQUIRE(t.state.isGrasping);
    CHECK(t.state.target == run.target);
    CHECK(on.count(top) == 1);
  }
  // Version 1 fields: a finger that closed past the bar onto the table is not in contact (its
  // point and distance would be the table's), one on the bar has the bar's exact distance.
  const AnalyticShape barShape{ShapeKind::box, {0.06f, 0.004f, 0.015f}};
  for (int f = 0; f < 5; ++f) {
    const XrGraspFingerStateSDFG& v1 = t.state.fingers[f];
    if (t.touches.touched[f] != run.target) CHECK_FALSE(v1.inContact);
    if (!v1.inContact) continue;
    const glm::vec3 c(v1.contactPoint.x, v1.contactPoint.y, v1.contactPoint.z);
    CHECK(std::abs(barShape.signedDistance(c) - v1.distance) <= 0.0002f);
  }
  Joints joints;
  REQUIRE(locateJoints(*run.app, run.tracker, joints) == XR_SUCCESS);
  CHECK(depthInBox(joints, {ShapeKind::box, {table.half.x, table.half.y, table.half.z}},
                   table.pose) <= 0.001f);
  CHECK(validationLog().empty());
}

TEST_CASE("A target behind scene geometry is never taken: the fingers stop on what is in front",
          "[layer][scenes]") {
  // A graspable sphere in the box, and a wall (scene) between the palm and it: the wall's near
  // face 3 mm under the palm, the sphere beyond it.
  const Table wall = tableUnderPalm(kGrip);
  const OpenRightHand hand = openRightHand(kGrip);
  const glm::vec3 behind = hand.palm + hand.down * (2.0f * wall.half.y + 0.06f);
  const TestMesh ball = makeIcosphere(0.025f, 3);
  GraspRun run(ball, {{0, 0, 0, 1}, {behind.x, behind.y, behind.z}}, kGrip);
  const XrGraspTargetSDFG w = makeShape(run, XR_GRASP_SHAPE_TYPE_BOX_SDFG, wall.half, wall.pose,
                                        XR_GRASP_TARGET_ROLE_SCENE_SDFG);
  REQUIRE(untilSetUp(*run.app, *run.ext, [](const auto& s) { return s.readyCount >= 2; }));
  REQUIRE(runUntil(*run.app, [&] { return touchesOf(run).touches.isClosed == XR_TRUE; }));
  const Touches t = touchesOf(run);
  CHECK_FALSE(t.state.isGrasping);
  const auto on = fingersOn(t.touches);
  CHECK(on.count(run.target) == 0);
  CHECK(on.count(w) == 1);
  CHECK(validationLog().empty());
}

TEST_CASE("Two touching objects: the grab takes the one most fingers touch, the other stops them",
          "[layer][scenes]") {
  // Two balls side by side across the fingers, touching each other, under the palm.
  const TestMesh ball = makeIcosphere(0.025f, 3);
  const OpenRightHand hand = openRightHand(kGrip);
  const XrPosef first = belowOpenRightPalm(ball, kGrip, {0, 0, 0, 1}, hand.across * -0.0125f);
  XrPosef second = first;
  second.position.x += hand.across.x * 0.05f;
  second.position.y += hand.across.y * 0.05f;
  second.position.z += hand.across.z * 0.05f;
  GraspRun run(ball, first, kGrip);
  const XrGraspTargetSDFG other = makeTarget(*run.app, *run.ext, ball, second);
  REQUIRE(untilSetUp(*run.app, *run.ext, [](const auto& s) { return s.readyCount >= 2; }));
  REQUIRE(runUntil(*run.app, [&] { return run.grasping(); }));
  const Touches t = touchesOf(run);
  const auto on = fingersOn(t.touches);
  const int onTaken = on.count(t.state.target) ? on.at(t.state.target) : 0;
  CHECK(onTaken >= 1);
  for (const auto& [target, fingers] : on) CHECK(onTaken >= fingers);
  CHECK((t.state.target == run.target || t.state.target == other));
  // No part of either ball is inside a finger's joint sphere.
  Joints joints;
  REQUIRE(locateJoints(*run.app, run.tracker, joints) == XR_SUCCESS);
  for (const XrPosef& centre : {first, second}) {
    for (const XrHandJointLocationEXT& j : joints.joints) {
      const float d = length(sub(j.pose.position, centre.position)) - 0.025f;
      CHECK(d - j.radius >= -0.001f);
    }
  }
  CHECK(validationLog().empty());
}

TEST_CASE("An ignored target is passed through, and roles change from the next sync",
          "[layer][scenes]") {
  // An ignored plate under the open hand, a table 2 cm under the plate. The fingers closing on the
  // table show that the layer solved this squeeze (however long the machine took), so what the
  // plate did not do is checked on a solve that ran: a plate that took part would stop the fingers
  // on its top (scene geometry) or be taken (graspable).
  const glm::vec3 size(0.2f, 0.01f, 0.2f);
  const TestMesh plate = toTestMesh(makeBox(size));
  const XrPosef platePose = belowOpenRightPalm(plate, kGrip, facingPalm(kGrip));
  GraspRun run(plate, platePose, kGrip);
  setRole(run, run.target, XR_GRASP_TARGET_ROLE_IGNORED_SDFG);
  Table table;
  table.pose = awayFromPalm(kGrip, platePose, size.y / 2 + 0.02f + table.half.y);
  const XrGraspTargetSDFG top = makeShape(run, XR_GRASP_SHAPE_TYPE_BOX_SDFG, table.half, table.pose,
                                          XR_GRASP_TARGET_ROLE_SCENE_SDFG);
  REQUIRE(untilSetUp(*run.app, *run.ext, [](const auto& s) { return s.readyCount >= 2; }));
  REQUIRE(runUntil(*run.app, [&] { return touchesOf(run).touches.isClosed == XR_TRUE; }));
  const Touches t = touchesOf(run);
  CHECK_FALSE(t.state.isGrasping);
  const auto on = fingersOn(t.touches);
  CHECK(on.count(run.target) == 0);
  CHECK(on.count(top) == 1);
  // Passed through: fingers went on into the plate (10 mm thick) on their way to the table.
  Joints joints;
  REQUIRE(locateJoints(*run.app, run.tracker, joints) == XR_SUCCESS);
  CHECK(depthInBox(joints, {ShapeKind::box, size / 2.0f}, platePose) > 0.005f);
  setRole(run, run.target, XR_GRASP_TARGET_ROLE_GRASPABLE_SDFG);
  REQUIRE(runUntil(*run.app, [&] { return run.grasping(); }));
  // Scene geometry from now: the hand lets go, and holds nothing while it rests on it.
  setRole(run, run.target, XR_GRASP_TARGET_ROLE_SCENE_SDFG);
  REQUIRE(runUntil(*run.app, [&] { return !run.grasping(); }));
  CHECK(validationLog().empty());
}

TEST_CASE("Bad roles and shapes are refused and change nothing", "[layer][scenes][bad_input]") {
  const TestMesh ball = makeIcosphere(0.03f, 2);
  GraspRun run(ball, {{0, 0, 0, 1}, {5.0f, 0.0f, 0.0f}}, kGrip);
  const XrPosef somewhere{{0, 0, 0, 1}, {0, -1, -1}};
  auto tryShape = [&](int32_t type, XrVector3f half, int32_t role) {
    XrGraspTargetShapeSDFG shape{XR_TYPE_GRASP_TARGET_SHAPE_SDFG, nullptr,
                                 XrGraspShapeTypeSDFG(type), half};
    XrGraspTargetRoleInfoSDFG r{XR_TYPE_GRASP_TARGET_ROLE_SDFG, &shape,
                                XrGraspTargetRoleSDFG(role)};
    XrGraspTargetCreateInfoSDFG ci{XR_TYPE_GRASP_TARGET_CREATE_INFO_SDFG, &r};
    ci.placement = {XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG, nullptr, run.app->local, somewhere};
    XrGraspTargetSDFG t = reinterpret_cast<XrGraspTargetSDFG>(uintptr_t(77));
    const XrResult result = run.ext->create(run.app->session, &ci, &t);
    // Nothing written on failure.
    if (result != XR_SUCCESS) CHECK(t == reinterpret_cast<XrGraspTargetSDFG>(uintptr_t(77)));
    return result;
  };
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  CHECK(tryShape(XR_GRASP_SHAPE_TYPE_BOX_SDFG, {0.1f, 0.1f, 0.1f}, 3) ==
        XR_ERROR_VALIDATION_FAILURE);
  CHECK(tryShape(XR_GRASP_SHAPE_TYPE_BOX_SDFG, {0.1f, 0.1f, 0.1f}, -1) ==
        XR_ERROR_VALIDATION_FAILURE);
  CHECK(tryShape(XR_GRASP_SHAPE_TYPE_BOX_SDFG, {nan, 0.1f, 0.1f}, 0) ==
        XR_ERROR_VALIDATION_FAILURE);
  CHECK(tryShape(XR_GRASP_SHAPE_TYPE_BOX_SDFG, {0.1f, -0.1f, 0.1f}, 0) ==
        XR_ERROR_VALIDATION_FAILURE);
  CHECK(tryShape(XR_GRASP_SHAPE_TYPE_BOX_SDFG, {0.1f, 0.1f, inf}, 0) ==
        XR_ERROR_VALIDATION_FAILURE);
  CHECK(tryShape(XR_GRASP_SHAPE_TYPE_BOX_SDFG, {0.0f, 0.1f, 0.1f}, 0) ==
        XR_ERROR_VALIDATION_FAILURE);
  CHECK(tryShape(XR_GRASP_SHAPE_TYPE_PLANE_SDFG, {0.1f, 0.0f, 0.0f}, 0) ==
        XR_ERROR_VALIDATION_FAILURE);
  CHECK(tryShape(7, {0.1f, 0.1f, 0.1f}, 0) == XR_ERROR_VALIDATION_FAILURE);
  // A shape and vertices together: not exactly one mesh struct.
  {
    XrGraspTargetVerticesSDFG v{XR_TYPE_GRASP_TARGET_VERTICES_SDFG};
    v.vertexCount = uint32_t(ball.vertices.size());
    v.vertices = ball.vertices.data();
    v.indexCount = uint32_t(ball.indices.size());
    v.indices = ball.indices.data();
    XrGraspTargetShapeSDFG shape{
        XR_TYPE_GRASP_TARGET_SHAPE_SDFG, &v, XR_GRASP_SHAPE_TYPE_BOX_SDFG, {0.1f, 0.1f, 0.1f}};
    XrGraspTargetCreateInfoSDFG ci{XR_TYPE_GRASP_TARGET_CREATE_INFO_SDFG, &shape};
    ci.placement = {XR_TYPE_GRASP_TARGET_PLACEMENT_SDFG, nullptr, run.app->local, somewhere};
    XrGraspTargetSDFG t = XR_NULL_HANDLE;
    CHECK(run.ext->create(run.app->session, &ci, &t) == XR_ERROR_VALIDATION_FAILURE);
  }
  // A good shape, then the calls a shape refuses.
  REQUIRE(tryShape(XR_GRASP_SHAPE_TYPE_PLANE_SDFG, {0, 0, 0}, 1) == XR_SUCCESS);
  const XrGraspTargetSDFG box = makeShape(run, XR_GRASP_SHAPE_TYPE_BOX_SDFG, {0.1f, 0.1f, 0.1f},
                                          somewhere, XR_GRASP_TARGET_ROLE_GRASPABLE_SDFG);
  XrGraspTargetVerticesSDFG moved{XR_TYPE_GRASP_TARGET_VERTICES_SDFG};
  moved.vertexCount = uint32_t(ball.vertices.size());
  moved.vertices = ball.vertices.data();
  CHECK(run.ext->update(box, &moved) == XR_ERROR_VALIDATION_FAILURE);
  auto set = run.app->fn<PFN_xrSetGraspTargetSettingsSDFG>("xrSetGraspTargetSettingsSDFG");
  XrGraspTargetRoleInfoSDFG badRole{XR_TYPE_GRASP_TARGET_ROLE_SDFG, nullptr,
                                    XrGraspTargetRoleSDFG(9)};
  XrGraspTargetSettingsSDFG s{XR_TYPE_GRASP_TARGET_SETTINGS_SDFG, &badRole,
                              XR_GRASP_HAND_RIGHT_BIT_SDFG};
  CHECK(set(box, &s) == XR_ERROR_VALIDATION_FAILURE);
  CHECK(validationLog().empty());
}

TEST_CASE(
    "A box held where it lies on a table: no finger enters it, its contacts are the shown ones",
    "[layer][scenes]") {
  // The box 6 x 3 x 10 cm lying on a table top (scene geometry), under the open palm, turned and
  // shifted so that the thumb or the little finger closes beside it onto the table; the outer
  // hand on (the default). Before the held object's fingers moved with the hand as solved, the
  // outer hand re-curled them on the table and put them 5-7 mm into the box.
  const glm::vec3 size(0.06f, 0.03f, 0.10f);
  const AnalyticShape boxShape{ShapeKind::box, size * 0.5f};
  const auto [angle, across] = GENERATE(std::pair{0.0f, -0.03f}, std::pair{1.6f, 0.0f});
  CAPTURE(angle, across);
  const OpenRightHand hand = openRightHand(kGrip);
  const XrQuaternionf flat = facingPalm(kGrip);
  const glm::quat q = glm::quat(flat.w, flat.x, flat.y, flat.z) *
                      glm::angleAxis(angle, glm::vec3(0.0f, 1.0f, 0.0f));
  glm::vec3 toKnuckles = hand.knuckles - hand.palm;
  toKnuckles -= glm::dot(toKnuckles, hand.down) * hand.down;
  const TestMesh box = toTestMesh(makeBox(size));
  const XrPosef boxPose = belowOpenRightPalm(
      box, kGrip, {q.x, q.y, q.z, q.w}, hand.across * across + glm::normalize(toKnuckles) * 0.02f);
  Table table;
  table.pose = awayFromPalm(kGrip, boxPose, size.y * 0.5f + table.half.y);
  table.pose.orientation = flat;
  const AnalyticShape tableShape{ShapeKind::box, {table.half.x, table.half.y, table.half.z}};
  GraspRun run(box, boxPose, kGrip);
  const XrGraspTargetSDFG top = makeShape(run, XR_GRASP_SHAPE_TYPE_BOX_SDFG, table.half, table.pose,
                                          XR_GRASP_TARGET_ROLE_SCENE_SDFG);
  REQUIRE(untilSetUp(*run.app, *run.ext, [](const auto& s) { return s.readyCount >= 2; }));
  REQUIRE(runUntil(*run.app, [&] { return run.grasping(); }));
  // Half a second at 90 Hz, the hand located as an app does, between its sync and frame end.
  const Pose localFromBox = toPose(boxPose);
  float deepestInBox = -1.0f, deepestInTable = -1.0f, contactOff = 0.0f, v1Off = 0.0f;
  int compared = 0, onTable = 0;
  auto next = std::chrono::steady_clock::now();
  for (int frame = 0; frame < 45; ++frame) {
    next += std::chrono::microseconds(11111);
    std::this_thread::sleep_until(next);
    Joints joints;
    XrGraspHandOffsetSDFG offset{XR_TYPE_GRASP_HAND_OFFSET_SDFG};
    XrGraspContactsSDFG contacts{XR_TYPE_GRASP_CONTACTS_SDFG, &offset};
    XrGraspTouchesSDFG touches{XR_TYPE_GRASP_TOUCHES_SDFG, &contacts};
    XrGraspStateSDFG state{XR_TYPE_GRASP_STATE_SDFG, &touches};
    XrResult located = XR_ERROR_RUNTIME_FAILURE, got = XR_ERROR_RUNTIME_FAILURE;
    run.app->frame([&] {
      located = locateJoints(*run.app, run.tracker, joints);
      got = run.state(state);
    });
    REQUIRE(located == XR_SUCCESS);
    REQUIRE(got == XR_SUCCESS);
    REQUIRE(state.isGrasping);
    REQUIRE(state.target == run.target);
    deepestInBox = std::max(deepestInBox, depthInBox(joints, boxShape, boxPose));
    deepestInTable = std::max(deepestInTable, depthInBox(joints, tableShape, table.pose));
    for (int f = 0; f < 5; ++f) {
      const XrGraspFingerStateSDFG& v1 = state.fingers[f];
      if (touches.touched[f] == top) {
        ++onTable;
        // A finger on the table is no contact on the box (version 1 and 2 alike).
        CHECK_FALSE(v1.inContact);
        CHECK(contacts.fingers[f].part == XR_GRASP_CONTACT_PART_NONE_SDFG);
      }
      if (!v1.inContact) continue;
      const glm::vec3 c(v1.contactPoint.x, v1.contactPoint.y, v1.contactPoint.z);
      v1Off = std::max(v1Off, std::abs(boxShape.signedDistance(c) - v1.distance));
      // Once the grab's blend is over, the contact sphere is where the shown joints put it.
      const XrGraspFingerContactSDFG& k = contacts.fingers[f];
      if (offset.blend < 1.0f || k.part == XR_GRASP_CONTACT_PART_NONE_SDFG) continue;
      const XrVector3f& a = joints.joints[k.joint].pose.position;
      const XrVector3f& b = joints.joints[std::min(int(k.joint) + 1, 25)].pose.position;
      const float t = k.part == XR_GRASP_CONTACT_PART_BONE_CAPSULE_SDFG ? k.boneFraction : 0.0f;
      const glm::vec3 shown = localFromBox.inverse().transformPoint(
          glm::mix(glm::vec3(a.x, a.y, a.z), glm::vec3(b.x, b.y, b.z), t));
      contactOff = std::max(
          contactOff,
          glm::length(shown - glm::vec3(k.sphereCenter.x, k.sphereCenter.y, k.sphereCenter.z)));
      ++compared;
    }
  }
  INFO("fingers on the table over the frames: " << onTable);
  CHECK(deepestInBox <= 0.0005f);
  CHECK(deepestInTable <= 0.001f);
  CHECK(compared > 0);
  CHECK(contactOff <= 0.001f);
  CHECK(v1Off <= 0.0002f);
  CHECK(validationLog().empty());
}
