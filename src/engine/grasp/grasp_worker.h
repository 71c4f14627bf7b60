// The thread a GraspSession runs its CPU work on, so that no call of the app's waits for an SDF
// build or a solve (DESIGN.md section 3: "The app's frame is not the layer's to spend").
//
// It owns the exact-distance structure (MeshDistance: BVH and pseudo-normals) of every target
// registered with CPU arrays, and is the only thread that touches it: the set-up
// (MeshDistance::create), the refit after new vertices, the grab-box SDF builds and the solves
// with their exact check all run here. The owner's thread only hands work over and takes
// finished results, under a mutex held for copies and moves, never for a build:
// - addTarget() queues the set-up of a mesh; targetInfo() says when it is ready (or failed);
// - updateVertices() leaves the newest positions for the next build of that target (latest wins:
//   positions nobody builds with are never refit);
// - request() leaves one job per hand slot (latest wins: a job not yet started is replaced, so the
//   queue never grows); take() returns the newest finished result of a slot, if any, at once.
// Set-ups run before hand jobs; the two slots take turns.
//
// Lifecycle: the destructor sets its stop flags, wakes the thread and joins it, and queued work
// is dropped. Whatever runs then stops at its next look at a WorkLimit: a grab-box build at its
// next row of nodes, a set-up (the mesh check, the winding, MeshDistance::create) or a refit
// within a few thousand triangles, so the join takes milliseconds, not the second a set-up of a
// million triangles takes (docs/threading.md gives the measured bound). A build also stops when
// its slot is cancelled or its target removed, and when it passes the job's buildTimeLimit (its
// result then says timed_out); a set-up or refit stops when its target is removed. Removing a
// target while a job reads it is safe: the job holds its own reference. A job that throws (out
// of memory) or fails reports its status in its result; the worker carries on.
// Thread-safe: every public function may be called from any thread, while the worker runs.
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "base/pose.h"
#include "base/status.h"
#include "grasp/contact.h"
#include "grasp/hand_clearance.h"
#include "grasp/solver.h"
#include "hand/hand_model.h"
#include "mesh/mesh.h"
#include "mesh/mesh_distance.h"
#include "mesh/mesh_orientation.h"
#include "sdf/sdf_backend.h"
#include "sdf/sdf_grid.h"

namespace sdfg {

enum class TargetSetup {
  unknown,  // no such target
  pending,  // queued or running on the worker: not graspable yet
  ready,
  failed,  // MeshDistance::create failed (TargetInfo::error says why)
};

class GraspWorker {
 public:
  static constexpr size_t kSlots = 2;

  struct TargetInfo {
    TargetSetup setup = TargetSetup::unknown;
    Aabb bounds;        // of the positions last set up or refit (valid once ready)
    std::string error;  // why the set-up failed
    // What the set-up found of the mesh's winding (orientOutward, valid once ready), and the
    // indices it turned outward when it flipped any (null: the app's were outward already).
    MeshOrientation orientation{};
    std::shared_ptr<const std::vector<uint32_t>> orientedIndices;
  };

  // A solver and what to prepare it with. The worker prepares it before its first solve (the
  // finger rigs of "ours" take up to about a millisecond: not the app's to spend); from then on
  // it is only read (solve() is const and does not allocate), so later jobs share it. The owner
  // never touches a setup it handed over; it makes a new one when the model or settings change.
  struct SolverSetup {
    std::shared_ptr<GraspSolver> solver;
    HandModel model;
    GridBox box;
    SolverOptions options;
    bool prepared = false;  // worker thread only
    Status prepareStatus = Status::ok;
    // Worker thread only: whether the solver can solve on a field built at another relative
    // pose (GraspScene::fieldFromHand; "ours" without the approach).
    bool reusesFields = false;
  };

  // One hand's build and solve.
  struct Job {
    uint64_t ticket = 0;  // echoed in the result; the owner drops results of older tickets
    uint64_t target = 0;
    Pose objectFromHand;
    GridBox box;
    std::shared_ptr<SolverSetup> solver;
    bool exactCheck = true;  // give the solver the target's exact distance
    // The longest the CPU build may take; past it the job ends with timed_out.
    std::chrono::milliseconds buildTimeLimit{1000};
    // A field built elsewhere (the GPU): solve on it, build nothing.
    std::optional<SdfGrid> field;
    int64_t time = 0;  // the frame time the hand and target poses belong to, echoed in Done
    // A tracked hand's open-hand parts to clear besides the model's (GraspScene::extraParts).
    HandParts extraParts{};
    int extraPartCount = 0;
  };

  struct Done {
    uint64_t ticket = 0;
    Status status = Status::ok;
    GraspResult result{};
    FingerContacts contacts{};  // computeContacts() of `result`, done here, off the app's thread
    int64_t time = 0;           // Job::time
    Pose objectFromHand;
    uint64_t version = 0;  // the target's vertex version the result was solved on
    bool built = false;    // a grab-box SDF was built on the CPU for it
    bool reused = false;   // solved on the slot's last field, moved rigidly (nothing built)
    std::chrono::microseconds duration{0};
  };

  // `backend`: the CPU grab-box builder the worker uses (one thread is the session's default:
  // the worker must not starve an app on a 2-core machine).
  explicit GraspWorker(std::unique_ptr<SdfBackend> backend);
  ~GraspWorker();
  GraspWorker(const GraspWorker&) = delete;
  GraspWorker& operator=(const GraspWorker&) = delete;

