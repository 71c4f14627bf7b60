#include <catch2/catch.hpp>

#include <openxr/openxr.h>

#include <cmath>
#include <cstdio>
#include <ctime>
#include <limits>
#include <random>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "hand/hand_model.h"

namespace {

using sdfg::Finger;
using sdfg::Hand;
using sdfg::HandModel;
using sdfg::Joint;
using sdfg::JointPoses;
using sdfg::Pose;

constexpr int j(Joint joint) {
  return static_cast<int>(joint);
}

// The core has no OpenXR dependency; its enum must still match XrHandJointEXT value for value.
static_assert(sdfg::kJointCount == XR_HAND_JOINT_COUNT_EXT, "joint count differs from OpenXR");
static_assert(j(Joint::palm) == XR_HAND_JOINT_PALM_EXT);
static_assert(j(Joint::wrist) == XR_HAND_JOINT_WRIST_EXT);
static_assert(j(Joint::thumb_metacarpal) == XR_HAND_JOINT_THUMB_METACARPAL_EXT);
static_assert(j(Joint::thumb_proximal) == XR_HAND_JOINT_THUMB_PROXIMAL_EXT);
static_assert(j(Joint::thumb_distal) == XR_HAND_JOINT_THUMB_DISTAL_EXT);
static_assert(j(Joint::thumb_tip) == XR_HAND_JOINT_THUMB_TIP_EXT);
static_assert(j(Joint::index_metacarpal) == XR_HAND_JOINT_INDEX_METACARPAL_EXT);
static_assert(j(Joint::index_proximal) == XR_HAND_JOINT_INDEX_PROXIMAL_EXT);
static_assert(j(Joint::index_intermediate) == XR_HAND_JOINT_INDEX_INTERMEDIATE_EXT);
static_assert(j(Joint::index_distal) == XR_HAND_JOINT_INDEX_DISTAL_EXT);
static_assert(j(Joint::index_tip) == XR_HAND_JOINT_INDEX_TIP_EXT);
static_assert(j(Joint::middle_metacarpal) == XR_HAND_JOINT_MIDDLE_METACARPAL_EXT);
static_assert(j(Joint::middle_proximal) == XR_HAND_JOINT_MIDDLE_PROXIMAL_EXT);
static_assert(j(Joint::middle_intermediate) == XR_HAND_JOINT_MIDDLE_INTERMEDIATE_EXT);
static_assert(j(Joint::middle_distal) == XR_HAND_JOINT_MIDDLE_DISTAL_EXT);
static_assert(j(Joint::middle_tip) == XR_HAND_JOINT_MIDDLE_TIP_EXT);
static_assert(j(Joint::ring_metacarpal) == XR_HAND_JOINT_RING_METACARPAL_EXT);
static_assert(j(Joint::ring_proximal) == XR_HAND_JOINT_RING_PROXIMAL_EXT);
static_assert(j(Joint::ring_intermediate) == XR_HAND_JOINT_RING_INTERMEDIATE_EXT);
static_assert(j(Joint::ring_distal) == XR_HAND_JOINT_RING_DISTAL_EXT);
static_assert(j(Joint::ring_tip) == XR_HAND_JOINT_RING_TIP_EXT);
static_assert(j(Joint::little_metacarpal) == XR_HAND_JOINT_LITTLE_METACARPAL_EXT);
static_assert(j(Joint::little_proximal) == XR_HAND_JOINT_LITTLE_PROXIMAL_EXT);
static_assert(j(Joint::little_intermediate) == XR_HAND_JOINT_LITTLE_INTERMEDIATE_EXT);
static_assert(j(Joint::little_distal) == XR_HAND_JOINT_LITTLE_DISTAL_EXT);
static_assert(j(Joint::little_tip) == XR_HAND_JOINT_LITTLE_TIP_EXT);

constexpr Finger kFingers[] = {Finger::thumb, Finger::index, Finger::middle, Finger::ring,
                               Finger::little};

JointPoses poseAll(const HandModel& hand, float a) {
  JointPoses p;
  hand.pose(sdfg::FingerCurls{a, a, a, a, a}, p);
  return p;
}

glm::vec3 axis(const Pose& p, glm::vec3 local) {
  return p.orientation * local;
}

// atan2 form: accurate for tiny angles, where acos of a float dot product is not.
float angleDeg(glm::vec3 a, glm::vec3 b) {
  return glm::degrees(std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b)));
}

