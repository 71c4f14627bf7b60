// Grasping for one XR session: the graspable targets, and per hand a grab state machine that
// builds the grab-box SDF of the target in the hand and solves the finger curls.
//
// The layer feeds it one HandFrame per hand per frame (after the app syncs its actions) and
// reads back each hand's HandGrasp when the app locates joints. States per hand: open -> held
// when the squeeze reaches the grab threshold with a target in the grab box; held -> open when
// the squeeze drops below threshold * releaseRatio or the target goes away. While held, the grasp
// is solved again when the target moves relative to the hand or its vertices change.
// Not thread-safe: the owner serializes calls (the layer holds its session lock).
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "hand_model.h"
#include "mesh.h"
#include "mesh_distance.h"
#include "sdf_backend.h"
#include "sdf_grid.h"
#include "solver.h"
#include "status.h"

namespace sdfg {

struct GraspSettings {
  std::string solver = "paper";  // a strategy of createSolver() that reads the SDF
  SolverOptions solverOptions{};
  GridBox box = GridBox::referenceDefault();
  float grabThreshold = 0.7f;   // squeeze in (0, 1] that starts a grab
  float releaseRatio = 0.8f;    // the grab ends below grabThreshold * releaseRatio
  float moveTolerance = 5e-4f;  // metres a target may move relative to the hand before a re-solve
  float turnTolerance = 5e-3f;  // radians, likewise

  std::optional<Error> validate() const;
};

// One hand at one instant, in a common "world" space of the caller's choosing.
struct HandFrame {
  bool valid = false;    // the hand's pose is known this frame
  Pose worldFromWrist;   // the wrist joint
  float squeeze = 0.0f;  // grab input, 0..1
  // Tracked joints (world space) and radii, when the hand is tracked: the model is fitted to
  // them when a grab starts. Null for controller-driven hands (the default adult model).
  const JointPoses* trackedJoints = nullptr;
  const std::array<float, kJointCount>* trackedRadii = nullptr;
};

struct TargetFrame {
  uint64_t id = 0;
  bool valid = false;  // located this frame
  Pose worldFromObject;
};

struct HandGrasp {
  bool holding = false;
  uint64_t target = 0;
  GraspResult result{};  // contact points in hand space
  Pose objectFromHand;   // at the last solve
  uint64_t solves = 0;   // how many times this grab was solved
};

class GraspSession {
 public:
  explicit GraspSession(std::unique_ptr<SdfBackend> backend);
  ~GraspSession();
  GraspSession(const GraspSession&) = delete;
  GraspSession& operator=(const GraspSession&) = delete;

  // Validates and applies settings; they take effect from the next grab. Fails (and keeps the
  // old settings) on invalid values or a strategy that does not read the SDF.
  Status configure(const GraspSettings& settings);
  const GraspSettings& settings() const { return settings_; }

  // Targets are keyed by the caller's id; the mesh must have passed makeMesh().
  Status addTarget(uint64_t id, const TriangleMesh& mesh);
  // New positions, same count; a hand holding the target re-solves at its next update.
  Status updateTargetVertices(uint64_t id, std::span<const glm::vec3> positions);
  // Removes the target; a hand holding it lets go. Returns false for an unknown id.
  bool removeTarget(uint64_t id);
  bool hasTarget(uint64_t id) const { return targets_.count(id) != 0; }

  // Advances one hand. Returns the first error met while solving (the hand then stays open).
  Status update(Hand hand, const HandFrame& frame, std::span<const TargetFrame> targets);
  void release(Hand hand);

  const HandGrasp& grasp(Hand hand) const { return hands_[size_t(hand)].grasp; }
  // The model the hand's grasp was solved with (default adult until a tracked grab fits one).
  const HandModel& model(Hand hand) const { return hands_[size_t(hand)].model; }
  float lastSqueeze(Hand hand) const { return hands_[size_t(hand)].squeeze; }

 private:
  struct Target {
    std::unique_ptr<MeshDistance> distance;
    Aabb bounds;
    uint64_t version = 0;
  };
  struct HandState {
    HandModel model;
    std::unique_ptr<GraspSolver> solver;
    bool prepared = false;
    HandGrasp grasp;
    uint64_t solvedVersion = 0;
    float squeeze = 0.0f;
    SdfGrid grid;
  };

  Status solve(HandState& hand, const Target& target, const Pose& objectFromHand);
  std::optional<uint64_t> pickTarget(const Pose& worldFromWrist,
                                     std::span<const TargetFrame> targets) const;

  std::unique_ptr<SdfBackend> backend_;
  GraspSettings settings_;
  std::map<uint64_t, Target> targets_;
  std::array<HandState, 2> hands_;
};

}  // namespace sdfg
