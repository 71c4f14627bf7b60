// The outer hand (grasp/outer_hand.h) on analytic scenes with known answers: a table top, a thin
// plate, a box beside the hand.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "grasp/outer_hand.h"
#include "grasp/scene_exact_source.h"
#include "scene/analytic_shape.h"

using namespace sdfg;

namespace {

constexpr double kFrame = 1.0 / 90.0;

struct TestHand {
  HandModel model = HandModel::defaultAdult(sdfg::Hand::right);
  JointPoses joints{};
  std::array<float, kJointCount> radii{};
  explicit TestHand(float curl = 0.0f) { setCurl(curl); }
  void setCurl(float curl) {
    FingerCurls c;
    c.fill(curl);
    model.pose(c, joints);
    for (int j = 0; j < kJointCount; ++j) radii[size_t(j)] = model.jointRadius(Joint(j));
  }
  // The lowest point of the hand's surface, wrist frame y (the palm faces -Y when the wrist's
  // orientation is the identity).
  float lowest() const {
    HandParts parts;
    const int n = jointParts(joints, radii, parts);
    float y = std::numeric_limits<float>::infinity();
    for (int i = 0; i < n; ++i)
      y = std::min(y, parts[size_t(i)].centre.y - parts[size_t(i)].radius);
    return y;
  }
};

Pose at(const glm::vec3& p) {
  return Pose{glm::quat(1, 0, 0, 0), p};
}

// The smallest clearance of the hand as shown (capped fingers at the model's curl), world frame.
float shownClearance(const TestHand& h, const OuterHandResult& r, const AnalyticShape& shape,
                     const Pose& worldFromShape) {
  JointPoses shown = h.joints;
  for (int f = 0; f < kFingerCount; ++f) {
    if (!r.capped[size_t(f)]) continue;
    const std::span<const Joint> fj = fingerJoints(Finger(f));
    std::array<Pose, 5> poses{};
    h.model.fingerPose(Finger(f), r.curl[size_t(f)], std::span(poses.data(), fj.size()));
    for (size_t k = 0; k < fj.size(); ++k) shown[size_t(fj[k])] = poses[k];
  }
  HandParts parts;
  const int n = jointParts(shown, h.radii, parts);
  float lowest = std::numeric_limits<float>::infinity();
  const Pose shapeFromWorld = worldFromShape.inverse();
  for (int i = 0; i < n; ++i) {
    const glm::vec3 p = shapeFromWorld.transformPoint(
        r.worldFromShownWrist.transformPoint(parts[size_t(i)].centre));
    lowest = std::min(lowest, shape.signedDistance(p) - parts[size_t(i)].radius);
  }
  return lowest;
}

// One update a frame (90 Hz) of `outer` for the still-shaped hand `h` with its wrist at `wrist`.
struct Stepper {
  OuterHand& outer;
  const TestHand& h;
  const SceneExactSource& scene;
  double t = 0.0;
  OuterHandResult operator()(const glm::vec3& wrist) {
    OuterHandInput in;
    in.worldFromWrist = at(wrist);
    in.joints = &h.joints;
    in.radii = &h.radii;
    in.time = (t += kFrame);
    const auto r = outer.update(in, &scene);
    REQUIRE(r.ok());
    return *r;
  }
};

// One frame of a still hand at `wrist` with `shape` moved to `worldFromShape` (as the worker says
// when a member's pose changed: sceneMoved).
OuterHandResult stillHandStep(OuterHand& outer, const TestHand& h, const glm::vec3& wrist,
                              int frame, const AnalyticShape& shape, const Pose& worldFromShape) {
  const std::vector<SceneMember> members{{1, nullptr, &shape, worldFromShape.inverse()}};
  const SceneExactSource scene(members);
  OuterHandInput in;
  in.worldFromWrist = at(wrist);
  in.joints = &h.joints;
  in.radii = &h.radii;
  in.time = frame * kFrame;
  in.sceneMoved = true;
  const auto result = outer.update(in, &scene);
  REQUIRE(result.ok());
  return *result;
}

}  // namespace