  // Queues the set-up of `mesh` under `id`; replaces a target of that id. The set-up validates
  // the mesh (validateMesh: the app's thread checks only what it can in one streaming pass), and
  // fails with its message when it is refused.
  void addTarget(uint64_t id, TriangleMesh mesh);
  // New positions (same count as the mesh) of vertex version `version`; applied before the next
  // build of the target. Unknown ids are ignored. Positions that collapse a triangle are refused
  // when they are applied: the target keeps its last shape (takeRefusedUpdates says so).
  void updateVertices(uint64_t id, std::vector<glm::vec3> positions, uint64_t version);
  // Targets whose positions were refused since the last call, with the reason; a run of refused
  // updates of a target is reported once, at its first.
  std::vector<std::pair<uint64_t, std::string>> takeRefusedUpdates();
  // A buffer for the next updateVertices() of `id`: one the worker is done with, of the mesh's
  // size when it has one (so filling it allocates nothing and touches no new pages), else empty.
  std::vector<glm::vec3> spareBuffer(uint64_t id);
  void removeTarget(uint64_t id);
  TargetInfo targetInfo(uint64_t id) const;

  // Leaves `job` for `slot`, replacing a job of the slot not yet started.
  void request(size_t slot, Job job);
  // Drops the slot's queued job and any finished result; a running one's result is dropped when
  // it ends.
  void cancel(size_t slot);
  // The slot's newest finished result, or nothing; never waits (nothing either when the lock is
  // busy at that instant: poll again).
  std::optional<Done> take(size_t slot);

  // Waits until nothing is queued or running, at most `timeout`; false on timeout. For tests and
  // tools: the layer never waits for the worker.
  bool waitIdle(std::chrono::milliseconds timeout) const;
  // Set-ups and hand jobs finished so far (cumulative).
  uint64_t setupsDone() const;
  uint64_t jobsDone() const;

 private:
  struct Target {
    // Set when the target is removed or replaced, or the worker is destroyed: its set-up or
    // refit in flight stops (the object is dropped, so a half-refit one is never used again).
    std::atomic<bool> stop{false};
    std::shared_ptr<MeshDistance> distance;           // touched by the worker thread only
    std::optional<TriangleMesh> setupMesh;            // waiting for its set-up
    std::optional<std::vector<glm::vec3>> positions;  // waiting for the next build
    // Used positions buffers, handed out again (spareBuffer). Three circulate for a mesh that
    // deforms every frame (the app fills one, one waits, the worker applies one), so after the
    // first updates nothing is allocated on the app's thread.
    std::vector<std::vector<glm::vec3>> spares;  // kMinSpares..kMaxSpares once in use
    uint64_t positionsVersion = 0;
    uint64_t appliedVersion = 0;
    TargetSetup setup = TargetSetup::pending;
    Aabb bounds;
    std::string error;
    MeshOrientation orientation{};
    std::shared_ptr<const std::vector<uint32_t>> orientedIndices;
    bool lastUpdateRefused = false;  // worker thread only: reports a run of refusals once
  };
  struct Slot {
    std::optional<Job> queued;
    bool running = false;
    uint64_t runningTicket = 0;
    uint64_t runningTarget = 0;
    uint64_t cancelledBelow = 0;  // results of tickets below this are dropped
    std::optional<Done> done;
  };

  // The spare pool: a job of a deforming target tops it up to kMinSpares before its refit, and
  // at most kMaxSpares are kept (the app fills one, one waits, the worker applies one).
  static constexpr size_t kMinSpares = 2;
  static constexpr size_t kMaxSpares = 3;
  // Moves `buffers` into the target's pool up to kMaxSpares (caller holds the mutex).
  static void keepSpares(Target& target, std::vector<std::vector<glm::vec3>>& buffers);

  void run();
  void runSetup(std::unique_lock<std::mutex>& lock, uint64_t id, std::shared_ptr<Target> target);
  void runJob(std::unique_lock<std::mutex>& lock, size_t slot, Job job);

  // The field a slot built last, for what it was built (worker thread only). A later job of the
  // same target and vertices whose whole box, moved rigidly to the new relative pose, still lies
  // inside it solves on it (GraspScene::fieldFromHand) instead of building: a rigid motion does
  // not change the object, only where the box sits on it. Once a target moves in the hand, its
  // fields are built in a grown box (two spacings more on every side) so that the next motions
  // fit.
  struct BuiltField {
    SdfGrid grid;
    bool valid = false;
    uint64_t target = 0;
    uint64_t version = 0;
    Pose objectFromHand;
    GridBox jobBox;  // the box the job asked for (the grid's may be grown)
  };
  // The map from the job's hand frame into the field's, when the field covers the job.
  static std::optional<Pose> reuseMap(const BuiltField& built, const Job& job, uint64_t version);

  std::unique_ptr<SdfBackend> backend_;  // worker thread only
  std::array<BuiltField, kSlots> fields_;

  // Set to stop the build a slot's job runs (WorkLimit::stop): by cancel() and removeTarget() of
  // the job's target, and by the destructor; cleared when the slot's next job starts.
  std::array<std::atomic<bool>, kSlots> stopBuild_{};

  mutable std::mutex mutex_;  // guards everything below
  mutable std::condition_variable wake_;
  mutable std::condition_variable idle_;
  bool stop_ = false;
  std::map<uint64_t, std::shared_ptr<Target>> targets_;
  std::deque<uint64_t> setups_;
  std::array<Slot, kSlots> slots_;
  size_t nextSlot_ = 0;
  bool busy_ = false;
  uint64_t setupsDone_ = 0;
  uint64_t jobsDone_ = 0;
  std::vector<std::pair<uint64_t, std::string>> refusedUpdates_;

  std::thread thread_;  // last: started after every member above exists
};

}  // namespace sdfg