float segmentDistance(glm::vec3 p, glm::vec3 a, glm::vec3 b) {
  const glm::vec3 ab = b - a;
  const float t = glm::clamp(glm::dot(p - a, ab) / glm::dot(ab, ab), 0.0f, 1.0f);
  return glm::length(p - (a + t * ab));
}

// Point on the palm's skin: XR_EXT_hand_tracking puts it at palm + (0, -r, 0) in palm space.
glm::vec3 palmSurface(const HandModel& hand, const JointPoses& p) {
  return p[j(Joint::palm)].transformPoint(glm::vec3(0.0f, -hand.jointRadius(Joint::palm), 0.0f));
}

}  // namespace

TEST_CASE("Hand joints follow the XR_EXT_hand_tracking order", "[core][hand]") {
  using sdfg::fingerJoints;
  SECTION("Each finger lists its joints from metacarpal to tip") {
    REQUIRE(fingerJoints(Finger::thumb).size() == 4);
    CHECK(fingerJoints(Finger::thumb)[0] == Joint::thumb_metacarpal);
    CHECK(fingerJoints(Finger::thumb)[3] == Joint::thumb_tip);
    for (Finger f : {Finger::index, Finger::middle, Finger::ring, Finger::little}) {
      const auto joints = fingerJoints(f);
      REQUIRE(joints.size() == 5);
      for (size_t k = 1; k < joints.size(); ++k) CHECK(j(joints[k]) == j(joints[k - 1]) + 1);
      CHECK(joints.back() == sdfg::tipJoint(f));
    }
  }
  SECTION("Names match the joints") {
    CHECK(std::string(sdfg::jointName(Joint::palm)) == "palm");
    CHECK(std::string(sdfg::jointName(Joint::ring_intermediate)) == "ring_intermediate");
    CHECK(std::string(sdfg::fingerName(Finger::little)) == "little");
  }
}

TEST_CASE("The open hand has the XR axes and the left hand mirrors the right", "[core][hand]") {
  const HandModel right = HandModel::defaultAdult(Hand::right);
  const JointPoses open = poseAll(right, 0.0f);

  SECTION("Wrist at the origin with identity orientation") {
    CHECK(glm::length(open[j(Joint::wrist)].position) == Approx(0.0f).margin(1e-7));
    CHECK(open[j(Joint::wrist)].orientation.w == Approx(1.0f).margin(1e-7));
  }
  SECTION("Fingers extend along -Z, the back of the hand is +Y, the thumb is toward -X") {
    for (Finger f : {Finger::index, Finger::middle, Finger::ring, Finger::little}) {
      for (Joint joint : sdfg::fingerJoints(f)) {
        CAPTURE(sdfg::jointName(joint));
        CHECK(axis(open[j(joint)], {0, 0, -1}).z < -0.9f);
        CHECK(axis(open[j(joint)], {0, 1, 0}).y > 0.99f);
      }
    }
    CHECK(open[j(Joint::middle_tip)].position.z < -0.15f);
    CHECK(open[j(Joint::thumb_tip)].position.x < -0.05f);
    CHECK(open[j(Joint::index_tip)].position.x < 0.0f);
    CHECK(open[j(Joint::little_tip)].position.x > 0.0f);
    // The palm sits on the middle metacarpal, oriented like it.
    CHECK(axis(open[j(Joint::palm)], {0, 0, -1}).z < -0.99f);
    CHECK(open[j(Joint::palm)].position.z < open[j(Joint::middle_metacarpal)].position.z);
    CHECK(open[j(Joint::palm)].position.z > open[j(Joint::middle_proximal)].position.z);
  }
  SECTION("Left hand: x -> -x, (w, x, y, z) -> (w, x, -y, -z), at any curl") {
    const HandModel left = HandModel::defaultAdult(Hand::left);
    CHECK(left.side() == Hand::left);
    for (float a : {0.0f, 0.4f, 1.0f}) {
      const JointPoses r = poseAll(right, a);
      const JointPoses l = poseAll(left, a);
      for (int i = 0; i < sdfg::kJointCount; ++i) {
        CAPTURE(a, i);
        CHECK(l[i].position.x == Approx(-r[i].position.x).margin(1e-6));
        CHECK(l[i].position.y == Approx(r[i].position.y).margin(1e-6));
        CHECK(l[i].position.z == Approx(r[i].position.z).margin(1e-6));
        CHECK(l[i].orientation.w == Approx(r[i].orientation.w).margin(1e-6));
        CHECK(l[i].orientation.x == Approx(r[i].orientation.x).margin(1e-6));
        CHECK(l[i].orientation.y == Approx(-r[i].orientation.y).margin(1e-6));
        CHECK(l[i].orientation.z == Approx(-r[i].orientation.z).margin(1e-6));
        CHECK(left.jointRadius(static_cast<Joint>(i)) == right.jointRadius(static_cast<Joint>(i)));
      }
    }
  }
}