TEST_CASE("The outer hand is the tracked hand while nothing is near", "[core][outer_hand]") {
  TestHand h;
  const AnalyticShape table{ShapeKind::box, glm::vec3(0.5f, 0.02f, 0.5f)};
  const std::vector<SceneMember> members{{1, nullptr, &table, at(glm::vec3(0.0f, 0.02f, 0.0f))}};
  const SceneExactSource scene(members);
  OuterHand outer(h.model);
  for (int frame = 0; frame < 30; ++frame) {
    OuterHandInput in;
    in.worldFromWrist = at(glm::vec3(0.01f * float(frame), 0.3f, 0.0f));
    in.joints = &h.joints;
    in.radii = &h.radii;
    in.time = frame * kFrame;
    const auto r = outer.update(in, &scene);
    REQUIRE(r.ok());
    CHECK_FALSE(r->constrained);
    CHECK(r->worldFromShownWrist.position == in.worldFromWrist.position);
    CHECK(r->worldFromShownWrist.orientation == in.worldFromWrist.orientation);
    CHECK(r->offset.position == glm::vec3(0.0f));
  }
}

TEST_CASE("A hand pushed into a table stops on it, slides along it and comes back out",
          "[core][outer_hand]") {
  TestHand h;
  const AnalyticShape table{ShapeKind::box, glm::vec3(0.5f, 0.02f, 0.5f)};
  const Pose worldFromTable = at(glm::vec3(0.0f, -0.02f, 0.0f));  // its top at y = 0
  const std::vector<SceneMember> members{{1, nullptr, &table, worldFromTable.inverse()}};
  const SceneExactSource scene(members);
  OuterHand outer(h.model);
  const float touchHeight = -h.lowest();  // wrist height at which the hand just touches y = 0
  float deepest = 0.0f, worstJitter = 0.0f;
  Pose last;
  Stepper next{outer, h, scene};
  auto step = [&](const glm::vec3& wrist) {
    const OuterHandResult r = next(wrist);
    deepest = std::min(deepest, shownClearance(h, r, table, worldFromTable));
    return r;
  };
  // Down from 5 cm above the touch to 4 cm below it, 1 cm per frame (0.9 m/s).
  OuterHandResult r;
  for (int k = 0; k <= 9; ++k) r = step(glm::vec3(0.0f, touchHeight + 0.05f - 0.01f * k, 0.0f));
  CHECK(r.constrained);
  CHECK(r.touching);
  CHECK(r.worldFromShownWrist.position.y == Approx(touchHeight).margin(0.002f));
  // Held still inside for 60 frames: no jitter.
  last = r.worldFromShownWrist;
  for (int k = 0; k < 60; ++k) {
    r = step(glm::vec3(0.0f, touchHeight - 0.04f, 0.0f));
    worstJitter =
        std::max(worstJitter, glm::length(r.worldFromShownWrist.position - last.position));
    last = r.worldFromShownWrist;
  }
  CHECK(worstJitter <= 0.0001f);
  // Slides 5 cm along x while 4 cm inside: the shown hand follows along the surface.
  for (int k = 1; k <= 10; ++k) r = step(glm::vec3(0.005f * k, touchHeight - 0.04f, 0.0f));
  CHECK(r.worldFromShownWrist.position.x == Approx(0.05f).margin(0.003f));
  CHECK(r.worldFromShownWrist.position.y == Approx(touchHeight).margin(0.002f));
  CHECK(deepest >= -0.001f);
  // Out again: the tracked hand, exactly.
  for (int k = 0; k <= 10; ++k) r = step(glm::vec3(0.05f, touchHeight - 0.04f + 0.01f * k, 0.0f));
  CHECK_FALSE(r.constrained);
  CHECK(r.worldFromShownWrist.position == glm::vec3(0.05f, touchHeight - 0.04f + 0.1f, 0.0f));
}

TEST_CASE("A hand swiped at 2 m/s through a 3 mm plate stays on its side", "[core][outer_hand]") {
  TestHand h;
  // A vertical plate 3 mm thick in x, the hand moving along +x (palm down, the side of the hand
  // leading).
  const AnalyticShape plate{ShapeKind::box, glm::vec3(0.0015f, 0.3f, 0.3f)};
  const Pose worldFromPlate = at(glm::vec3(0.0f));
  const std::vector<SceneMember> members{{1, nullptr, &plate, worldFromPlate.inverse()}};
  const SceneExactSource scene(members);
  OuterHandOptions o;
  o.releaseDistance = 1.0f;  // this test is about not passing, not about the release
  OuterHand outer(h.model, o);
  float deepest = 0.0f, farthestX = -1.0f;
  for (int k = 0; k < 30; ++k) {
    OuterHandInput in;
    // 2 m/s: 22 mm per frame, from 20 cm before the plate to 45 cm past it.
    in.worldFromWrist = at(glm::vec3(-0.2f + 0.0222f * k, 0.0f, 0.0f));
    in.joints = &h.joints;
    in.radii = &h.radii;
    in.time = k * kFrame;
    const auto r = outer.update(in, &scene);
    REQUIRE(r.ok());
    deepest = std::min(deepest, shownClearance(h, *r, plate, worldFromPlate));
    farthestX = std::max(farthestX, r->worldFromShownWrist.position.x);
  }
  CHECK(deepest >= -0.001f);
  // The wrist never reaches the plate's far side: the hand stays before it.
  CHECK(farthestX < 0.0f);
}

