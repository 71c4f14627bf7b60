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
// Set-ups run before hand jobs; the two slots take turns; a frame of the depth scene is fused
// when nothing else waits (requestDepth()).
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
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "base/pose.h"
#include "base/published.h"
#include "base/status.h"
#include "depth/depth_fusion.h"
#include "grasp/contact.h"
#include "grasp/hand_clearance.h"
#include "grasp/outer_hand.h"
#include "grasp/solver.h"
#include "hand/hand_model.h"
#include "mesh/mesh.h"
#include "mesh/mesh_distance.h"
#include "mesh/mesh_orientation.h"
#include "mesh/mesh_weld.h"
#include "scene/analytic_shape.h"
#include "scene/scene.h"
#include "sdf/sdf_backend.h"
#include "sdf/sdf_grid.h"

namespace sdfg {

// What a target's set-up found of its mesh, for the owner to tell the app once: the vertices it
// welded and triangles it dropped (weldByPosition), then the winding it repaired (orientOutward).
struct MeshSetupReport {
  WeldReport weld{};
  MeshOrientation orientation{};
};

class SceneExactSource;  // grasp/scene_exact_source.h

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
    // What the set-up found of the mesh (valid once ready): its split vertices and repeated
    // triangles (weldByPosition) and its winding (orientOutward); and the indices as it welded
    // and turned them outward when either changed anything (null: the app's were kept).
    MeshSetupReport found{};
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

  // One solid of a job's scene: a target and where it is relative to the hand.
  struct JobMember {
    uint64_t target = 0;
    Pose objectFromHand;
    bool graspable = false;  // the job's hand may take it
  };

  // One hand's build and solve, on the scene in its grab box.
  struct Job {
    uint64_t ticket = 0;  // echoed in the result; the owner drops results of older tickets
    // Every target in the grab box (scene/scene.h); members[0] is the one a GPU-built `field`
    // holds. Targets with neither a CPU mesh nor a shape (device buffers) take part only
    // through that field.
    std::vector<JobMember> members;
    // The target the hand holds: it keeps it whatever the fingers touch. 0: the grasp takes the
    // graspable target the closing hand touches (grasp/target_choice.h), or nothing.
    uint64_t held = 0;
    GridBox box;
    std::shared_ptr<SolverSetup> solver;
    bool exactCheck = true;  // give the solver the scene's exact distance
    // The longest the CPU build may take; past it the job ends with timed_out.
    std::chrono::milliseconds buildTimeLimit{1000};
    // A field of members[0] built elsewhere (the GPU): the others are merged into it on the CPU.
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
    // computeContacts() of `result` on the chosen target, done here, off the app's thread; a
    // finger that touches another target has no contact here (see `touched`).
    FingerContacts contacts{};
    int64_t time = 0;  // Job::time
    // The target the hand takes (Job::held when set); 0: it holds nothing (its fingers rest on
    // scene geometry, or on nothing).
    uint64_t chosen = 0;
    // Per finger, the target its contact is on (0: no contact).
    std::array<uint64_t, kFingerCount> touched{};
    Pose objectFromHand;   // the chosen target's, from the job (identity when none)
    uint64_t version = 0;  // the chosen target's vertex version the result was solved on
    // Every member's vertex version the result was solved on, in Job::members order.
    std::vector<uint64_t> versions;
    bool built = false;   // a grab-box SDF was built on the CPU for it
    bool reused = false;  // solved on the slot's last field, moved rigidly (nothing built)
    std::chrono::microseconds duration{0};
  };