TEST_CASE("Joint frames are unit rotations whose -Z points at the next joint", "[core][hand]") {
  for (Hand side : {Hand::right, Hand::left}) {
    const HandModel hand = HandModel::defaultAdult(side);
    for (float a : {0.0f, 0.37f, 1.0f}) {
      const JointPoses p = poseAll(hand, a);
      for (const Pose& pose : p) CHECK(glm::length(pose.orientation) == Approx(1.0f).margin(1e-5));
      for (Finger f : kFingers) {
        const auto joints = sdfg::fingerJoints(f);
        for (size_t k = 0; k + 1 < joints.size(); ++k) {
          CAPTURE(a, sdfg::jointName(joints[k]));
          const glm::vec3 bone = p[j(joints[k + 1])].position - p[j(joints[k])].position;
          // Bone lengths are the model's at every curl.
          CHECK(glm::length(bone) == Approx(hand.boneLength(joints[k])).margin(1e-6));
          CHECK(angleDeg(axis(p[j(joints[k])], {0, 0, -1}), bone) < 0.01f);
        }
        CHECK(hand.boneLength(joints.back()) == 0.0f);
      }
    }
  }
}

TEST_CASE("Default bone lengths are the anthropometric fractions of hand length", "[core][hand]") {
  const HandModel hand = HandModel::defaultAdult(Hand::right);
  const float handLength = 0.190f;
  // Buchholz, Armstrong & Goldstein (1992) segment lengths over hand length.
  CHECK(hand.boneLength(Joint::middle_metacarpal) == Approx(0.373f * handLength).margin(1e-6));
  CHECK(hand.boneLength(Joint::middle_proximal) == Approx(0.277f * handLength).margin(1e-6));
  CHECK(hand.boneLength(Joint::index_intermediate) == Approx(0.143f * handLength).margin(1e-6));
  CHECK(hand.boneLength(Joint::little_distal) == Approx(0.093f * handLength).margin(1e-6));
  CHECK(hand.boneLength(Joint::thumb_metacarpal) == Approx(0.251f * handLength).margin(1e-6));
  // Wrist crease to middle fingertip is one hand length in the open pose.
  const JointPoses open = poseAll(hand, 0.0f);
  CHECK(-open[j(Joint::middle_tip)].position.z == Approx(handLength).margin(2e-3));
  for (int i = 0; i < sdfg::kJointCount; ++i) CHECK(hand.jointRadius(static_cast<Joint>(i)) > 0);
  CHECK(hand.tipRadius(Finger::index) == hand.jointRadius(Joint::index_tip));
}