TEST_CASE("A finger pressed onto a surface stops on it", "[core][outer_hand]") {
  TestHand open;
  const AnalyticShape table{ShapeKind::box, glm::vec3(0.5f, 0.02f, 0.5f)};
  const float touch = -open.lowest();
  // The open hand 1 cm above the touch; the table's top at y = 0.
  const Pose worldFromTable = at(glm::vec3(0.0f, -0.02f, 0.0f));
  const std::vector<SceneMember> members{{1, nullptr, &table, worldFromTable.inverse()}};
  const SceneExactSource scene(members);
  OuterHand outer(open.model);
  OuterHandResult r;
  for (int k = 0; k <= 20; ++k) {
    TestHand h(0.05f * k);  // curling to fully closed over 20 frames
    OuterHandInput in;
    in.worldFromWrist = at(glm::vec3(0.0f, touch + 0.01f, 0.0f));
    in.joints = &h.joints;
    in.radii = &h.radii;
    in.time = k * kFrame;
    const auto got = outer.update(in, &scene);
    REQUIRE(got.ok());
    r = *got;
    CHECK(shownClearance(h, r, table, worldFromTable) >= -0.001f);
  }
  // The hand does not move up: its fingers stop on the table instead.
  CHECK(r.worldFromShownWrist.position.y == Approx(touch + 0.01f).margin(1e-5f));
  int stopped = 0;
  for (int f = 1; f < kFingerCount; ++f)
    stopped += r.capped[size_t(f)] && r.curl[size_t(f)] < 0.99f;
  CHECK(stopped >= 3);
}

TEST_CASE("Past the release distance the shown hand returns to tracking, blended",
          "[core][outer_hand]") {
  TestHand h;
  const AnalyticShape table{ShapeKind::box, glm::vec3(0.5f, 0.1f, 0.5f)};
  const Pose worldFromTable = at(glm::vec3(0.0f, -0.1f, 0.0f));
  const std::vector<SceneMember> members{{1, nullptr, &table, worldFromTable.inverse()}};
  const SceneExactSource scene(members);
  OuterHand outer(h.model);
  const float touch = -h.lowest();
  bool blended = false, released = false;
  OuterHandResult r;
  double t = 0.0;
  for (int k = 0; k < 60; ++k) {
    OuterHandInput in;
    // Down 1 cm per frame, to 15 cm below the touch.
    in.worldFromWrist = at(glm::vec3(0.0f, touch + 0.02f - 0.01f * std::min(k, 17), 0.0f));
    in.joints = &h.joints;
    in.radii = &h.radii;
    in.time = (t += kFrame);
    r = *outer.update(in, &scene);
    blended = blended || r.blending;
    released = released || r.released;
  }
  CHECK(blended);
  CHECK(released);
  // Following the tracked hand inside, until it comes out.
  CHECK(r.worldFromShownWrist.position.y == Approx(touch - 0.15f).margin(1e-5f));
  for (int k = 0; k < 30; ++k) {
    OuterHandInput in;
    in.worldFromWrist = at(glm::vec3(0.0f, touch - 0.15f + 0.01f * k, 0.0f));
    in.joints = &h.joints;
    in.radii = &h.radii;
    in.time = (t += kFrame);
    r = *outer.update(in, &scene);
  }
  CHECK_FALSE(r.released);
  CHECK_FALSE(r.constrained);
}

