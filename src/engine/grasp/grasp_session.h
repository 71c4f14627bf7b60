// Grasping for one XR session: its targets (the scene), and per hand a grab state machine that
// builds the grab-box SDF of everything in the hand's grab box and solves the finger curls.
//
// Targets are meshes (CPU arrays or device buffers) or analytic shapes (scene/analytic_shape.h),
// each with a role (scene/scene.h: graspable, scene geometry only, ignored) and a placement (a
// space key and a pose in it). A broad phase over their bounds (scene/scene_index.h) finds the
// ones in a grab box without a loop over all of them.
//
// The layer feeds it the frame's space poses and one HandFrame per hand per frame (after the app
// syncs its actions) and reads back each hand's HandGrasp when the app locates joints. States
// per hand: open -> closed when the squeeze reaches the grab threshold with any target in the
// grab box. The fingers close on the union of every target there (each hand part stops on the
// first surface it meets, whoever owns it), and each solve takes the graspable target most
// fingers touch (grasp/target_choice.h), which the hand then keeps until the release; while the
// fingers touch only scene geometry the hand holds nothing (they still rest on it), and takes a
// graspable target at the first solve that touches one. closed -> open
// when the squeeze drops below threshold * releaseRatio or the held target goes away. While
// closed, the grasp is solved again when anything in the box moves relative to the hand, comes or
// goes, or changes its vertices.
//
// The outer hand (settings.outerHand): in every frame, whether the user squeezes or not, each
// hand near a target is kept outside every target near it (grasp/outer_hand.h, run on the
// worker; grasp/outer_view.h says how a frame is drawn before its result is in). The grab logic
// then works with the hand where it is shown: a grab starts from the outer hand, not from inside
// the table, and a held target counts as part of the hand (it is kept out of the rest).
//
// Threading: a GraspWorker owned by the session runs the target set-up (addTarget returns at
// once; the target is graspable once targetSetup() says ready), the refit after new vertices, the
// CPU builds and every solve with its exact check; update() only hands the frame's poses over and
// takes the newest finished result, never waiting. Until a newer result arrives a hand keeps its
// last solve (reposeCorrection() says how to keep it on a target that moved since). Tests and
// tools wait for outcomes (waitWorkerIdle, or a deadline), never for a number of updates.
//
// SDF builds: on the CPU backend, on the worker; or, with a DeferredSdfBackend (the app's Vulkan
// device), requested during update(), submitted by the owner through submitDeferred() where it
// may use the queue, collected by a later update() and solved on the worker (one frame or more of
// latency; a hand counts as holding from the request, its grasp is not shown() until the first
// result). While the deferred backend is not ready yet (preparing its pipelines at session start)
// a target with a CPU mesh is built on the CPU at once and a device target waits. After a failure
// of the deferred backend every build goes to the CPU; targets that exist only on the device
// (addDeviceTarget) can no longer be grasped.
// Not thread-safe: the owner serializes calls (the layer holds its session lock, which it never
// holds across a call into the runtime or Vulkan: docs/threading.md).
#pragma once

#include <chrono>

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "base/status.h"
#include "grasp/contact.h"
#include "grasp/grasp_worker.h"
#include "grasp/hand_clearance.h"
#include "grasp/outer_hand.h"
#include "grasp/outer_view.h"
#include "grasp/solver.h"
#include "hand/hand_model.h"
#include "mesh/mesh.h"
#include "mesh/mesh_distance.h"
#include "scene/analytic_shape.h"
#include "scene/scene.h"
#include "scene/scene_index.h"
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
  // The longest a grab-box SDF build may run before it is given up (the hand stays open, the
  // caller logs why once, and the hand grabs again only after a release): a mesh the BVH serves
  // badly (a soup of large intersecting triangles) must not keep a hand waiting for seconds, nor
  // a device build that never completes. CPU builds on the worker stop at it; a deferred (GPU)
  // build still not collected after it is cancelled. Positive.
  std::chrono::milliseconds buildTimeLimit{1000};
  // The outer hand: the shown hand stays outside every target near it in every frame. Off in
  // the engine (its tools and tests compare solvers on the hand as given); the layer turns it on
  // for apps (docs/layer.md says why). Takes effect at the next update.
  bool outerHand = false;
  OuterHandOptions outerOptions{};

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
  // The caller's time stamp of this frame (the layer: the predicted display time the poses were
  // located at), handed back as HandGrasp::time of the solves made from it.
  int64_t time = 0;
  // The grasp's offset the hand is drawn with (wrist frame; grasp/hand_offset_blend.h, as of the
  // caller's last frame): the outer hand keeps the hand out where it is drawn.
  Pose graspOffset{};
};