TEST_CASE("Curl blends the open and closed poses per joint with slerp", "[core][hand]") {
  const HandModel hand = HandModel::defaultAdult(Hand::right);
  const JointPoses open = poseAll(hand, 0.0f);
  const JointPoses closed = poseAll(hand, 1.0f);

  auto local = [](const JointPoses& p, Joint parent, Joint child) {
    return glm::conjugate(p[j(parent)].orientation) * p[j(child)].orientation;
  };

  SECTION("Curl 0 is the flat hand: each long finger is straight") {
    for (Finger f : {Finger::index, Finger::middle, Finger::ring, Finger::little}) {
      const auto js = sdfg::fingerJoints(f);
      for (size_t k = 1; k + 1 < js.size(); ++k) {
        const glm::vec3 a = open[j(js[k])].position - open[j(js[k - 1])].position;
        const glm::vec3 b = open[j(js[k + 1])].position - open[j(js[k])].position;
        CHECK(angleDeg(a, b) < (k == 1 ? 12.0f : 0.01f));  // knuckle: only the spread
      }
    }
  }
  SECTION("Curl 1 is the fist: MCP 80-90, PIP ~100, DIP ~70 degrees toward the palm") {
    for (Finger f : {Finger::index, Finger::middle, Finger::ring, Finger::little}) {
      const auto js = sdfg::fingerJoints(f);
      const glm::vec3 mc = closed[j(js[1])].position - closed[j(js[0])].position;
      const glm::vec3 pp = closed[j(js[2])].position - closed[j(js[1])].position;
      const glm::vec3 mp = closed[j(js[3])].position - closed[j(js[2])].position;
      const glm::vec3 dp = closed[j(js[4])].position - closed[j(js[3])].position;
      CAPTURE(sdfg::fingerName(f));
      CHECK(angleDeg(mc, pp) > 80.0f);
      CHECK(angleDeg(mc, pp) < 92.0f);
      CHECK(angleDeg(pp, mp) == Approx(100.0f).margin(1.0f));
      CHECK(angleDeg(mp, dp) == Approx(70.0f).margin(3.0f));
      // Toward the palm: the proximal phalanx turns to -Y of its metacarpal.
      CHECK(glm::dot(pp, axis(closed[j(js[0])], {0, -1, 0})) > 0.0f);
    }
  }
  SECTION("Intermediate curls are the per-joint slerp of the open and closed local rotations") {
    for (float a : {0.25f, 0.5f, 0.8f}) {
      const JointPoses mid = poseAll(hand, a);
      for (Finger f : kFingers) {
        const auto js = sdfg::fingerJoints(f);
        for (size_t k = 1; k + 1 < js.size(); ++k) {
          const glm::quat expected =
              glm::slerp(local(open, js[k - 1], js[k]), local(closed, js[k - 1], js[k]), a);
          const glm::quat got = local(mid, js[k - 1], js[k]);
          CAPTURE(a, sdfg::jointName(js[k]));
          CHECK(std::abs(glm::dot(expected, got)) == Approx(1.0f).margin(1e-5));
        }
      }
    }
  }
  SECTION("Curls are clamped to [0, 1] and NaN reads as open") {
    JointPoses p;
    hand.pose({-1.0f, 2.0f, std::numeric_limits<float>::quiet_NaN(), 0.0f, 1.0f}, p);
    CHECK(glm::length(p[j(Joint::thumb_tip)].position - open[j(Joint::thumb_tip)].position) <
          1e-6f);
    CHECK(glm::length(p[j(Joint::index_tip)].position - closed[j(Joint::index_tip)].position) <
          1e-6f);
    CHECK(glm::length(p[j(Joint::middle_tip)].position - open[j(Joint::middle_tip)].position) <
          1e-6f);
  }
}

