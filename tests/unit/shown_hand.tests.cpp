// How a hand is shown (grasp/shown_hand.h and the rules it draws with): a tracked hand nothing
// changes passes through bit-identical; a finger never curls past its contact nor past the
// user's own curl; the offset blends by time, not by updates; a closed tracked hand grabs.
#include <catch2/catch.hpp>

#include <cmath>

#include <glm/gtc/quaternion.hpp>

#include "grasp/hand_offset_blend.h"
#include "grasp/shown_curls.h"
#include "grasp/shown_hand.h"
#include "grasp/tracked_squeeze.h"
#include "hand/hand_synthesis.h"

namespace {

using namespace sdfg;

// A right hand at a pose of its own, fingers at `curl`, in a base space.
JointPoses trackedHand(float curl) {
  const HandModel model = HandModel::defaultAdult(Hand::right);
  JointPoses joints;
  JointRadii radii;
  const Pose baseFromWrist{glm::angleAxis(0.4f, glm::normalize(glm::vec3(1, 2, 3))),
                           glm::vec3(0.1f, -0.2f, -0.4f)};
  FingerCurls curls;
  curls.fill(curl);
  placeJoints(model, curls, baseFromWrist, joints, radii);
  return joints;
}

bool samePose(const Pose& a, const Pose& b) {
  return a.position == b.position && a.orientation == b.orientation;
}

GraspResult contactsAt(float curl) {
  GraspResult r;
  for (FingerState& f : r.fingers) {
    f.curl = curl;
    f.jointCurls.fill(curl);
    f.contact = true;
  }
  return r;
}

}  // namespace

TEST_CASE("A tracked hand that shows no grasp passes through bit-identical", "[core][shown_hand]") {
  ShownHand view;  // nothing shown, no offset
  const JointPoses tracked = trackedHand(0.6f);
  JointPoses joints = tracked;
  std::array<bool, kJointCount> changed{};
  changed.fill(true);
  drawTrackedHand(view, joints, changed);
  for (int j = 0; j < kJointCount; ++j) {
    CAPTURE(j);
    CHECK_FALSE(changed[size_t(j)]);
    CHECK(samePose(joints[size_t(j)], tracked[size_t(j)]));
  }
}

TEST_CASE("A shown grasp stops only the fingers the user curls past their contact",
          "[core][shown_hand]") {
  // Every finger touches at curl 0.3. The user holds the hand at 0.6 (past the contact: the
  // fingers stop at 0.3), then at 0.2 (short of it: the user's own fingers stay).
  ShownHand view;
  view.shown = true;
  view.result = contactsAt(0.3f);
  SECTION("the user curls past the contact: finger joints replaced, wrist and palm untouched") {
    const JointPoses tracked = trackedHand(0.6f);
    JointPoses joints = tracked;
    std::array<bool, kJointCount> changed{};
    drawTrackedHand(view, joints, changed);
    CHECK_FALSE(changed[size_t(Joint::wrist)]);
    CHECK_FALSE(changed[size_t(Joint::palm)]);
    CHECK(samePose(joints[size_t(Joint::wrist)], tracked[size_t(Joint::wrist)]));
    CHECK(changed[size_t(Joint::index_tip)]);
    // The stopped fingers are where the model puts them at the contact curl.
    const JointPoses atContact = trackedHand(0.3f);
    CHECK(glm::length(joints[size_t(Joint::index_tip)].position -
                      atContact[size_t(Joint::index_tip)].position) < 1e-4f);
  }
  SECTION("the user holds the hand more open than the contact: nothing changes") {
    const JointPoses tracked = trackedHand(0.2f);
    JointPoses joints = tracked;
    std::array<bool, kJointCount> changed{};
    drawTrackedHand(view, joints, changed);
    for (int j = 0; j < kJointCount; ++j) {
      CAPTURE(j);
      CHECK_FALSE(changed[size_t(j)]);
      CHECK(samePose(joints[size_t(j)], tracked[size_t(j)]));
    }
  }
  SECTION("per joint the lesser curl: a contact curl past the user's keeps the user's") {
    GraspResult r = contactsAt(0.3f);
    r.fingers[1].jointCurls = {0.3f, 0.9f, 0.9f, 0.0f};
    FingerCurls user;
    user.fill(0.6f);
    const ShownCurls c = shownCurls(r, user);
    CHECK(c.replace[1]);
    CHECK(c.curls[1][0] == 0.3f);
    CHECK(c.curls[1][1] == 0.6f);
    CHECK(c.curls[1][2] == 0.6f);
  }
}

