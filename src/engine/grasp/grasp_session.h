// Grasping for one XR session: the graspable targets, and per hand a grab state machine that
// builds the grab-box SDF of the target in the hand and solves the finger curls.
//
// The layer feeds it one HandFrame per hand per frame (after the app syncs its actions) and
// reads back each hand's HandGrasp when the app locates joints. States per hand: open -> held
// when the squeeze reaches the grab threshold with a target in the grab box; held -> open when
// the squeeze drops below threshold * releaseRatio or the target goes away. While held, the grasp
// is solved again when the target moves relative to the hand or its vertices change.
//
// SDF builds: on the CPU backend during update(); or, with a DeferredSdfBackend (the app's Vulkan
// device), requested during update(), submitted by the owner through submitDeferred() where it
// may use the queue, and collected by a later update() (one frame or more of latency; a hand
// counts as holding from the request, its grasp has solves == 0 until the first result). While
// the deferred backend is not ready yet (preparing its pipelines at session start) a target with
// a CPU mesh is built on the CPU at once and a device target waits. After a failure of the
// deferred backend every build goes to the CPU; targets that exist only on the device
// (addDeviceTarget) can no longer be grasped.
// Not thread-safe: the owner serializes calls (the layer holds its session lock).
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "base/status.h"
#include "grasp/hand_clearance.h"
#include "grasp/solver.h"
#include "hand/hand_model.h"
#include "mesh/mesh.h"
#include "mesh/mesh_distance.h"
#include "sdf/sdf_backend.h"
#include "sdf/sdf_grid.h"

namespace sdfg {

struct GraspSettings {
  std::string solver = "paper";  // a strategy of createSolver() that reads the SDF
  SolverOptions solverOptions{};
  GridBox box = GridBox::referenceDefault();
  float grabThreshold = 0.7f;   // squeeze in (0, 1] that starts a grab
  float releaseRatio = 0.8f;    // the grab ends below grabThreshold * releaseRatio
  float moveTolerance = 5e-4f;  // metres a target may move relative to the hand before a re-solve
  float turnTolerance = 5e-3f;  // radians, likewise
  // Strategies that read GraspScene::exact ("ours") check their stops on the exact distance of
  // the target's mesh (targets with a CPU mesh; device targets have none): 0.1 mm contacts
  // instead of the 16^3 field's millimetres, at tens to hundreds of microseconds per solve.
  bool exactCheck = true;

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
  GraspResult result{};     // contact points in hand space
  Pose objectFromHand;      // at the last solve
  uint64_t solves = 0;      // how many times this grab was solved
  bool builtOnGpu = false;  // the SDF of the last solve came from the deferred (GPU) backend
};

// Where the session's grab-box SDFs were built so far.
struct SdfBuildStats {
  uint64_t gpuBuilds = 0;  // results collected from the deferred backend
  uint64_t cpuBuilds = 0;  // builds on the CPU backend
  bool gpuFailed = false;  // the deferred backend failed; the CPU builds from then on
};

class GraspSession {
 public:
  // `backend`: the CPU builder (always needed: headless sessions and the fallback). `deferred`:
  // optional device backend used first while it works.
  explicit GraspSession(std::unique_ptr<SdfBackend> backend,
                        std::unique_ptr<DeferredSdfBackend> deferred = nullptr);
  ~GraspSession();
  GraspSession(const GraspSession&) = delete;
  GraspSession& operator=(const GraspSession&) = delete;

  // Validates and applies settings; they take effect from the next grab. Fails (and keeps the
  // old settings) on invalid values or a strategy that does not read the SDF.
  Status configure(const GraspSettings& settings);
  const GraspSettings& settings() const { return settings_; }