TEST_CASE("A closed fist ends near the palm with the thumb opposing", "[core][hand]") {
  const HandModel hand = HandModel::defaultAdult(Hand::right);
  const JointPoses closed = poseAll(hand, 1.0f);
  const glm::vec3 palm = palmSurface(hand, closed);
  const float palmRadius = hand.jointRadius(Joint::palm);

  for (Finger f : {Finger::index, Finger::middle, Finger::ring, Finger::little}) {
    CAPTURE(sdfg::fingerName(f));
    const glm::vec3 tip = closed[j(sdfg::tipJoint(f))].position;
    CHECK(glm::length(tip - palm) < 0.035f);  // within a few cm of the palm skin
    CHECK(tip.y < 0.0f);                      // on the palm side, not behind the back
    // Resting on the palm skin, not sunk into it: the tip sphere reaches the palm plane
    // within a few millimetres, and its centre stays outside the palm.
    CHECK(tip.y + hand.tipRadius(f) > -palmRadius - 0.008f);
    CHECK(tip.y < -palmRadius);
  }
  // The thumb tip lies against the index or middle finger, not inside them.
  const glm::vec3 thumbTip = closed[j(Joint::thumb_tip)].position;
  float gap = 1.0f;
  for (Finger f : {Finger::index, Finger::middle}) {
    const auto js = sdfg::fingerJoints(f);
    for (size_t k = 1; k + 1 < js.size(); ++k) {
      const float d =
          segmentDistance(thumbTip, closed[j(js[k])].position, closed[j(js[k + 1])].position) -
          hand.tipRadius(Finger::thumb) - hand.jointRadius(js[k + 1]);
      gap = std::min(gap, d);
    }
  }
  CHECK(gap > -0.003f);
  CHECK(gap < 0.010f);
  CHECK(thumbTip.y < 0.0f);
}

TEST_CASE("Tip curves are continuous and curl moves every tip toward the palm", "[core][hand]") {
  const HandModel hand = HandModel::defaultAdult(Hand::right);
  const glm::vec3 palm = palmSurface(hand, poseAll(hand, 0.0f));
  for (Finger f : kFingers) {
    CAPTURE(sdfg::fingerName(f));
    const std::vector<glm::vec3> curve = hand.tipCurve(f, 0.01f);
    REQUIRE(curve.size() == 101);
    CHECK(glm::length(curve.front() - hand.tipPosition(f, 0.0f)) < 1e-7f);
    CHECK(glm::length(curve.back() - hand.tipPosition(f, 1.0f)) < 1e-7f);
    float maxStep = 0.0f;
    float pathLength = 0.0f;
    for (size_t k = 1; k < curve.size(); ++k) {
      const float step = glm::length(curve[k] - curve[k - 1]);
      maxStep = std::max(maxStep, step);
      pathLength += step;
      // Monotone: every step brings the tip closer to the palm skin.
      CHECK(glm::length(curve[k] - palm) <= glm::length(curve[k - 1] - palm) + 1e-6f);
    }
    // No jump: no step is much longer than the average step.
    CHECK(maxStep < 2.5f * pathLength / static_cast<float>(curve.size() - 1));
    CHECK(maxStep < 0.006f);
  }
}

TEST_CASE("Curve parameters are min(k * da, 1) and end exactly at 1", "[core][hand]") {
  using sdfg::HandModel;
  SECTION("da = 0.1 gives 11 samples") {
    const auto p = HandModel::curveParameters(0.1f);
    REQUIRE(p.size() == 11);
    for (size_t k = 0; k < p.size(); ++k) CHECK(p[k] == Approx(0.1f * k).margin(1e-6));
    CHECK(p.back() == 1.0f);
  }
  SECTION("da = 0.3 gives 0, 0.3, 0.6, 0.9, 1") {
    const auto p = HandModel::curveParameters(0.3f);
    REQUIRE(p.size() == 5);
    CHECK(p[3] == Approx(0.9f).margin(1e-6));
    CHECK(p[4] == 1.0f);
  }
  SECTION("da = 0.01 gives 101 samples, strictly increasing") {
    const auto p = HandModel::curveParameters(0.01f);
    REQUIRE(p.size() == 101);
    for (size_t k = 1; k < p.size(); ++k) CHECK(p[k] > p[k - 1]);
    CHECK(p[50] == Approx(0.5f).margin(1e-6));
    CHECK(p.back() == 1.0f);
  }
  SECTION("da = 1 gives 0 and 1") {
    const auto p = HandModel::curveParameters(1.0f);
    REQUIRE(p.size() == 2);
    CHECK(p[0] == 0.0f);
    CHECK(p[1] == 1.0f);
  }
  SECTION("Invalid steps give nothing") {
    CHECK(HandModel::curveParameters(0.0f).empty());
    CHECK(HandModel::curveParameters(-0.1f).empty());
    CHECK(HandModel::curveParameters(std::numeric_limits<float>::quiet_NaN()).empty());
    CHECK(HandModel::curveParameters(1.5f).empty());
    CHECK(HandModel::curveParameters(std::numeric_limits<float>::infinity()).empty());
    CHECK(HandModel::curveParameters(1e-9f).empty());  // would be a billion samples
    const HandModel hand = HandModel::defaultAdult(Hand::right);
    CHECK(hand.tipCurve(Finger::index, 0.0f).empty());
  }
}

