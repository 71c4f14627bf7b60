// The depth scene through GraspSession (issue 35): an app's depth handed to the session frame by
// frame, fused on its worker around each hand, grasped and kept out of by the outer hand, with no
// target registered. The depth is rendered from the embedded mug on a table (depth_render.h);
// the truth the hands are measured against is those meshes.
#include <catch2/catch.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtx/quaternion.hpp>

#include "depth_reaches.h"
#include "depth_render.h"
#include "eval/approaching.h"
#include "eval/evaluator.h"
#include "eval/placements.h"
#include "grasp/grasp_session.h"
#include "grasp/shown_hand.h"
#include "hand/hand_synthesis.h"
#include "mesh/mesh_distance.h"
#include "sdf/sdf_backend.h"

using namespace sdfg;
using namespace sdfg::depth_test;
using namespace std::chrono_literals;

namespace {

constexpr int64_t kFrameNs = 11'111'111;  // 90 Hz

// A session with the depth scene on, fed one depth image of a still scene: every frame's update
// of the right hand, then that frame's depth, then the worker let finish (the same answers on
// every machine).
struct DepthRig {
  GraspSession session{makeCpuSdfBackend(1)};
  HandModel model = HandModel::defaultAdult(Hand::right);
  DepthView view = headView();
  std::vector<float> stored;
  int64_t time = kFrameNs;

  DepthRig(const MugOnTable& scene, bool outer) {
    GraspSettings s;
    s.solver = "ours";
    s.outerHand = outer;
    REQUIRE(session.configure(s) == Status::ok);
    REQUIRE(session.enableDepthScene() == Status::ok);
    stored = storedDepth(view, renderDistances(view, scene.objects()), Stored::d24);
  }
  // One frame: the controller-driven hand at `wrist` with `squeeze`, then the frame's depth.
  void frame(const Pose& wrist, float squeeze) {
    HandFrame f;
    f.valid = true;
    f.worldFromWrist = wrist;
    f.squeeze = squeeze;
    f.time = time;
    REQUIRE(session.update(Hand::right, f, std::span<const SpaceFrame>{}) == Status::ok);
    REQUIRE(session.submitDepth({view}, {stored}, double(time) * 1e-9) == Status::ok);
    time += kFrameNs;
    REQUIRE(session.waitWorkerIdle(10s));
  }
};

}  // namespace

TEST_CASE("Depth scene: a session refuses depth it cannot read and depth while it is off",
          "[depth][session]") {
  GraspSession session{makeCpuSdfBackend(1)};
  const DepthView view = headView();
  const std::vector<float> flat(size_t(view.width) * view.height, 0.5f);
  CHECK(session.submitDepth({view}, {flat}, 0.0) == Status::unsupported);
  REQUIRE(session.enableDepthScene() == Status::ok);
  CHECK(session.enableDepthScene() == Status::invalid_argument);
  DepthFusionOptions bad;
  bad.voxel = 0.0f;
  GraspSession other{makeCpuSdfBackend(1)};
  CHECK(other.enableDepthScene(bad) == Status::invalid_argument);
  CHECK_FALSE(other.depthSceneEnabled());

  // A view that cannot be right, and values of the wrong count: nothing is queued.
  DepthView broken = view;
  broken.nearZ = broken.farZ;
  CHECK(session.submitDepth({broken}, {flat}, 0.0) == Status::invalid_argument);
  CHECK(session.submitDepth({view}, {std::vector<float>(7, 0.5f)}, 0.0) ==
        Status::invalid_argument);
  CHECK(session.submitDepth({view, view}, {flat}, 0.0) == Status::invalid_argument);
  REQUIRE(session.waitWorkerIdle(10s));
  CHECK_FALSE(session.depthState(Hand::right).valid);
  // The depth targets are the session's own: not the caller's to move, remove or count.
  const uint64_t id = GraspSession::depthTarget(Hand::right);
  CHECK(session.placeTarget(id, 1, Pose{}) == Status::invalid_argument);
  CHECK_FALSE(session.removeTarget(id));
  CHECK(session.setupCounts().ready == 0);
}

