// Approaching placements and the whole hand's penetration (eval/approaching.h): on a box whose
// top face cuts the open hand the deepest part is known exactly; placements span 1 cm inside to
// 5 cm outside and flag the open hands already inside.
#include <algorithm>
#include <cmath>

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include "eval/approaching.h"
#include "eval/evaluator.h"
#include "grasp/solver.h"
#include "hand/hand_model.h"
#include "io/shapes.h"

namespace {

using namespace sdfg;

}  // namespace

TEST_CASE("whole-hand penetration is the deepest part of palm, metacarpals and phalanges",
          "[approaching]") {
  const HandModel hand = HandModel::defaultAdult(Hand::right);
  // A 40 cm slab, 10 cm thick, whose top face y = 0.05 (object space) lies 6 mm above the open
  // palm's lowest point, the hand level over it: on a plane the deepest capsule point is at a
  // joint, where r - (y - top) is largest.
  const TriangleMesh slab = makeBox(glm::vec3(0.4f, 0.1f, 0.4f));
  auto query = ExactMeshQuery::create(slab);
  REQUIRE(query.ok());
  JointPoses open;
  hand.pose(FingerCurls{}, open);
  const float palmBottom = open[size_t(Joint::palm)].position.y - hand.jointRadius(Joint::palm);
  const Pose objectFromHand{glm::quat(1, 0, 0, 0),
                            glm::vec3(0.0f, 0.05f - palmBottom - 0.006f, 0.08f)};
  float expected = 0.0f;
  for (int j = 0; j < kJointCount; ++j) {
    if (Joint(j) == Joint::wrist) continue;
    const glm::vec3 p = objectFromHand.transformPoint(open[size_t(j)].position);
    expected = std::max(expected, hand.jointRadius(Joint(j)) - (p.y - 0.05f));
  }
  REQUIRE(expected >= 0.006f);
  const std::array<JointCurls, kFingerCount> openCurls{};
  CHECK(handPenetrationMm(**query, hand, objectFromHand, openCurls) ==
        Approx(expected * 1000.0f).margin(0.01f));
  // Moved up by the depth, the hand is clear: the correction is applied.
  const Pose up{glm::quat(1, 0, 0, 0), glm::vec3(0.0f, expected + 0.0005f, 0.0f)};
  CHECK(handPenetrationMm(**query, hand, objectFromHand, openCurls, up) == 0.0f);
  // A grasp result carries its own correction and curls.
  GraspResult g;
  g.handCorrection = up;
  CHECK(graspPenetrationMm(**query, hand, objectFromHand, g) == 0.0f);
}

TEST_CASE("approaching placements put the palm 1 cm inside to 5 cm outside", "[approaching]") {
  const HandModel hand = HandModel::defaultAdult(Hand::right);
  const TriangleMesh ball = makeSphere(0.06f, 3);
  auto query = ExactMeshQuery::create(ball);
  REQUIRE(query.ok());
  const std::vector<ApproachPlacement> a =
      generateApproachingPlacements(ball, **query, hand, GridBox::referenceDefault(), 60, 5);
  REQUIRE(a.size() == 60);
  int inside = 0;
  for (const ApproachPlacement& p : a) {
    CHECK(p.placement.palmDistance >= kApproachMinPalmDistance);
    CHECK(p.placement.palmDistance <= kApproachMaxPalmDistance);
    const std::array<JointCurls, kFingerCount> openCurls{};
    CHECK(p.openInside ==
          (handPenetrationMm(**query, hand, p.placement.objectFromHand, openCurls) > 0.0f));
    // A palm joint inside the ball means the open hand is inside.
    if (p.placement.palmDistance < 0.0f) CHECK(p.openInside);
    inside += p.openInside ? 1 : 0;
  }
  // Both kinds occur: the split has two sides.
  CHECK(inside > 0);
  CHECK(inside < 60);
  // The same seed gives the same placements.
  const std::vector<ApproachPlacement> b =
      generateApproachingPlacements(ball, **query, hand, GridBox::referenceDefault(), 60, 5);
  CHECK(glm::length(a[7].placement.objectFromHand.position -
                    b[7].placement.objectFromHand.position) == 0.0f);
}