TEST_CASE("Scale multiplies every length and radius", "[core][hand]") {
  const HandModel one = HandModel::defaultAdult(Hand::right, 1.0f);
  const HandModel two = HandModel::defaultAdult(Hand::right, 2.0f);
  for (float a : {0.0f, 0.6f, 1.0f}) {
    const JointPoses p1 = poseAll(one, a);
    const JointPoses p2 = poseAll(two, a);
    for (int i = 0; i < sdfg::kJointCount; ++i) {
      CAPTURE(a, i);
      CHECK(glm::length(p2[i].position - 2.0f * p1[i].position) < 1e-6f);
      CHECK(std::abs(glm::dot(p2[i].orientation, p1[i].orientation)) == Approx(1.0f).margin(1e-6));
    }
  }
  for (int i = 0; i < sdfg::kJointCount; ++i) {
    const Joint joint = static_cast<Joint>(i);
    CHECK(two.jointRadius(joint) == Approx(2.0f * one.jointRadius(joint)).margin(1e-7));
    CHECK(two.boneLength(joint) == Approx(2.0f * one.boneLength(joint)).margin(1e-7));
  }
  // A scale that is not a positive number falls back to 1.
  const HandModel bad = HandModel::defaultAdult(Hand::right, std::nanf(""));
  CHECK(bad.boneLength(Joint::index_proximal) == one.boneLength(Joint::index_proximal));
}