// A target located in its own right this frame (the older form of update(): each target is
// its own space). The layer places targets in spaces and passes SpaceFrames instead.
struct TargetFrame {
  uint64_t id = 0;
  bool valid = false;  // located this frame
  Pose worldFromObject;
};

struct HandGrasp {
  // The grasp the hand shows: closed, with a first solve in. (Closed alone is the time between
  // the squeeze and that solve, when the hand still shows the user's own pose.)
  bool shown() const { return holding && solves > 0; }
  // The hand shows a grasp that holds a target (not only fingers resting on scene geometry).
  bool holdsTarget() const { return shown() && target != 0; }

  bool holding = false;  // closed: the squeeze started a grab that has not ended
  uint64_t target = 0;   // the target held; 0: none (yet, or the fingers touch no graspable one)
  // Per finger (thumb first), the target its contact is on at the last solve (0: none).
  std::array<uint64_t, kFingerCount> touched{};
  GraspResult result{};     // contact points in hand space
  Pose objectFromHand;      // at the last solve
  uint64_t solves = 0;      // how many times this grab was solved
  bool builtOnGpu = false;  // the SDF of the last solve came from the deferred (GPU) backend
  // Per finger, where it touches the target (target frame), computed at each solve: exact on
  // targets with a CPU mesh, from the field on device targets (contact.h).
  FingerContacts contacts{};
  int64_t time = 0;  // HandFrame::time of the frame whose poses the last solve used
};

// Where the session's grab-box SDFs were built so far.
struct SdfBuildStats {
  uint64_t gpuBuilds = 0;     // results collected from the deferred backend
  uint64_t cpuBuilds = 0;     // builds on the CPU backend
  uint64_t reusedFields = 0;  // solves on an earlier CPU field moved rigidly (no build; worker)
  bool gpuFailed = false;     // the deferred backend failed; the CPU builds from then on
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