TEST_CASE("Depth scene: a hand squeezed by a mug it only saw as depth closes on it",
          "[depth][session][grasp]") {
  const MugOnTable scene;
  DepthRig rig(scene, /*outer=*/false);
  const GridBox box = GridBox::referenceDefault();
  const MugTruth truth = mugTruth(scene);
  // As depth_scene_tests has them (depth_reaches.h).
  const int count = 20;
  const std::vector<Placement> placements = seenReaches(truth, rig.view, rig.model, box, count);

  int made = 0, heldDepth = 0, reportedContacts = 0;
  std::vector<float> penetrations, residuals;
  for (const Placement& pl : placements) {
    const Pose& atObject = pl.objectFromHand;
    // The reach: the open hand 8 cm back along the surface's normal, then at the placement, a
    // frame of depth fused at each (what the hand hides at the end was seen on the way in).
    const Pose back{atObject.orientation, atObject.position + 0.08f * pl.normal};
    rig.frame(back, 0.0f);
    rig.frame(back, 0.0f);
    rig.frame(atObject, 0.0f);
    rig.frame(atObject, 0.0f);
    REQUIRE(rig.session.depthState(Hand::right).valid);
    bool shown = false;
    for (int k = 0; k < 50 && !shown; ++k) {
      rig.frame(atObject, 1.0f);
      shown = rig.session.grasp(Hand::right).shown();
    }
    REQUIRE(shown);
    const HandGrasp& g = rig.session.grasp(Hand::right);
    if (g.target == GraspSession::depthTarget(Hand::right)) ++heldDepth;
    const TrueGrade grade = gradeOnTruth(truth, rig.model, atObject, g.result);
    for (int f = 0; f < kFingerCount; ++f) {
      if (!g.result.fingers[size_t(f)].contact) continue;
      residuals.push_back(std::abs(grade.clearanceMm[size_t(f)]));
      // What a finger touches is said: the depth scene, not a target of the caller's.
      if (g.touched[size_t(f)] == GraspSession::depthTarget(Hand::right)) ++reportedContacts;
    }
    const int touching = grade.touching;
    const float deepest = grade.deepestMm;
    made += touching >= 2 ? 1 : 0;
    penetrations.push_back(deepest);
    // Let go, and the next reach starts open.
    rig.frame(atObject, 0.0f);
    CHECK_FALSE(rig.session.grasp(Hand::right).holding);
  }
  const float penP99 = quantile(penetrations, 0.99), resMedian = quantile(residuals, 0.5);
  std::printf(
      "depth scene through the session (mug on a table, D24, head 40 cm away): %d reaches, %d "
      "grasps made, %d holding the depth scene; finger penetration into the true surfaces p99 "
      "%.2f mm, max %.2f mm; contact residual median %.2f mm, p95 %.2f mm; %d of %zu contacts "
      "said to be on the depth scene\n",
      count, made, heldDepth, penP99, quantile(penetrations, 1.0), resMedian,
      quantile(residuals, 0.95), reportedContacts, residuals.size());
  CHECK(heldDepth == count);
  CHECK(reportedContacts == int(residuals.size()));
  CHECK(penP99 <= 2.0f);
  CHECK(resMedian <= 1.5f);
  CHECK(made >= count * 3 / 4);
}

TEST_CASE("Depth scene: the outer hand keeps an open hand out of a table it only saw as depth",
          "[depth][session][outer]") {
  const MugOnTable scene;
  DepthRig rig(scene, /*outer=*/true);
  // Palm down beside the mug, lowered from 6 cm above the table top to 3 cm into it.
  JointPoses open;
  rig.model.pose(FingerCurls{}, open);
  const glm::vec3 palmLocal = open[size_t(Joint::palm)].position;
  const glm::quat down = glm::rotation(palmFacing(open[size_t(Joint::palm)]), glm::vec3(0, -1, 0));
  const glm::vec3 above(0.15f, 0.0f, 0.0f);
  float deepest = 0.0f, deepestTracked = 0.0f;
  for (float h = 0.06f; h >= -0.03f; h -= 0.002f) {
    const Pose wrist{down, above + glm::vec3(0.0f, h, 0.0f) - down * palmLocal};
    rig.frame(wrist, 0.0f);
    JointPoses drawn;
    JointRadii radii;
    placeJoints(rig.model, FingerCurls{}, wrist, drawn, radii);
    for (int j = 0; j < kJointCount; ++j)
      deepestTracked = std::max(deepestTracked, radii[size_t(j)] - drawn[size_t(j)].position.y);
    const ShownHand shown = takeShownHand(rig.session, Hand::right, HandOffset{}, 0.0f);
    drawGripHand(shown, wrist * wristFromGrip(rig.model), MotionRange::unobstructed, drawn, radii);
    // The table top is y = 0 (MugOnTable).
    for (int j = 0; j < kJointCount; ++j)
      deepest = std::max(deepest, radii[size_t(j)] - drawn[size_t(j)].position.y);
  }
  std::printf(
      "outer hand on the depth scene: an open hand lowered 3 cm into a table seen only as depth, "
      "drawn %.2f mm into it (tracked: %.2f mm)\n",
      1000.0 * deepest, 1000.0 * deepestTracked);
  CHECK(deepestTracked > 0.03f);
  CHECK(deepest <= 0.002f);
}