  // Targets are keyed by the caller's id; the mesh must have passed makeMesh().
  Status addTarget(uint64_t id, const TriangleMesh& mesh);
  // A target whose mesh exists only in the deferred backend (registered there under `id`, e.g.
  // the app's Vulkan buffers). `bounds` (target frame) must contain the mesh at all times; it
  // decides whether the target is in a grab box. Errors: invalid_argument (id in use, bad
  // bounds), unsupported (no working deferred backend or it has no mesh `id`).
  Status addDeviceTarget(uint64_t id, const Aabb& bounds);
  // The mesh of a device target changed in place: a hand holding it re-solves.
  Status touchTarget(uint64_t id);
  // New bounds of a device target (see addDeviceTarget). Errors: invalid_argument.
  Status updateTargetBounds(uint64_t id, const Aabb& bounds);
  // New positions, same count; a hand holding the target re-solves at its next update.
  Status updateTargetVertices(uint64_t id, std::span<const glm::vec3> positions);
  // Removes the target; a hand holding it lets go. Returns false for an unknown id.
  bool removeTarget(uint64_t id);
  bool hasTarget(uint64_t id) const { return targets_.count(id) != 0; }

  // Advances one hand. Returns the first error met while solving (the hand then stays open).
  Status update(Hand hand, const HandFrame& frame, std::span<const TargetFrame> targets);
  void release(Hand hand);

  // Hands the requested builds to the deferred backend's device; with `sharedQueueFree` false
  // only those for a queue the backend owns (see DeferredSdfBackend::submit). A failure
  // switches the session to the CPU (the next update redoes the builds there).
  Status submitDeferred(bool sharedQueueFree);
  bool needsSubmit(bool sharedQueueFree) const {
    return deferredUsable() && deferred_->needsSubmit(sharedQueueFree);
  }
  bool deferredUsable() const { return deferred_ != nullptr && !deferred_->failed(); }
  // Whether the deferred backend takes builds now (see DeferredSdfBackend::ready: it may still
  // be preparing; array targets are then built on the CPU, device targets wait).
  bool deferredReady();
  DeferredSdfBackend* deferred() { return deferred_.get(); }
  // Whether targets added with a CPU mesh (addTarget) build on the deferred backend too (the
  // default) or on the CPU backend; device targets always use the deferred one.
  void setDeferredForMeshTargets(bool deferred) { deferredForMeshTargets_ = deferred; }
  // Drops the deferred backend (waits for its work in flight): before the device goes away.
  void dropDeferred();
  const SdfBuildStats& buildStats() const { return stats_; }
  // Hands whose deferred build was requested and not yet collected.
  int pendingBuilds() const { return int(hands_[0].pending) + int(hands_[1].pending); }

  const HandGrasp& grasp(Hand hand) const { return hands_[size_t(hand)].grasp; }
  // The model the hand's grasp was solved with (default adult until a tracked grab fits one).
  const HandModel& model(Hand hand) const { return hands_[size_t(hand)].model; }
  float lastSqueeze(Hand hand) const { return hands_[size_t(hand)].squeeze; }

 private:
  struct Target {
    std::unique_ptr<MeshDistance> distance;  // null for device targets
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
    // A deferred build requested for this hand, and the pose and version it was made for.
    bool pending = false;
    Pose pendingPose;
    uint64_t pendingVersion = 0;
    // A tracked hand's open-hand parts as the user holds it (wrist frame), cleared besides the
    // model's open hand (GraspScene::extraParts); 0 for a controller-driven hand.
    HandParts trackedParts{};
    int trackedPartCount = 0;
  };
  // Sets hand.trackedParts from the frame's tracked joints (none: count 0). Before a solve.
  static void noteTrackedParts(HandState& hand, const HandFrame& frame);

  Status solve(HandState& hand, size_t slot, uint64_t id, const Target& target,
               const Pose& objectFromHand);
  // `exactMesh`: the target's mesh for the exact check (null: none).
  Status solveWithGrid(HandState& hand, const Pose& objectFromHand, uint64_t version, bool gpu,
                       const MeshDistance* exactMesh);
  // Collects the hand's deferred build, if any; on a device failure redoes it on the CPU.
  Status collect(HandState& hand, size_t slot);
  void cancelPending(HandState& hand, size_t slot);
  std::optional<uint64_t> pickTarget(const Pose& worldFromWrist,
                                     std::span<const TargetFrame> targets) const;

  std::unique_ptr<SdfBackend> backend_;
  std::unique_ptr<DeferredSdfBackend> deferred_;
  bool deferredForMeshTargets_ = true;
  SdfBuildStats stats_;
  GraspSettings settings_;
  std::map<uint64_t, Target> targets_;
  std::array<HandState, 2> hands_;
};

}  // namespace sdfg