  // Targets are keyed by the caller's id; the arrays need only have passed the checks one
  // streaming pass makes (counts, finite coordinates, indices in range): the set-up (the rest of
  // validateMesh, the winding, bounds, BVH, exact distance) runs on the worker. The target is not
  // graspable until targetSetup() says ready; a set-up failure is reported once by
  // takeSetupFailures().
  // On a session whose deferred backend builds mesh targets too, it gets its own copy of the
  // arrays: `deviceCopy` when given (the same arrays, copied by a caller that holds a lock before
  // taking it), else a copy made here.
  Status addTarget(uint64_t id, TriangleMesh mesh, SharedMesh deviceCopy = {});
  // ready for device targets at once.
  TargetSetup targetSetup(uint64_t id) const;
  // What each set-up finished since the last call found of its mesh: split vertices welded,
  // repeated triangles dropped, the winding (the worker turns every part outward); for the owner
  // to report once.
  std::vector<std::pair<uint64_t, MeshSetupReport>> takeSetupReports();
  // Targets whose set-up failed since the last call, with the reason (each reported once).
  std::vector<std::pair<uint64_t, std::string>> takeSetupFailures();
  // Targets whose new vertices the worker refused since the last call (a triangle collapsed to
  // zero area), with the reason. The target keeps its last accepted shape; a run of refused
  // updates is reported once, at its first.
  std::vector<std::pair<uint64_t, std::string>> takeRefusedUpdates();
  // How many targets are set up, still being set up, failed (without a loop over the targets).
  // A device target counts as being set up until its first readback is (see addDeviceTarget).
  struct SetupCounts {
    size_t ready = 0, pending = 0, failed = 0;
  };
  SetupCounts setupCounts();
  // Waits until the worker has nothing queued or running, at most `timeout` (tests and tools
  // only; false on timeout).
  bool waitWorkerIdle(std::chrono::milliseconds timeout) const;
  // Holds the worker (GraspWorker::hold): tests and tools that show what a hand gets while the
  // worker's answer is late. The layer never holds it.
  void holdWorker(bool held);
  // A target whose mesh exists only in the deferred backend (registered there under `id`, e.g.
  // the app's Vulkan buffers). `bounds` (target frame) must contain the mesh at all times; it
  // decides whether the target is in a grab box. Errors: invalid_argument (id in use, bad
  // bounds), unsupported (no working deferred backend or it has no mesh `id`).
  // Where the backend reads meshes back (DeferredSdfBackend::requestReadback), the device mesh
  // is read back at once and set up on the worker like a CPU mesh: from then on the target is a
  // mesh like any other (exact stops and contacts, a member of scenes, the outer hand sees it),
  // built on the GPU from that copy, and every change the owner reports (touchTarget) is read
  // back again while the target is within kReadbackReach of a hand (farther, when it comes
  // near). What the hands see of a deforming device mesh is then one readback behind the app's
  // last write: a frame or two. Until its first readback is set up (or where there is none) it
  // takes part through the GPU's grab-box field only, as members[0] of a scene.
  Status addDeviceTarget(uint64_t id, const Aabb& bounds);
  // The mesh of a device target changed in place: a hand holding it re-solves (once the
  // readback of the change is in, for a target that has one).
  Status touchTarget(uint64_t id);
  // What readbacks found since the last call, one sentence per target for the owner to log: a
  // mesh the worker refused (the target goes on through its grab-box field only), triangles
  // left out because the device could not give their indices.
  std::vector<std::pair<uint64_t, std::string>> takeReadbackNotes();
  // How far from a hand (metres, wrist to the target's bounds) a device target's changes are
  // read back as they happen.
  static constexpr float kReadbackReach = 0.5f;
  // New bounds of a device target (see addDeviceTarget). Errors: invalid_argument.
  Status updateTargetBounds(uint64_t id, const Aabb& bounds);
  // New positions, same count; a hand holding the target re-solves at its next update.
  Status updateTargetVertices(uint64_t id, std::span<const glm::vec3> positions);
  // Which hands may grasp the target (both by default; neither: not graspable for now). For a
  // hand that may not grasp it, it is scene geometry (the fingers stop on it). A hand holding it
  // that may no longer lets go at its next update. Errors: invalid_argument (unknown id).
  Status setTargetHands(uint64_t id, bool left, bool right);
  // A target that is an analytic shape (a table top, a floor): ready at once. Errors:
  // invalid_argument (id in use, or the shape's validate() refuses it).
  Status addShapeTarget(uint64_t id, const AnalyticShape& shape);
  // What the target is to the hands (graspable by default). A hand holding a target that is no
  // longer graspable lets go at its next update. Errors: invalid_argument (unknown id).
  Status setTargetRole(uint64_t id, TargetRole role);
  TargetRole targetRole(uint64_t id) const;
  // Where the target is: `spaceFromObject` in the space the caller keys `space` (update() says
  // where the spaces are). A target takes part in grasps only while placed. Errors:
  // invalid_argument (unknown id).
  Status placeTarget(uint64_t id, uint64_t space, const Pose& spaceFromObject);
  // The target takes part in nothing until placed again (its space was destroyed).
  Status unplaceTarget(uint64_t id);
  // The targets whose bounds overlap the box of half extents `half` at `worldFromBox`, in the
  // spaces of the last update (the broad phase; for tools and tests).
  std::vector<SceneHit> targetsNear(const Pose& worldFromBox, const glm::vec3& half) const;
  // The same, handing over `positions` and their bounds (computed by the caller while it filled
  // them): nothing is copied, but for the deferred backend's copy of a target it builds
  // (wantsDevicePositions). Fill a buffer from vertexBuffer() to allocate nothing.
  Status updateTargetVertices(uint64_t id, std::vector<glm::vec3>&& positions, const Aabb& bounds);
  // The same with that copy made by the caller (before taking its lock): `devicePositions` is
  // handed over on success and comes back holding the copy it replaced, for the caller to free
  // after its lock. Null: made here when needed.
  Status updateTargetVertices(uint64_t id, std::vector<glm::vec3>&& positions, const Aabb& bounds,
                              std::shared_ptr<const std::vector<glm::vec3>>& devicePositions);
  // Whether the deferred backend builds target `id` from a copy of its positions, which a vertex
  // update must then bring (see updateTargetVertices).
  bool wantsDevicePositions(uint64_t id) const;
  // A buffer the worker is done with, sized for target `id`'s positions when it has one (empty
  // before the first update).
  std::vector<glm::vec3> vertexBuffer(uint64_t id);
  // Removes the target; a hand holding it lets go. Returns false for an unknown id.
  bool removeTarget(uint64_t id);
  bool hasTarget(uint64_t id) const { return targets_.count(id) != 0; }

