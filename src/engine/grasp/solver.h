// The grasp solver interface: given where the target is relative to the hand, find how far each
// finger closes before it touches.
//
// Strategies ("paper", "physics-convex", "physics-mesh", later "ours") implement GraspSolver.
// Callers create one by name, prepare() it once per hand model and box (that is where curve
// caches are built), then call solve() per grasp. A strategy says which representation of the
// target it reads: the grab-box SDF, or a Bullet collider.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "base/pose.h"
#include "base/status.h"
#include "hand/hand_model.h"
#include "sdf/sdf_grid.h"

namespace sdfg {

class PhysicsCollider;  // solver_physics.h
class MeshDistance;     // mesh_distance.h
struct HandPart;        // hand_clearance.h

struct SolverOptions {
  float da = 0.1f;           // curl step along each finger's curve, in (0, 1]
  float threshold = -1.0f;   // stop distance in metres; < 0: each finger's tip radius
  float refineStep = 0.01f;  // physics strategies: the fine step after the coarse one
  bool approach = false;     // "ours": move the hand onto the surface first (approachPose)
  // "ours", with approach: only when the palm is this close to the surface (metres; infinity:
  // any distance), not touching it, and facing it within approachMaxAngle (radians).
  float approachRange = std::numeric_limits<float>::infinity();
  float approachMaxAngle = 3.1416f;
  // "ours": before the fingers close, move the open hand out of the target by the smallest
  // rigid correction (grasp/hand_clearance.h), up to clearanceBound metres of motion; a hand
  // that needs more is not moved. clearanceMargin: the clearance every part ends with.
  bool clearance = true;
  float clearanceBound = 0.03f;
  float clearanceMargin = 0.0005f;
  bool clearanceRotation = true;  // a turn about the palm where it moves the hand less
};

struct FingerState {
  float curl = 0.0f;        // overall curl of the finger (its tip's curve parameter)
  JointCurls jointCurls{};  // per joint; all equal to `curl` for single-curl strategies
  bool contact = false;     // stopped on the surface (false: closed fully without touching)
  glm::vec3 contactPoint{
      0.0f};              // hand space: where the finger touches (the stopping sphere's centre)
  float distance = 0.0f;  // the target's distance at contactPoint as the strategy saw it
  // The touching part, when `contact`: the sphere whose centre is contactPoint lies on the bone
  // from fingerJoints()[contactBone] to the next joint, at contactT (0 at that joint, 1 at the
  // next one: the next joint's own sphere). Tip-only strategies report the tip (the last bone,
  // 1). -1 without a contact. contact.h turns it into the exact contact on the target.
  int contactBone = -1;
  float contactT = 1.0f;
};

struct GraspResult {
  std::array<FingerState, kFingerCount> fingers{};
  // Where the strategy moved the hand before closing it (SolverOptions::approach): maps the
  // corrected hand frame, in which the fingers and contact points are, into the scene's hand
  // frame. Identity for every strategy that leaves the hand where it is.
  Pose handCorrection{};
  // Strategies that check their stops on GraspScene::exact ("ours"): points sampled there and
  // the wall time of that check (included in the solve), microseconds. 0 without a source.
  int exactSamples = 0;
  float exactCheckUs = 0.0f;
  // The open hand's clearance (SolverOptions::clearance; "ours"): its smallest part clearance
  // (distance - radius, metres) before any correction, how far the correction moved the most
  // moved part (metres; includes the approach), and whether a correction within the bound
  // could not clear it (then the hand was left where it was).
  float openClearance = std::numeric_limits<float>::infinity();
  float handMoved = 0.0f;
  bool clearanceExceeded = false;
};

// One exact sample of the target's distance (ExactDistanceSource).
struct ExactSample {
  // Signed, metres, negative inside; +infinity when no surface is within the search distance
  // (then the side is unknown and `closest` is not set).
  float distance = std::numeric_limits<float>::infinity();
  glm::vec3 closest{0.0f};  // closest surface point, in the frame of the query point
  // Source-specific id of the closest feature (MeshExactSource: the triangle), or max() when
  // none was found. On entry to sample() it is a hint: the id an earlier sample of a point near
  // this one returned (max(): none), which may make the search cheaper; it never changes the
  // result.
  uint32_t feature = std::numeric_limits<uint32_t>::max();
  // Which solid the closest feature belongs to: a scene member's index (SceneExactSource), 0 for
  // a single mesh; max() when none was found. Output only.
  uint32_t member = std::numeric_limits<uint32_t>::max();
};

// Exact distance to the target at a few points, for strategies that check the stops they found
// on the sampled field ("ours"): the field's error at 16^3 is millimetres near curved and sharp
// parts. An interface so that a GPU path can answer a batch at once; MeshExactSource answers on
// the CPU from a MeshDistance.
class ExactDistanceSource {
 public:
  virtual ~ExactDistanceSource() = default;
  // For each i: out[i] is the exact sample of handPoints[i] (scene hand frame) searched within
  // maxDistances[i] metres (a small bound keeps the search cheap). The three spans must have the
  // same size; the caller owns them. out[i].feature on entry is a hint (see ExactSample). Must be
  // safe to call from several threads at once.
  virtual void sample(std::span<const glm::vec3> handPoints, std::span<const float> maxDistances,
                      std::span<ExactSample> out) const = 0;
};

// ExactDistanceSource over a MeshDistance of the target in object space: hand-space points are
// mapped by objectFromHand. Keeps a reference to `mesh` (the caller keeps it alive and does not
// update it while solves run). The sign is MeshDistance::localSignedDistanceWithin's (the side
// of the nearest sheet, also on open meshes).
class MeshExactSource final : public ExactDistanceSource {
 public:
  MeshExactSource(const MeshDistance& mesh, const Pose& objectFromHand);
  void sample(std::span<const glm::vec3> handPoints, std::span<const float> maxDistances,
              std::span<ExactSample> out) const override;