TEST_CASE("A curled hand swiped at 2 m/s into a 3 mm plate stays on its side",
          "[core][outer_hand]") {
  // A vertical plate (its faces at x = +-1.5 mm, its top edge at y = 0), the hand's palm 1 cm below
  // that edge, fingers curled: they meet the face first.
  const AnalyticShape plate{ShapeKind::box, glm::vec3(0.0015f, 0.15f, 0.15f)};
  const Pose worldFromPlate = at(glm::vec3(0.0f, -0.15f, 0.0f));
  const std::vector<SceneMember> members{{1, nullptr, &plate, worldFromPlate.inverse()}};
  const SceneExactSource scene(members);
  for (const float curl : {0.3f, 0.6f, 0.9f}) {
    CAPTURE(curl);
    TestHand h(curl);
    OuterHandOptions o;
    o.releaseDistance = 1.0f;  // about not passing, not about the release
    OuterHand outer(h.model, o);
    const float palmY = h.joints[size_t(Joint::palm)].position.y;
    float deepest = 0.0f, farthest = -1.0f;
    for (int k = 0; k < 30; ++k) {
      OuterHandInput in;
      in.worldFromWrist = at(glm::vec3(-0.25f + 0.0222f * k, -0.01f - palmY, 0.09f));
      in.joints = &h.joints;
      in.radii = &h.radii;
      in.time = k * kFrame;
      const auto r = outer.update(in, &scene);
      REQUIRE(r.ok());
      const float c = shownClearance(h, *r, plate, worldFromPlate);
      deepest = std::min(deepest, c);
      farthest = std::max(farthest, r->worldFromShownWrist.position.x);
    }
    CHECK(deepest >= -0.001f);
    CHECK(farthest < 0.0f);
  }
}

TEST_CASE("A target that moves into a still hand pushes the shown hand out of its way",
          "[core][outer_hand]") {
  // The world moves, not the hand: a table top rising into it (locomotion down a slope, a lift),
  // and a box brought to it sideways (an object handed over), at 0.3, 1 and 2 m/s (3.3, 11.1 and
  // 22.2 mm a frame at 90 Hz).
  const float speed = GENERATE(0.3f, 1.0f, 2.0f);
  CAPTURE(speed);
  const float perFrame = speed / 90.0f;
  TestHand h;
  const float touchHeight = -h.lowest();
  const glm::vec3 wrist(0.0f, touchHeight + 0.01f, 0.0f);  // 1 cm above where it touches y = 0
  const AnalyticShape table{ShapeKind::box, glm::vec3(0.5f, 0.02f, 0.5f)};
  const AnalyticShape box{ShapeKind::box, glm::vec3(0.03f, 0.03f, 0.03f)};
  const bool rising = GENERATE(true, false);
  CAPTURE(rising);
  const AnalyticShape& shape = rising ? table : box;
  OuterHand outer(h.model);
  float deepest = 0.0f;
  OuterHandResult r;
  bool pushed = false;
  for (int frame = 0; frame < 30; ++frame) {
    // The table's top from 1 cm under the hand up to 9 cm into it; the box from 12 cm beside the
    // palm (along +x) to 2 cm past it; then still.
    const float travel = std::min(0.1f, perFrame * float(frame));
    const Pose worldFromShape = rising ? at(glm::vec3(0.0f, -0.02f + travel, 0.0f))
                                       : at(glm::vec3(0.12f - travel, touchHeight - 0.02f, 0.0f));
    r = stillHandStep(outer, h, wrist, frame, shape, worldFromShape);
    pushed = pushed || r.pushedOut;
    deepest = std::min(deepest, shownClearance(h, r, shape, worldFromShape));
  }
  CHECK(pushed);
  CHECK(r.constrained);
  // Never inside by more than the exact search's tolerance, in any frame.
  CHECK(deepest >= -0.001f);
}