  // The depth scene (depth/depth_fusion.h, docs/depth.md): what the app draws, known only through
  // the depth it submits, fused on the worker into a volume around each hand. Each volume is a
  // target (depthTarget(hand)), graspable by both hands and kept out by the outer hand like any
  // other; setTargetRole() makes it scene geometry or ignores it. It is empty, and takes part in
  // nothing, until the first frame fused near that hand. A hand that takes it keeps its first
  // solve until the release (the volume changes every frame; the hand does not follow it).
  // Errors: invalid_argument (options validate() refuses, or on already).
  Status enableDepthScene(const DepthFusionOptions& options = {});
  bool depthSceneEnabled() const { return depthOn_; }
  // One frame of the app's depth: its views and their stored values (DepthFusion::integrate), at
  // `time` (seconds, not decreasing). Fused around where each hand was at its last update, with
  // the hands the app draws left out (their model at the wrist the update had, as shown); a frame
  // the worker has not started is replaced. Errors: unsupported (the depth scene is off),
  // invalid_argument (a view validate() refuses, or stored values of the wrong count: nothing is
  // queued).
  Status submitDepth(std::vector<DepthView> views, std::vector<std::vector<float>> depth,
                     double time);
  // The depth scene's target near `hand`: ids the caller's own never take (bit 62 set; the layer's
  // keys are handles and pointers).
  static constexpr uint64_t kDepthTargetBase = uint64_t(1) << 62;
  // The space the depth targets are placed in: the world itself (update()'s frames).
  static constexpr uint64_t kDepthWorldSpace = (uint64_t(3) << 62) | 0xffffu;
  static uint64_t depthTarget(Hand hand) { return kDepthTargetBase | uint64_t(hand); }
  static bool isDepthTarget(uint64_t id) {
    return id == depthTarget(Hand::left) || id == depthTarget(Hand::right);
  }
  // What the worker last fused near `hand` (valid: a frame was fused).
  const GraspWorker::DepthDone& depthState(Hand hand) const { return depthDone_[size_t(hand)]; }
  // Where each hand's depth is fused as of the last update (world, axis-aligned, the cube of
  // DepthFusionOptions::size): only pixels whose rays meet one of these matter to the scene, so a
  // caller that reads depth may read those alone. nullopt for a hand no update has seen.
  struct DepthBox {
    glm::vec3 lo{0.0f}, hi{0.0f};
  };
  std::array<std::optional<DepthBox>, 2> depthBoxes() const;

  // Advances one hand, with the spaces where they are this frame (targets in spaces not listed,
  // or not valid, take part in nothing this frame). Returns the first error met while solving (the
  // hand then stays open).
  Status update(Hand hand, const HandFrame& frame, std::span<const SpaceFrame> spaces);
  // The same with each target located on its own (placed in a space of its own at the identity;
  // tests and tools).
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
  // How to show the hand's last solve on a target that moved relative to the hand since (its
  // result is being re-solved): the pose, in the current hand frame, of the hand frame the solve
  // was made in (currentHandFromSolvedHand). Drawing the hand there keeps every contact on the
  // target's surface, off the controller by the motion since the solve. Nothing when the target
  // moved less than the re-solve tolerances (the solve is shown as it is).
  std::optional<Pose> reposeCorrection(Hand hand) const;
  // The model the hand's grasp was solved with (default adult until a tracked grab fits one).
  const HandModel& model(Hand hand) const { return hands_[size_t(hand)].model; }
  // What the outer hand shows of the hand as of the last update (inactive: the hand as given).
  const OuterView& outerView(Hand hand) const { return hands_[size_t(hand)].outer.view; }
  float lastSqueeze(Hand hand) const { return hands_[size_t(hand)].squeeze; }