  // One hand's outer hand for one frame (grasp/outer_hand.h): where the hand is shown so that it
  // stays outside every target near it. Short (a few hundred exact samples): the worker runs it
  // before any queued build, and a newer one replaces one not yet started.
  struct OuterJob {
    uint64_t ticket = 0;  // increasing per slot; echoed in OuterDone
    // The targets near the hand; JobMember::objectFromHand maps *world* points here (the
    // session's common space), not the hand's.
    std::vector<JobMember> members;
    Pose worldFromWrist;  // the tracked (or synthesized) wrist
    JointPoses joints{};  // the hand as it would be shown, wrist frame
    std::array<float, kJointCount> radii{};
    double time = 0.0;  // seconds
    // A held object: part of the hand (kept out of everything else, not out of itself). Its
    // surface is sampled here, once per target and vertex version.
    uint64_t attached = 0;
    Pose wristFromAttached;
    bool rigidFingers = false;  // OuterHandInput::rigidFingers
    Pose drawnOffset{};         // OuterHandInput::drawnOffset
    HandModel model = HandModel::defaultAdult(Hand::right);
    OuterHandOptions options{};
  };
  struct OuterDone {
    uint64_t ticket = 0;
    Status status = Status::ok;
    OuterHandResult result{};
    Pose trackedWrist;  // OuterJob::worldFromWrist: what the result's shown pose was solved for
    // The job's joints placed at the tracked wrist (world), and the attached parts' farthest
    // reach from the wrist: how far the tracked hand moved since (GraspSession's fast path).
    std::array<glm::vec3, kJointCount> trackedJoints{};
    std::array<float, kJointCount> radii{};
    float attachedReach = 0.0f;
    // Set-ups the worker had finished when it started the job (cumulative, as setupsDone()):
    // shows that a queued set-up did not delay it.
    uint64_t setupsBefore = 0;
    // What the session shows while the next answer is late (an app draws before the worker
    // answers its frame), so that the hand is not left the targets' motion since inside them. A
    // step is as long as from the job before to this one (`stepInterval` seconds; 0: nothing
    // moved); predicted[h] is the correction (world, applied after the shown wrist) that keeps
    // the shown hand out of the scene with its moving targets moved on kPredictedSteps[h] steps
    // as they moved in the step before (a worker late by several frames leaves several steps of
    // motion to cover); sceneMotion how far a part of a moving target moves in a step.
    double jobTime = 0.0;  // OuterJob::time
    static constexpr std::array<int, 4> kPredictedSteps{1, 2, 4, 8};
    std::array<Pose, 4> predicted{};
    // Where each target the job kept the hand out of was (world), and its farthest point from its
    // origin (0: unbounded): how far the targets moved since this answer, for the session to tell.
    struct Placed {
      uint64_t id = 0;
      Pose worldFromObject;
      float reach = 0.0f;
    };
    std::vector<Placed> placed;
    double stepInterval = 0.0;
    float sceneMotion = 0.0f;
  };
  // The newest finished outer-hand result of a slot, published by the worker and read from any
  // thread without waiting for the worker's work (the layer's xrLocateHandJointsEXT draws with a
  // result that finished after the update that asked for it).
  struct OuterMailbox {
    Published<OuterDone> latest;
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
  // A target that is an analytic shape (scene/analytic_shape.h): ready at once.
  void addShape(uint64_t id, const AnalyticShape& shape);
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

  // Leaves the outer-hand job of `slot` (replacing one not yet started).
  void requestOuter(size_t slot, OuterJob job);
  // Where the slot's outer-hand results are published (the same mailbox for the worker's life).
  std::shared_ptr<const OuterMailbox> outerMailbox(size_t slot) const {
    return outer_[slot].mailbox;
  }
  // Forgets the slot's outer-hand history (the hand left every target): the next job starts from
  // its tracked pose. Drops a queued job; a result of an older ticket may still be published, the
  // owner ignores it.
  void resetOuter(size_t slot);