TEST_CASE("A synthesized hand curls with the squeeze and stops on the contact",
          "[core][shown_hand]") {
  ShownHand view;
  view.model = HandModel::defaultAdult(Hand::right);
  view.squeeze = 1.0f;
  const Pose baseFromGrip{glm::quat(1, 0, 0, 0), glm::vec3(0.2f, -0.3f, -0.4f)};
  JointPoses fist, held;
  JointRadii radii;
  drawGripHand(view, baseFromGrip, MotionRange::unobstructed, fist, radii);
  view.shown = true;
  view.result = contactsAt(0.3f);
  drawGripHand(view, baseFromGrip, MotionRange::unobstructed, held, radii);
  const auto tipToPalm = [](const JointPoses& j) {
    return glm::length(j[size_t(Joint::middle_tip)].position - j[size_t(Joint::palm)].position);
  };
  // Held at the contact the fingers stay more open than the user's fist.
  CHECK(tipToPalm(held) > tipToPalm(fist) + 0.01f);
  CHECK(samePose(held[size_t(Joint::wrist)], fist[size_t(Joint::wrist)]));
}

TEST_CASE("The hand's offset blends by time, not by updates", "[core][shown_hand]") {
  HandGrasp held;
  held.holding = true;
  held.solves = 1;
  held.result.handCorrection.position = glm::vec3(0.0f, 0.0f, 0.02f);
  // The same 0.05 s at 60 and at 120 updates a second: the same blend (half of 0.1 s).
  for (int hz : {60, 120}) {
    CAPTURE(hz);
    HandOffset o;
    const int64_t step = 1'000'000'000 / hz;
    int64_t t = 1'000'000'000;
    advanceHandOffset(o, held, t, 0.1f);  // the first update only notes the time
    CHECK(o.blend == 0.0f);
    for (int i = 0; i < hz / 20; ++i) advanceHandOffset(o, held, t += step, 0.1f);
    CHECK(o.blend == Approx(0.5f).margin(0.02f));
    // Shown: smoothstep of the blend, along the correction.
    const Pose shown = shownHandOffset(o);
    CHECK(shown.position.z == Approx(0.02f * 0.5f).margin(0.001f));
  }
  SECTION("after the release it blends back out") {
    HandOffset o;
    advanceHandOffset(o, held, 1, 0.1f);
    advanceHandOffset(o, held, 1 + 200'000'000, 0.1f);
    CHECK(o.blend == 1.0f);
    advanceHandOffset(o, HandGrasp{}, 1 + 250'000'000, 0.1f);
    CHECK(o.blend == Approx(0.5f).margin(1e-4f));
    advanceHandOffset(o, HandGrasp{}, 1 + 400'000'000, 0.1f);
    CHECK(o.blend == 0.0f);
    CHECK(samePose(shownHandOffset(o), Pose{}));
  }
}

TEST_CASE("A tracked hand grabs by closing: open reads about 0, a fist about 1",
          "[core][shown_hand]") {
  const HandModel model = HandModel::defaultAdult(Hand::right);
  const auto squeezeAt = [&](float curl) {
    JointPoses local;
    FingerCurls curls;
    curls.fill(curl);
    model.pose(curls, local);
    return squeezeFromTrackedHand(model, local);
  };
  CHECK(squeezeAt(0.0f) == Approx(0.0f).margin(0.02f));
  CHECK(squeezeAt(0.5f) == Approx(0.5f).margin(0.02f));
  CHECK(squeezeAt(1.0f) == Approx(1.0f).margin(0.02f));
}