 private:
  // A device target's copy on the CPU (addDeviceTarget): none (no readback on this backend),
  // asked (the first readback is on its way), settingUp (on the worker), ready (a mesh like any
  // other), failed (the worker refused it: the field only).
  enum class Mirror { none, asked, settingUp, ready, failed };
  struct Target {
    bool meshTarget = false;    // CPU arrays (addTarget), not device buffers
    bool shapeTarget = false;   // an analytic shape (addShapeTarget)
    bool deviceTarget = false;  // the deferred backend's mesh (addDeviceTarget)
    bool volumeTarget = false;  // a depth scene's volume (enableDepthScene)
    Mirror mirror = Mirror::none;
    uint64_t readbackApplied = 0;  // generation of the newest one handed to the worker
    bool readbackStale = false;    // changed since, while far from every hand
    std::optional<AnalyticShape> shape;
    TargetRole role = TargetRole::graspable;
    // Where it is (placeTarget); in the broad phase while placed, set up and not ignored.
    bool placed = false;
    uint64_t space = 0;
    Pose spaceFromObject;
    bool indexed = false;
    TargetSetup setup = TargetSetup::ready;
    // With a deferred backend that builds mesh targets: the arrays it uploads, shared with it
    // and never changed (new positions, and the set-up's outward indices, replace a pointer).
    SharedMesh deviceCopy;
    size_t vertexCount = 0;  // what updateTargetVertices must match
    Aabb bounds;
    uint64_t version = 0;
    std::array<bool, 2> hands{true, true};  // graspable by the left, the right hand
  };
  struct HandState {
    HandModel model;
    // The solver the worker prepares and solves with (replaced, never changed, by the owner once
    // handed over).
    std::shared_ptr<GraspWorker::SolverSetup> workerSolver;
    bool prepared = false;
    HandGrasp grasp;
    // The target's pose relative to the hand at the last update (for reposeCorrection).
    std::optional<Pose> objectFromHandNow;
    // A job handed to the worker and not yet collected, and whether its field came from the GPU.
    bool jobPending = false;
    bool jobOnGpu = false;
    uint64_t ticket = 0;
    uint64_t solvedVersion = 0;
    float squeeze = 0.0f;
    SdfGrid grid;
    // A deferred build requested for this hand, and the pose and version it was made for.
    bool pending = false;
    Pose pendingPose;
    uint64_t pendingVersion = 0;
    int64_t pendingTime = 0;
    // When the deferred build was requested: one still not collected after buildTimeLimit is
    // given up, as a CPU build past it is (a device that never finishes must not hold a hand).
    std::chrono::steady_clock::time_point pendingSince{};
    int64_t frameTime = 0;  // HandFrame::time of the update in progress
    // A grab that failed (a build over its time bound, a refused solve) is not retried while
    // the user keeps squeezing: once per squeeze, not once per frame.
    bool waitForRelease = false;
    // A tracked hand's open-hand parts as the user holds it (wrist frame), cleared besides the
    // model's open hand (GraspScene::extraParts); 0 for a controller-driven hand.
    HandParts trackedParts{};
    int trackedPartCount = 0;
    // The scene of the last job posted (its members, relative to the hand, and their versions):
    // a change in it is what asks for a new solve.
    std::vector<GraspWorker::JobMember> members;
    std::vector<uint64_t> memberVersions;
    // A solve took a target (HandGrasp::target): kept until the release. Until then every solve
    // chooses again from what the fingers touch.
    bool decided = false;
    // The deferred build's scene (members[0] is the target it builds).
    std::vector<GraspWorker::JobMember> pendingMembers;
    std::optional<Pose> lastWrist;  // world, at the last update with a valid hand (readbacks)
    struct Outer {
      bool engaged = false;      // jobs posted since the last reset
      uint64_t ticket = 0;       // of the last job posted
      uint64_t resetTicket = 0;  // results up to this ticket predate the last reset
      OuterView view;
    } outer;
  };
  // Whether the worker has the target's distance on the CPU (a mesh, a shape, or a device
  // target's readback): the exact check, the choice and the outer hand see only these.
  static bool onCpu(const Target& t) {
    return t.meshTarget || t.shapeTarget || t.volumeTarget || t.mirror == Mirror::ready;
  }
  // Readbacks (grasp_session_readback.cpp): asks for one of the target's mesh; takes those that
  // arrived and the worker's set-ups of them; asks for the stale ones now near a hand.
  void askReadback(uint64_t id, Target& t);
  void collectReadbacks();
  bool nearHand(uint64_t id, const Target& t) const;
  // The outer hand's part of an update (grasp_session_outer.cpp): takes its newest result,
  // decides the frame's fallback, posts the frame's job, and returns the hand where it is shown
  // (`frame` moved by the fallback; its tracked joints copied to `moved`).
  HandFrame updateOuter(Hand side, HandState& hand, const HandFrame& frame, JointPoses& moved);
  // The placed, set-up targets with a CPU mesh or shape whose bounds overlap the box of half
  // extents `half` centred on `centre` (world), as outer-hand members (objectFromHand maps world
  // points), the held target left out.
  void outerMembers(const glm::vec3& centre, float half, uint64_t held,
                    std::vector<GraspWorker::JobMember>& out) const;
  // Whether a part of the hand (`joints` in the wrist's frame, placed at `worldFromWrist`, or
  // moved there straight from `from`) comes within `margin` of the bounds of a member
  // (conservative: the bounds, not the surfaces, and the box around each part's motion). Members
  // whose bounds prove nothing (a device target's, which the app declares; a depth scene's box
  // around the hand) always may when `proving` (the answer is to prove the hand clear), else a
  // device target's bounds are taken as given and a depth scene is left out. A few microseconds:
  // the app's thread may ask.
  bool mayTouchBounds(const Pose& worldFromWrist, const JointPoses& joints,
                      const std::array<float, kJointCount>& radii, float margin,
                      std::span<const GraspWorker::JobMember> members,
                      const std::optional<Pose>& from, bool proving) const;
  // Sets hand.trackedParts from the frame's tracked joints (none: count 0). Before a solve.
  static void noteTrackedParts(HandState& hand, const HandFrame& frame);