  // The depth scene (depth/depth_fusion.h): one frame of the app's depth, fused into one volume
  // per slot around where that hand is. Fused when nothing else waits (a grab, a set-up or an
  // outer-hand job goes first), the newest frame replacing one not yet started: a worker slower
  // than the frames fuses fewer of them, never a backlog.
  struct DepthJob {
    std::vector<DepthView> views;
    std::vector<std::vector<float>> depth;  // views[i]'s stored values (DepthFusion::integrate)
    // Where each slot's cube is centred (world); nothing: that volume is left as it is.
    std::array<std::optional<glm::vec3>, kSlots> centres{};
    std::vector<DepthExclusion> hands;  // the spheres of every hand the app draws
    double time = 0.0;                  // seconds, not decreasing
  };
  // What a slot's volume target is after the last frame fused.
  struct DepthDone {
    bool valid = false;       // a frame was fused
    uint64_t version = 0;     // of the target (Resolved::version, Done::versions)
    Aabb bounds;              // the volume's, world frame
    size_t observed = 0;      // voxels observed and not forgotten
    size_t refusedViews = 0;  // views of the frame that integrate() refused
  };
  // Registers the depth scene's targets, one per slot (ready at once; empty until their first
  // frame), fused with `options`. Errors: invalid_argument (options refused, ids in use, or on
  // already).
  Status enableDepth(const std::array<uint64_t, kSlots>& ids, const DepthFusionOptions& options);
  void requestDepth(DepthJob job);
  // The state of every slot's volume after the newest frame fused since the last call, or
  // nothing (none fused, or the lock busy at that instant: poll again); never waits.
  std::optional<std::array<DepthDone, kSlots>> takeDepth();

  // While held, the worker starts no job (the one running finishes); queued jobs wait, newer
  // ones replace them as usual. For tests and tools that need a late worker (what a hand shows
  // while the worker's answer has not come) or a known order of jobs; the layer never holds it.
  void hold(bool held);

  // Waits until nothing is queued or running, at most `timeout`; false on timeout (always while
  // held with work queued). For tests and tools: the layer never waits for the worker.
  bool waitIdle(std::chrono::milliseconds timeout) const;
  // Set-ups and hand jobs finished so far (cumulative).
  uint64_t setupsDone() const;
  uint64_t jobsDone() const;

 private:
  struct Target {
    // Set when the target is removed or replaced, or the worker is destroyed: its set-up or
    // refit in flight stops (the object is dropped, so a half-refit one is never used again).
    std::atomic<bool> stop{false};
    std::shared_ptr<MeshDistance> distance;  // touched by the worker thread only
    std::optional<AnalyticShape> shape;      // a shape target (no mesh)
    // A depth scene's volume (owned by its fusion; worker thread only, like `distance`).
    const DistanceVolume* volume = nullptr;
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
    MeshSetupReport found{};
    std::shared_ptr<const std::vector<uint32_t>> orientedIndices;
    bool lastUpdateRefused = false;  // worker thread only: reports a run of refusals once
  };
  struct OuterSlot {
    std::optional<OuterJob> queued;
    bool reset = false;  // drop the history before the next job
    std::shared_ptr<OuterMailbox> mailbox = std::make_shared<OuterMailbox>();
    // Worker thread only: the history, and the held object's surface samples (object frame).
    std::unique_ptr<OuterHand> hand;
    uint64_t sampledTarget = 0;
    uint64_t sampledVersion = 0;
    std::vector<HandPart> samples;
    // The members of the last job run: whether the scene moved, or changed its shape, since.
    struct Seen {
      uint64_t id = 0;
      Pose objectFromHand;
      uint64_t version = 0;  // of the vertices
    };
    std::vector<Seen> lastScene;
    double lastJobTime = 0.0;  // OuterJob::time of the last job run
  };
  struct Slot {
    std::optional<Job> queued;
    bool running = false;
    uint64_t runningTicket = 0;
    std::vector<uint64_t> runningTargets;  // the running job's members
    uint64_t cancelledBelow = 0;           // results of tickets below this are dropped
    std::optional<Done> done;
  };

  // The spare pool: a job of a deforming target tops it up to kMinSpares before its refit, and
  // at most kMaxSpares are kept (the app fills one, one waits, the worker applies one).
  static constexpr size_t kMinSpares = 2;
  static constexpr size_t kMaxSpares = 3;
  // Moves `buffers` into the target's pool up to kMaxSpares (caller holds the mutex).
  static void keepSpares(Target& target, std::vector<std::vector<glm::vec3>>& buffers);

