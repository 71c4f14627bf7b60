// The "ours" grasp strategy: the paper's SDF method with its section 5 limits removed.
//
// - Whole finger: spheres sampled along every phalanx (proximal phalanx to tip, spaced by the
//   joint radii) are tested, not just the tip, and each joint stops on its own: when a sphere on
//   a bone touches, the joints that move that bone stop and the more distal joints keep closing,
//   so a finger wraps around a handle instead of stopping at the first touch.
// - No tunnelling: each finger advances by the distance bound the sampled field gives
//   (conservative advancement with a precomputed bound on every sphere's speed along the curl),
//   so no feature the field resolves is skipped, whatever SolverOptions::da.
// - Exact stop: the contact is bracketed and refined by regula falsi on the trilinear field to
//   within kContactTolerance of the threshold (the outside end of the bracket), then polished by
//   a few secant steps on a curvature-corrected reconstruction of the same nodes (trilinear minus
//   its leading h^2 error term), which is what takes a 16^3 field from about 1 mm to about
//   0.1 mm of the true surface on smooth parts. Every pose is checked against the field it
//   stops on: no sphere ends inside it.
// - Exact check (when GraspScene::exact is set): the field's error near curved and sharp parts
//   (millimetres at 16^3) is removed where it matters. After each joint group stops on the
//   field, the spheres it moved that the field puts within kExactBand of touching are sampled
//   exactly (bounded searches), their clearance measured against their own capsule, and the
//   group's curl corrected by Newton steps on that exact clearance until the closest one is
//   within kContactTolerance of touching and none is inside (opening further if needed). Each
//   sample also gives the exact slope of its clearance along the curl (the unit vector from the
//   closest point against the centre's velocity), so a step errs only by the surface's
//   curvature over the motion. The field's own polish is skipped then; without a source
//   nothing changes. A candidate is not sampled while its field clearance minus kFieldTrust
//   (solver_ours_detail.h) cannot beat the closest one found, except at the poses where the stop
//   is decided, where every candidate is; each search is seeded with the sphere's last closest
//   feature (ExactSample::feature). The field's stop is then only refined to 0.5 mm (the field's
//   own error). Every moving sphere within the band is a candidate, whichever bone it is on: the
//   first to touch on the exact surface stops the group.
// - Approach (optional, SolverOptions::approach): approachPose() follows the field's gradient
//   from the palm to turn and move the hand onto the surface before the fingers close.
// - Never inside (SolverOptions::clearance, on by default): an open hand with any part inside
//   the target is first moved out by the smallest rigid correction (clearHand(),
//   hand_clearance.h), then the fingers close from there. The thumb's metacarpal, which turns
//   as the hand closes, is sampled along its length like a phalanx.
//
// Holding a moving or deforming target lives in grasp_holder.h. solve() never allocates.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "base/pose.h"
#include "base/status.h"
#include "grasp/hand_clearance.h"
#include "grasp/solver.h"
#include "hand/hand_model.h"
#include "sdf/sdf_grid.h"

namespace sdfg {

struct ApproachOptions {
  float targetDistance = -1.0f;  // palm joint centre to surface, metres; < 0: palm radius + 5 mm
  float tolerance = 0.0005f;     // stop once |distance - target| is below this (metres)...
  float angleTolerance = 0.02f;  // ...and the palm is this close to facing the surface (radians)
  float maxStep = 0.03f;         // largest move per iteration, metres
  float maxTurn = 0.5f;          // largest turn per iteration, radians
  int maxIterations = 32;
};

struct ApproachResult {
  // Maps points of the corrected hand frame into the hand frame the field was built in
  // (oldHandFromNewHand). Identity when the palm already faces the surface at the target.
  Pose handCorrection;
  float distance = 0.0f;  // sampled distance at the palm joint after the correction
  float angle = 0.0f;     // angle between the palm normal and the surface direction, radians
  int iterations = 0;
  bool converged = false;
};

// Moves and turns the hand so the palm faces the surface the field describes: each iteration
// samples the field and its gradient at the palm joint (open hand), turns the hand about the
// palm so its palm normal (-Y of the palm joint) points down the gradient, and moves it along
// the gradient to `targetDistance`. Pure function of its inputs. Fails on invalid options; a
// field whose gradient vanishes at the palm (no surface direction) leaves the pose unchanged
// and reports converged = false.
Result<ApproachResult> approachPose(const SdfGrid& field, const HandModel& hand,
                                    const ApproachOptions& options = {});

class OursSolver final : public GraspSolver {
 public:
  // Most spheres tested per finger, and the number of rotating joints per finger.
  static constexpr int kMaxSpheres = 40;
  static constexpr int kMaxJoints = 4;
  // A finger is in contact once its closest sphere is within this of its threshold.
  static constexpr float kContactTolerance = 0.0001f;  // metres
  // Exact check: spheres the field puts within this of touching are sampled exactly.
  static constexpr float kExactBand = 0.004f;  // metres