TEST_CASE("fitToJoints recovers a measured hand from tracked joints", "[core][hand]") {
  for (Hand side : {Hand::right, Hand::left}) {
    const HandModel truth = HandModel::defaultAdult(side, 1.3f);
    const JointPoses hand = poseAll(truth, 0.3f);
    // Tracked joints arrive in some base space: apply an arbitrary rigid transform.
    const Pose baseFromHand{glm::normalize(glm::quat(0.8f, 0.3f, -0.4f, 0.2f)),
                            glm::vec3(0.4f, 1.2f, -0.7f)};
    std::array<Pose, sdfg::kJointCount> tracked;
    std::array<float, sdfg::kJointCount> radii;
    for (int i = 0; i < sdfg::kJointCount; ++i) {
      tracked[i] = baseFromHand * hand[i];
      radii[i] = truth.jointRadius(static_cast<Joint>(i));
    }

    SECTION("Bone lengths, radii and poses match the measured hand") {
      auto fit = HandModel::fitToJoints(side, tracked, radii);
      REQUIRE(fit.ok());
      CHECK(fit->side() == side);
      for (int i = 0; i < sdfg::kJointCount; ++i) {
        const Joint joint = static_cast<Joint>(i);
        CAPTURE(sdfg::jointName(joint));
        CHECK(fit->boneLength(joint) == Approx(truth.boneLength(joint)).margin(1e-4));
        CHECK(fit->jointRadius(joint) == truth.jointRadius(joint));
      }
      // Curl poses are kept: the fitted hand reproduces the measured one at every curl.
      for (float a : {0.0f, 0.3f, 1.0f}) {
        const JointPoses expected = poseAll(truth, a);
        const JointPoses got = poseAll(*fit, a);
        for (int i = 0; i < sdfg::kJointCount; ++i) {
          CAPTURE(a, i);
          CHECK(glm::length(got[i].position - expected[i].position) < 1e-4f);
        }
      }
    }
    SECTION("Non-finite input and collapsed bones are rejected") {
      auto nanPose = tracked;
      nanPose[j(Joint::ring_distal)].position.y = std::numeric_limits<float>::quiet_NaN();
      auto r1 = HandModel::fitToJoints(side, nanPose, radii);
      REQUIRE_FALSE(r1.ok());
      CHECK(r1.error().code == sdfg::Status::invalid_argument);
      CHECK(r1.error().message.find("ring_distal") != std::string::npos);

      auto nanRadius = radii;
      nanRadius[j(Joint::palm)] = std::numeric_limits<float>::infinity();
      CHECK_FALSE(HandModel::fitToJoints(side, tracked, nanRadius).ok());

      auto collapsed = tracked;
      collapsed[j(Joint::index_tip)].position = collapsed[j(Joint::index_distal)].position;
      auto r2 = HandModel::fitToJoints(side, collapsed, radii);
      REQUIRE_FALSE(r2.ok());
      CHECK(r2.error().code == sdfg::Status::invalid_argument);
      CHECK(r2.error().message.find("index_distal") != std::string::npos);

      auto zeroQuat = tracked;
      zeroQuat[j(Joint::wrist)].orientation = glm::quat(0.0f, 0.0f, 0.0f, 0.0f);
      CHECK_FALSE(HandModel::fitToJoints(side, zeroQuat, radii).ok());
    }
  }
}

TEST_CASE("estimateCurls inverts pose()", "[core][hand]") {
  std::mt19937 rng(1234);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  for (Hand side : {Hand::right, Hand::left}) {
    for (float scale : {1.0f, 0.85f}) {
      const HandModel hand = HandModel::defaultAdult(side, scale);
      std::vector<sdfg::FingerCurls> cases = {
          {0, 0, 0, 0, 0}, {1, 1, 1, 1, 1}, {0.5f, 0.25f, 0.75f, 0.1f, 0.9f}};
      for (int n = 0; n < 20; ++n)
        cases.push_back({uni(rng), uni(rng), uni(rng), uni(rng), uni(rng)});
      for (const auto& curls : cases) {
        JointPoses p;
        hand.pose(curls, p);
        const sdfg::FingerCurls est = hand.estimateCurls(p);
        for (int f = 0; f < sdfg::kFingerCount; ++f) {
          CAPTURE(scale, f, curls[f]);
          CHECK(est[f] == Approx(curls[f]).margin(0.02));
        }
      }
    }
  }
  SECTION("Non-finite joints read as open") {
    const HandModel hand = HandModel::defaultAdult(Hand::right);
    JointPoses p = poseAll(hand, 0.7f);
    p[j(Joint::middle_distal)].position.x = std::numeric_limits<float>::quiet_NaN();
    const sdfg::FingerCurls est = hand.estimateCurls(p);
    CHECK(est[2] == 0.0f);
    CHECK(est[1] == Approx(0.7f).margin(0.02));
  }
}