  // A job member's target as the job found it, with the new positions it applies first (a grasp
  // job before its build, an outer-hand job before it looks: a deforming target is seen as the
  // app last wrote it by either).
  struct Resolved {
    uint64_t id = 0;
    std::shared_ptr<Target> target;  // null: removed, or not set up
    std::optional<std::vector<glm::vec3>> positions;
    uint64_t version = 0;  // the vertex version the job sees
    size_t missingSpares = 0;
    std::optional<Aabb> refitBounds;
  };
  // Takes the target's waiting positions (caller holds the mutex; `target` set up).
  static Resolved resolve(uint64_t id, std::shared_ptr<Target> target);
  // Fills the pools of deforming targets (takes and releases the held lock around allocations).
  void fillSpares(std::unique_lock<std::mutex>& lock, std::span<Resolved> resolved);
  // Refits each target that has new positions (lock not held). Positions that collapse a
  // triangle are refused (the first of a run into `refused`) and the last shape stays whole;
  // timed_out when a target is being dropped.
  static Status refit(std::span<Resolved> resolved,
                      std::vector<std::pair<uint64_t, std::string>>& refused);
  // Records what the refits applied and returns their buffers to the pools (caller holds the
  // mutex).
  void commitRefits(std::span<Resolved> resolved,
                    std::vector<std::pair<uint64_t, std::string>>& refused);

  void run();
  void runSetup(std::unique_lock<std::mutex>& lock, uint64_t id, std::shared_ptr<Target> target);
  void runJob(std::unique_lock<std::mutex>& lock, size_t slot, Job job);
  void runOuter(std::unique_lock<std::mutex>& lock, size_t slot, OuterJob job);
  void runDepth(std::unique_lock<std::mutex>& lock, DepthJob job);
  // Anything queued (the caller holds the mutex).
  bool anyQueued() const;
  // A job member as the exact source and the field read it: the target's mesh or shape (the
  // caller keeps the target alive while the member is used).
  static SceneMember sceneMember(const JobMember& m, const Target& t);
  // After the solve: which target the hand takes, what each finger touches, and the contacts on
  // the target taken (Done::chosen, touched, contacts, objectFromHand, version).
  static void chooseAndContact(const Job& job, std::span<const SceneMember> scene,
                               std::span<const size_t> sceneIndex, const SceneExactSource& exact,
                               const SdfGrid* field, Done& done);

  // The field a slot built last, for what it was built (worker thread only). A later job of the
  // same target and vertices whose whole box, moved rigidly to the new relative pose, still lies
  // inside it solves on it (GraspScene::fieldFromHand) instead of building: a rigid motion does
  // not change the object, only where the box sits on it. Once a target moves in the hand, its
  // fields are built in a grown box (two spacings more on every side) so that the next motions
  // fit.
  struct BuiltField {
    SdfGrid grid;
    bool valid = false;
    std::vector<uint64_t> targets;   // the scene's members
    std::vector<uint64_t> versions;  // their vertex versions
    std::vector<Pose> objectFromHand;
    GridBox jobBox;  // the box the job asked for (the grid's may be grown)
  };
  // The map from the job's hand frame into the field's, when the field covers the job: the same
  // members at the same versions, all moved by one rigid motion relative to the hand.
  static std::optional<Pose> reuseMap(const BuiltField& built, const Job& job,
                                      std::span<const uint64_t> versions);

  std::unique_ptr<SdfBackend> backend_;  // worker thread only
  std::array<BuiltField, kSlots> fields_;
  std::array<SdfGrid, kSlots> scratch_;  // the scene field's per-member builds

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
  std::array<OuterSlot, kSlots> outer_;
  struct DepthState {
    bool enabled = false;
    std::array<uint64_t, kSlots> ids{};
    std::array<std::optional<DepthFusion>, kSlots> fusion;  // worker thread only once enabled
    std::optional<DepthJob> queued;
    std::array<DepthDone, kSlots> done{};
    bool fresh = false;  // done changed since the last takeDepth()
  } depth_;
  size_t nextSlot_ = 0;
  size_t nextOuter_ = 0;       // the outer slots take turns too
  bool lastRanOuter_ = false;  // a queued grab runs before the next outer job
  bool busy_ = false;
  bool held_ = false;  // hold()
  uint64_t setupsDone_ = 0;
  uint64_t jobsDone_ = 0;
  std::vector<std::pair<uint64_t, std::string>> refusedUpdates_;

  std::thread thread_;  // last: started after every member above exists
};

}  // namespace sdfg