  // Asks for a solve of the hand on `members` (the scene in its grab box, not empty).
  Status solve(HandState& hand, size_t slot, std::vector<GraspWorker::JobMember> members);
  // Collects the hand's deferred build, if any, for the worker to solve on; on a device failure
  // has the worker redo it on the CPU.
  Status collect(HandState& hand, size_t slot);
  // Takes the worker's finished job for the hand, if any.
  Status collectJob(HandState& hand, size_t slot);
  // A grab that failed: drops what is in flight, opens the hand, and starts no new grab until the
  // squeeze is released (HandState::waitForRelease).
  void giveUp(HandState& hand, size_t slot);
  // Hands a build (of members other than members[0] when `field` holds that one) and solve to
  // the worker.
  void post(HandState& hand, size_t slot, std::vector<GraspWorker::JobMember> members,
            std::optional<SdfGrid> field, bool gpu, int64_t time);
  Status prepareSolver(HandState& hand);
  void refreshSetups();
  // Takes what the worker fused since the last update: the depth targets' versions and bounds.
  void collectDepth();
  void cancelPending(HandState& hand, size_t slot);
  // The scene in the grab box of a hand at worldFromWrist: every placed, set-up target that is not
  // ignored whose bounds overlap the box, relative to the hand, graspable when `side` may take it
  // (the held target first, and always, when there is one and it is located). Device targets
  // first otherwise (a deferred build takes members[0]). At most kMaxSceneMembers, the nearest.
  std::vector<GraspWorker::JobMember> sceneInBox(Hand side, const Pose& worldFromWrist,
                                                 uint64_t held) const;
  // Whether `now` differs from the scene last solved on (members, versions, relative poses).
  bool sceneChanged(const HandState& hand, std::span<const GraspWorker::JobMember> now) const;
  // Puts the target in the broad phase, or takes it out, as its placement, set-up and role say.
  void reindex(uint64_t id, Target& t);

  std::unique_ptr<DeferredSdfBackend> deferred_;
  bool deferredForMeshTargets_ = true;
  SdfBuildStats stats_;
  GraspSettings settings_;
  std::map<uint64_t, Target> targets_;
  SceneIndex index_;
  bool depthOn_ = false;
  float depthBoxSize_ = DepthFusionOptions{}.size;  // the fusion's cube, as enableDepthScene set
  std::array<GraspWorker::DepthDone, 2> depthDone_{};
  std::vector<std::pair<uint64_t, MeshSetupReport>> setupReports_;
  std::vector<uint64_t> pendingSetups_;  // ids whose set-up may still be running (refreshSetups)
  size_t failedSetups_ = 0;
  std::array<HandState, 2> hands_;
  std::vector<std::pair<uint64_t, std::string>> setupFailures_;
  std::vector<uint64_t> mirrorSetups_;  // device targets whose readback the worker sets up
  std::vector<uint64_t> staleTargets_;  // device targets changed while far from every hand
  uint64_t readbackGeneration_ = 0;
  size_t mirrorsPending_ = 0;  // device targets whose first readback is not set up yet
  std::vector<std::pair<uint64_t, std::string>> readbackNotes_;
  std::unique_ptr<GraspWorker> worker_;  // last: joined before anything it could reach goes
};

}  // namespace sdfg