 private:
  const MeshDistance* mesh_;
  Pose objectFromHand_;
  Pose handFromObject_;
};

// The target as the solvers see it. Only the representation a strategy asks for must be set.
struct GraspScene {
  const SdfGrid* field = nullptr;             // SDF of the target in the grab box (hand space)
  const PhysicsCollider* collider = nullptr;  // Bullet collider of the target (object space)
  Pose objectFromHand;                        // hand-space point -> object space
  // Optional exact distance of the same target (scene hand frame). "ours" checks and corrects
  // its stops with it; null: the field alone, as before. Other strategies ignore it.
  const ExactDistanceSource* exact = nullptr;
  // Where the field was built: maps scene hand points into the hand frame `field` was built in
  // (identity: built for this scene). A field of the same rigid target built at another relative
  // pose is the same distance function, so "ours" samples it through this map instead of a new
  // build; the caller must make sure the box still covers the fingers there. Other strategies
  // need identity.
  Pose fieldFromHand{};
  // More parts of the open hand to clear before closing (SolverOptions::clearance), hand space of
  // the scene: a tracked hand as the user holds it, which can differ from the model's open pose
  // by centimetres. Empty: the model's open hand alone. The caller owns the parts.
  std::span<const HandPart> extraParts{};
};

class GraspSolver {
 public:
  virtual ~GraspSolver() = default;

  virtual std::string_view name() const = 0;
  virtual bool needsField() const = 0;
  virtual bool needsCollider() const = 0;

  // Caches what depends only on the hand model, the box and the options (the finger curves in
  // box coordinates). Call again when any of them changes. Fails on invalid options.
  virtual Status prepare(const HandModel& hand, const GridBox& box,
                         const SolverOptions& options) = 0;

  // Solves one grasp into `out`. Fails when not prepared or when the scene lacks what
  // needsField()/needsCollider() ask for. Never allocates for the SDF strategies.
  virtual Status solve(const GraspScene& scene, GraspResult& out) const = 0;

  // Why the last prepare() failed, naming the option or input; empty after a successful one.
  virtual std::string_view prepareError() const { return {}; }
};

// Checks the options every strategy shares: da and refineStep finite and in (0, 1], threshold
// finite (negative means "the finger's tip radius"). Returns the first problem, or nothing.
std::optional<Error> validateSolverOptions(const SolverOptions& options);

// Names accepted by createSolver(): the strategies that run in an app ("ours", the default, then
// "paper"). The benchmark's full list, with the physics baselines, is eval/strategies.h.
std::vector<std::string> solverNames();

// Creates a strategy by name; an unknown name is an invalid_argument error listing the known ones.
Result<std::unique_ptr<GraspSolver>> createSolver(std::string_view name);

}  // namespace sdfg