  std::string_view name() const override { return "ours"; }
  bool needsField() const override { return true; }
  bool needsCollider() const override { return false; }

  Status prepare(const HandModel& hand, const GridBox& box, const SolverOptions& options) override;
  Status solve(const GraspScene& scene, GraspResult& out) const override;

  // Why the last prepare() failed; empty after a successful one.
  std::string_view prepareError() const override { return error_; }
  std::string_view lastError() const { return error_; }

 private:
  struct Sphere {
    uint8_t bone = 0;         // rotating joint that moves it last (index into fingerJoints())
    float t = 0.0f;           // position between the bone's start joint (0) and its end joint (1)
    float radius = 0.0f;      // capsule radius there (the finger's surface)
    float testRadius = 0.0f;  // radius + cover margin + threshold offset: the stop distance
  };
  // One finger's rotating joints, from the slerp between its open and closed local rotations:
  // q(a) = open * (cos(a*angle/2), sin(a*angle/2) * axis).
  struct JointRig {
    glm::quat open{1.0f, 0.0f, 0.0f, 0.0f};
    glm::vec3 axis{1.0f, 0.0f, 0.0f};
    float angle = 0.0f;
    glm::vec3 offset{0.0f};  // joint position in the parent frame (hand space for joint 0)
  };
  struct FingerRig {
    int joints = 0;  // rotating joints (3 for the thumb, 4 for the others)
    std::array<JointRig, kMaxJoints> rig{};
    glm::vec3 tipOffset{0.0f};  // tip position in the last rotating joint's frame
    int sphereCount = 0;
    std::array<Sphere, kMaxSpheres> spheres{};
    // speed[f][i]: bound on |d centre / d a| of sphere i when joints f.. move together.
    std::array<std::array<float, kMaxSpheres>, kMaxJoints> speed{};
    std::array<float, kMaxJoints> minStep{};  // smallest curl step per stage (0.5 mm of motion)
    std::array<float, kMaxJoints> maxJump{};  // largest secant jump per stage
    int tipSphere = 0;
    std::array<float, kMaxJoints + 1> jointRadius{};  // capsule radius at each joint
    float thresholdOffset = 0.0f;                     // SolverOptions::threshold - tip radius
    bool ownKinematics = true;  // false: the model's curve is not a per-joint slerp; ask it
  };
  struct Eval;
  struct Stage;

  float stage(Stage& st, JointCurls& curls, float a, int& touching, glm::vec3& touchPoint,
              float& touchValue) const;
  void evaluate(Stage& st, const JointCurls& curls, float a, Eval& e, bool corrected) const;
  float polish(Stage& st, JointCurls& curls, float a, Eval& e) const;
  void jointPositions(int finger, const JointCurls& curls,
                      std::array<glm::vec3, kMaxJoints + 1>& hand) const;
  struct ExactContext;
  float exactStop(const ExactContext& cx, int finger, int firstFree, float a, JointCurls& curls,
                  int& touching, glm::vec3& touchPoint, float& touchValue, int& samples) const;

  HandModel hand_{};
  // The open hand's parts and its palm, for the clearance before the fingers close.
  HandParts parts_{};
  int partCount_ = 0;
  glm::vec3 palm_{0.0f};
  GridBox box_{};
  SolverOptions options_{};
  bool prepared_ = false;
  std::string error_;
  std::array<FingerRig, kFingerCount> fingers_{};
};

}  // namespace sdfg