TEST_CASE("Per-joint curls equal the single curl when all entries are equal", "[core][hand]") {
  const HandModel hand = HandModel::defaultAdult(Hand::right);
  std::array<Pose, 5> single;
  std::array<Pose, 5> perJoint;
  for (Finger f : kFingers) {
    const size_t n = sdfg::fingerJoints(f).size();
    for (float a : {0.0f, 0.33f, 1.0f}) {
      hand.fingerPose(f, a, std::span<Pose>(single.data(), n));
      hand.fingerPose(f, sdfg::JointCurls{a, a, a, a}, std::span<Pose>(perJoint.data(), n));
      for (size_t k = 0; k < n; ++k) {
        CHECK(glm::length(single[k].position - perJoint[k].position) == 0.0f);
        CHECK(glm::dot(single[k].orientation, perJoint[k].orientation) ==
              Approx(1.0f).margin(1e-7));
      }
      CHECK(glm::length(hand.tipPosition(f, a) - single[n - 1].position) == 0.0f);
    }
  }
  SECTION("Joints stop on their own: a closed distal joint leaves the rest unchanged") {
    hand.fingerPose(Finger::index, sdfg::JointCurls{0, 0, 0, 0}, perJoint);
    hand.fingerPose(Finger::index, sdfg::JointCurls{0, 0, 0, 1}, single);
    for (size_t k = 0; k < 4; ++k)
      CHECK(glm::length(single[k].position - perJoint[k].position) < 1e-7f);
    CHECK(glm::length(single[4].position - perJoint[4].position) > 0.005f);
  }
}

TEST_CASE("Phalanx spheres cover every phalanx with overlapping neighbours", "[core][hand]") {
  const HandModel hand = HandModel::defaultAdult(Hand::right);
  for (float a : {0.0f, 0.5f, 1.0f}) {
    const JointPoses p = poseAll(hand, a);
    for (Finger f : kFingers) {
      CAPTURE(a, sdfg::fingerName(f));
      std::vector<sdfg::BodySphere> spheres{sdfg::BodySphere{}};  // appends after existing
      hand.phalanxSpheres(f, a, spheres);
      REQUIRE(spheres.size() > 4);
      spheres.erase(spheres.begin());
      const auto js = sdfg::fingerJoints(f);
      // From the proximal joint to the tip.
      CHECK(glm::length(spheres.front().center - p[j(js[1])].position) < 1e-6f);
      CHECK(spheres.front().radius == Approx(hand.jointRadius(js[1])));
      CHECK(glm::length(spheres.back().center - p[j(js.back())].position) < 1e-6f);
      CHECK(spheres.back().radius == Approx(hand.tipRadius(f)));
      CHECK(spheres.front().bone == 1);
      CHECK(spheres.back().bone == js.size() - 2);
      for (size_t k = 1; k < spheres.size(); ++k) {
        const auto& s0 = spheres[k - 1];
        const auto& s1 = spheres[k];
        const float d = glm::length(s1.center - s0.center);
        CHECK(d <= s0.radius + s1.radius - 0.5f * std::min(s0.radius, s1.radius) + 1e-6f);
        CHECK(s1.bone >= s0.bone);
        // Every sphere lies on its bone.
        const float off =
            segmentDistance(s1.center, p[j(js[s1.bone])].position, p[j(js[s1.bone + 1])].position);
        CHECK(off < 1e-5f);
      }
    }
  }
}

TEST_CASE("Forward kinematics speed (printed, not asserted)", "[core][hand][bench]") {
  // Thread CPU time, not wall time: the CI machine is shared, and a descheduled thread would
  // otherwise be billed to the hand model.
  auto cpuNs = [] {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) * 1e9 + static_cast<double>(ts.tv_nsec);
  };
  const HandModel hand = HandModel::defaultAdult(Hand::right);
  std::array<Pose, 5> out;
  constexpr int kIters = 200000;
  float sink = 0.0f;
  const double t0 = cpuNs();
  for (int i = 0; i < kIters; ++i) {
    hand.fingerPose(Finger::index, static_cast<float>(i % 1000) * 0.001f, out);
    sink += out[4].position.z;
  }
  const double t1 = cpuNs();
  for (int i = 0; i < kIters; ++i) {
    sink += hand.tipPosition(Finger::thumb, static_cast<float>(i % 1000) * 0.001f).x;
  }
  const double t2 = cpuNs();
  std::printf("hand FK (thread CPU time): fingerPose(index) %.1f ns, tipPosition(thumb) %.1f ns\n",
              (t1 - t0) / kIters, (t2 - t1) / kIters);
  CHECK(std::isfinite(sink));
}