TEST_CASE("A tracked hand that jumps is shown at its new pose at once, or the nearest clear one",
          "[core][outer_hand]") {
  // Pressed 3 cm into a table (shown on it), then tracking jumps 50 cm: onto a clear pose, or onto
  // one 1 cm into a box standing there. Never blended through what lies between.
  TestHand h;
  const float touchHeight = -h.lowest();
  const AnalyticShape table{ShapeKind::box, glm::vec3(0.5f, 0.02f, 0.5f)};
  const Pose worldFromTable = at(glm::vec3(0.0f, -0.02f, 0.0f));
  const AnalyticShape box{ShapeKind::box, glm::vec3(0.05f, 0.05f, 0.05f)};
  // The box's top 1 cm above where the hand at x = 0.5 m touches y = 0.
  const Pose worldFromBox = at(glm::vec3(0.5f, -0.04f, 0.0f));
  const std::vector<SceneMember> members{{1, nullptr, &table, worldFromTable.inverse()},
                                         {2, nullptr, &box, worldFromBox.inverse()}};
  const SceneExactSource scene(members);
  OuterHand outer(h.model);
  Stepper step{outer, h, scene};
  for (int k = 0; k <= 5; ++k) step(glm::vec3(0.0f, touchHeight + 0.01f - 0.008f * k, 0.0f));
  REQUIRE(step(glm::vec3(0.0f, touchHeight - 0.03f, 0.0f)).constrained);
  const bool intoBox = GENERATE(false, true);
  CAPTURE(intoBox);
  const glm::vec3 landing(-0.5f, touchHeight + 0.05f, 0.0f);
  const glm::vec3 inBox(0.5f, touchHeight - 0.0f, 0.0f);  // 1 cm into the box's top
  const OuterHandResult r = step(intoBox ? inBox : landing);
  CHECK_FALSE(r.blending);
  if (!intoBox) {
    CHECK_FALSE(r.constrained);
    CHECK(r.worldFromShownWrist.position == landing);
  } else {
    CHECK(r.pushedOut);
    CHECK(shownClearance(h, r, box, worldFromBox) >= -0.001f);
    CHECK(glm::length(r.worldFromShownWrist.position - inBox) < 0.02f);  // the nearest way out
  }
}

TEST_CASE("Bad input to the outer hand is refused and changes nothing", "[core][outer_hand]") {
  TestHand h;
  const AnalyticShape table{ShapeKind::box, glm::vec3(0.5f, 0.02f, 0.5f)};
  const std::vector<SceneMember> members{
      {1, nullptr, &table, at(glm::vec3(0.0f, -0.02f, 0.0f)).inverse()}};
  const SceneExactSource scene(members);
  const float touchHeight = -h.lowest();
  OuterHand plain(h.model), refused(h.model);
  Stepper good{plain, h, scene}, other{refused, h, scene};
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const int kind = GENERATE(0, 1, 2);  // null joints, a non-finite wrist, a non-finite offset
  CAPTURE(kind);
  for (int k = 0; k <= 8; ++k) {
    const glm::vec3 wrist(0.0f, touchHeight + 0.01f - 0.005f * float(k), 0.0f);
    OuterHandInput bad;
    bad.worldFromWrist = at(wrist);
    bad.joints = &h.joints;
    bad.radii = &h.radii;
    bad.time = other.t;
    if (kind == 0) bad.joints = nullptr;
    if (kind == 1) bad.worldFromWrist.position.x = nan;
    if (kind == 2) bad.drawnOffset.orientation.w = nan;
    const auto r = refused.update(bad, &scene);
    REQUIRE_FALSE(r.ok());
    CHECK(r.error().code == Status::invalid_argument);
    const OuterHandResult a = good(wrist), b = other(wrist);
    CHECK(a.worldFromShownWrist.position == b.worldFromShownWrist.position);
    CHECK(a.constrained == b.constrained);
  }
}

TEST_CASE("After a release the shown hand never follows tracking into another object",
          "[core][outer_hand]") {
  TestHand h;
  // A thick table (top at y = 0) and a comb standing on it: a box 2 cm thick in x, 8 cm tall.
  const AnalyticShape table{ShapeKind::box, glm::vec3(0.5f, 0.1f, 0.5f)};
  const Pose worldFromTable = at(glm::vec3(0.0f, -0.1f, 0.0f));
  const AnalyticShape comb{ShapeKind::box, glm::vec3(0.01f, 0.04f, 0.2f)};
  const Pose worldFromComb = at(glm::vec3(0.16f, 0.04f, 0.0f));
  const std::vector<SceneMember> members{{1, nullptr, &table, worldFromTable.inverse()},
                                         {2, nullptr, &comb, worldFromComb.inverse()}};
  const SceneExactSource scene(members);
  OuterHand outer(h.model);
  Stepper next{outer, h, scene};
  const float touch = -h.lowest();
  // Pushed 15 cm into the table, 1 cm a frame: let go past the release distance, blended to
  // tracking, then shown as tracked inside.
  OuterHandResult r;
  for (int k = 0; k <= 17; ++k) r = next(glm::vec3(0.0f, touch + 0.02f - 0.01f * float(k), 0.0f));
  for (int k = 0; k < 40; ++k) r = next(glm::vec3(0.0f, touch - 0.15f, 0.0f));
  REQUIRE(r.released);
  // Up until the hand is half out (its lower part still in the table), then along +x into the
  // comb, 1 cm a frame, to 4 cm past where the hand's side meets its near face (x = 0.15).
  const float halfOut = touch - 0.01f;
  for (float y = touch - 0.15f; y < halfOut; y += 0.01f) r = next(glm::vec3(0.0f, y, 0.0f));
  r = next(glm::vec3(0.0f, halfOut, 0.0f));
  CHECK(shownClearance(h, r, table, worldFromTable) < -0.002f);  // partly in the table
  // The wrist's x where the hand's side (its largest x in the wrist frame) touches the comb.
  HandParts parts;
  const int n = jointParts(h.joints, h.radii, parts);
  float side = -1.0f;
  for (int i = 0; i < n; ++i)
    side = std::max(side, parts[size_t(i)].centre.x + parts[size_t(i)].radius);
  const float meets = 0.15f - side;
  float deepestInComb = 0.0f, trackedX = 0.0f;
  for (int k = 1; 0.01f * float(k) <= meets + 0.04f; ++k) {
    trackedX = 0.01f * float(k);
    r = next(glm::vec3(trackedX, halfOut, 0.0f));
    deepestInComb = std::min(deepestInComb, shownClearance(h, r, comb, worldFromComb));
  }
  // The tracked hand went 4 cm into the comb (followed there while released, the shown hand
  // was 18.6 mm inside it); the shown hand stopped on it (it may turn along it) and is held again.
  CHECK(deepestInComb >= -0.001f);
  CHECK_FALSE(r.released);
  CHECK(r.constrained);
  CHECK(r.worldFromShownWrist.position.x < trackedX - 0.005f);
}

TEST_CASE("A thin plate moving through a still open hand at 2 m/s pushes it, never through",
          "[core][outer_hand]") {
  // A 3 mm plate (a tray, a door) swept up through where the hand is, 22 mm a frame, from 2 cm
  // under it to 4 cm past where it would have cut through the palm.
  TestHand h;
  const float touchHeight = -h.lowest();
  const glm::vec3 wrist(0.0f, touchHeight + 0.02f, 0.0f);
  const AnalyticShape plate{ShapeKind::box, glm::vec3(0.2f, 0.0015f, 0.2f)};
  OuterHand outer(h.model);
  float deepest = 0.0f, lowestWrist = 1.0f;
  for (int frame = 0; frame < 20; ++frame) {
    const float y = std::min(0.0015f + 0.0222f * float(frame), touchHeight + 0.06f);
    const Pose worldFromPlate = at(glm::vec3(0.0f, y, 0.0f));
    const OuterHandResult result = stillHandStep(outer, h, wrist, frame, plate, worldFromPlate);
    deepest = std::min(deepest, shownClearance(h, result, plate, worldFromPlate));
    // The shown wrist, relative to the plate: never on its far side.
    lowestWrist = std::min(lowestWrist, result.worldFromShownWrist.position.y - y);
  }
  CHECK(deepest >= -0.001f);
  CHECK(lowestWrist > 0.0f);
}

TEST_CASE("A hand that appears inside a box (its first update) is shown at the nearest clear pose",
          "[core][outer_hand]") {
  // Tracking found again, or the first frame near a target: no history, the hand 1 cm into a
  // box's top. Shown out of it at once, within 2 cm of the tracked pose (the nearest way out).
  TestHand h;
  const float touchHeight = -h.lowest();
  const AnalyticShape box{ShapeKind::box, glm::vec3(0.05f, 0.05f, 0.05f)};
  const Pose worldFromBox = at(glm::vec3(0.0f, -0.04f, 0.0f));  // its top at y = 0.01
  const std::vector<SceneMember> members{{1, nullptr, &box, worldFromBox.inverse()}};
  const SceneExactSource scene(members);
  OuterHand outer(h.model);
  Stepper step{outer, h, scene};
  const glm::vec3 inside(0.0f, touchHeight, 0.0f);
  const OuterHandResult r = step(inside);
  CHECK(r.pushedOut);
  CHECK(shownClearance(h, r, box, worldFromBox) >= -0.001f);
  CHECK(glm::length(r.worldFromShownWrist.position - inside) < 0.02f);
  // Held there while tracking stays inside; back to tracking once it is clear.
  CHECK(shownClearance(h, step(inside), box, worldFromBox) >= -0.001f);
  const glm::vec3 above(0.0f, touchHeight + 0.05f, 0.0f);
  const OuterHandResult out = step(above);
  CHECK(out.worldFromShownWrist.position == above);
}
