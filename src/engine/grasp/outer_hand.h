// The outer hand: the hand the user sees stays outside every registered object in every frame,
// not only at a grab (issue 27). When the tracked hand enters an object, the shown hand stops on
// its surface and slides along it; when it comes out, the shown hand is the tracked hand again.
//
// It is a god-object (a proxy with history, as in haptic rendering): each frame the shown hand
// moves from where it was shown last toward the tracked hand, and never through a surface.
// - Rigid part (palm, metacarpals, a held object): from the last shown wrist pose toward the
//   tracked one, by steps no longer than the distance to the nearest unseen surface (so at any
//   speed it cannot cross a thin plate), each step the motion nearest the tracked pose that keeps
//   every part clear on the linearised exact distances (a small quadratic programme, translation
//   and a turn about the palm). A hand pushed through a thin plate stays on the side it came from.
// - Fingers: each finger's curl (the hand model's curl space) moves from the last shown curl
//   toward the user's, and stops at contact: a finger pressed onto a surface stops on it, and is
//   shown at the model's pose at that curl; a finger that touches nothing is shown as given.
// - Release: when the tracked hand is more than releaseDistance from the shown one (largest part
//   motion), the shown hand returns to tracking, blended over blendTime, as the Ultraleap and
//   SteamVR hands do; it re-engages once the tracked hand is clear again, or as soon as a part
//   that is clear where the hand is shown would follow tracking onto a surface (a hand let go
//   inside a table and moved on into a comb stops on the comb; its parts still in the table are
//   free to come out).
// - While the straight motion from the last shown pose to the tracked one is free by more than the
//   motion itself (nothing near), the shown hand is the tracked hand, exactly.
//
// Distances come from an ExactDistanceSource in world space (a SceneExactSource whose members'
// objectFromHand map world points). Pure CPU work with bounded exact searches: the session's
// worker runs it, never the app's thread.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "base/pose.h"
#include "grasp/hand_clearance.h"
#include "grasp/solver.h"
#include "hand/hand_model.h"
#include "mesh/mesh.h"
#include "scene/analytic_shape.h"

namespace sdfg {

// Farther than a hand moves between two updates (3 m/s at 30 Hz is 10 cm), metres of largest
// part motion: the tracked hand jumped (tracking lost and found elsewhere, or teleported).
inline constexpr float kJumpDistance = 0.2f;

struct OuterHandOptions {
  float margin = 0.0005f;         // clearance every part keeps, metres
  float releaseDistance = 0.10f;  // metres of largest part motion between shown and tracked
  float blendTime = 0.25f;        // seconds of the return to tracking past releaseDistance
  int maxIterations = 12;         // sliding steps per frame
  // The shown hand does not move while the tracked hand moves less than this (largest part
  // motion, metres) since the last frame and the shown one is constrained: no jitter on a hand
  // held still against a surface.
  float stillness = 0.00005f;
  std::optional<Error> validate() const;
};

// One frame of the hand as the app would show it without the outer hand.
struct OuterHandInput {
  Pose worldFromWrist;  // the tracked (or synthesized) wrist joint, world space
  // The 26 joints in the wrist's frame and their radii, as they would be shown.
  const JointPoses* joints = nullptr;
  const std::array<float, kJointCount>* radii = nullptr;
  double time = 0.0;  // seconds, any origin (the blend's clock)
  // Parts of a held object, wrist frame: part of the hand, kept out of everything else (the
  // caller leaves the held object itself out of `scene`). They may rest on a surface (a held
  // object lying on a table where the app put it does not push the hand off it) but not enter it.
  std::span<const HandPart> attached{};
  // The fingers are a grasp's (its solve, clear of the whole scene from open to contact): moved
  // with the rigid part as given, never re-curled, so they stay on what they hold.
  bool rigidFingers = false;
  // A target of `scene` moved since the last update: the hand shown then is tested against the
  // scene now, and moved out of what moved into it.
  bool sceneMoved = false;
  // The grasp's offset the hand is drawn with (wrist frame; grasp/hand_offset_blend.h), after the
  // outer hand's own: every part, capped fingers too, is kept out where it is drawn.
  Pose drawnOffset{};
};

struct OuterHandResult {
  Pose worldFromShownWrist;  // where the wrist is shown
  Pose offset;               // the shown wrist in the tracked wrist's frame (identity: tracked)
  // Per finger: shown at the model's pose at curl[f] (true), or as given (false; curl[f] is then
  // the curl the model estimates for the finger as given).
  std::array<bool, kFingerCount> capped{};
  std::array<float, kFingerCount> curl{};
  bool constrained = false;  // the shown hand differs from the input
  bool touching = false;     // some part is on a surface (within margin + 0.5 mm)
  bool blending = false;     // returning to tracking past releaseDistance
  bool released = false;     // following tracking until the tracked hand is clear again
  bool pushedOut = false;    // a target had moved into the hand shown last: moved out of it
  // A lower bound of the shown hand's smallest part clearance, metres (inf: nothing near; for a
  // free hand searched to 2.5 cm, so at most that).
  float clearance = 0.0f;
  int samples = 0;  // exact samples taken this frame
};

// Points on a held object's surface (object frame, radius 0), for OuterHandInput::attached once
// moved to the wrist frame: its vertices, evenly thinned, and points spread over its triangles by
// area, at most kMaxAttachedParts in all. Between samples an edge of the scene can dent the
// object by the samples' spacing (millimetres on a hand-sized object); the hand's own parts are
// covered exactly.
inline constexpr int kMaxAttachedParts = 256;
std::vector<HandPart> surfaceParts(const TriangleMesh& mesh);
// A box's corners, edge midpoints and a grid on each face; nothing for a plane (never held).
std::vector<HandPart> surfaceParts(const AnalyticShape& shape);

class OuterHand {
 public:
  explicit OuterHand(const HandModel& model, const OuterHandOptions& options = {});

  // One frame. `scene` is everything the hand stays out of (null: nothing near; the shown hand is
  // the input and the history is dropped). Fails only on invalid input (joints or radii null,
  // non-finite poses).
  Result<OuterHandResult> update(const OuterHandInput& in, const ExactDistanceSource* scene);
  void reset();
  // The hand model whose curls the capped fingers use (fitted to a tracked hand by the caller);
  // the same model again changes nothing.
  void setModel(const HandModel& model);
  void setOptions(const OuterHandOptions& options) { options_ = options; }
  const HandModel& model() const { return model_; }
  // The smallest rigid motion (world, applied after the shown pose) that takes the hand shown last
  // (its rigid parts and, unless they were a grasp's, its fingers at their shown curls: what
  // update() pushes out of a target that moved in) out of `scene`, e.g. the scene a frame on with
  // its moving targets where their motion takes them; nothing when it is out already, nothing was
  // shown, or no clear pose is within the release distance.
  std::optional<Pose> pushOutOf(const ExactDistanceSource& scene) const;

 private:
  struct FingerRig {
    std::vector<float> t;  // spheres along the finger's moving bones: bone index + fraction
    std::vector<float> radius;
    float speed = 0.0f;  // bound on any sphere's motion per unit curl, metres
  };
  void prepareFingers();
  // The sphere centres of finger f at curl a (wrist frame).
  void fingerSpheres(int f, float a, std::vector<glm::vec3>& out) const;
  // The hand as shown at shown_ (world spheres and radii): `rigid` parts (wrist frame) and, with
  // `fingers`, every finger at its shown curl (curl_).
  void shownSpheres(std::span<const glm::vec3> rigid, std::span<const float> rigidRadius,
                    bool fingers, std::vector<glm::vec3>& world, std::vector<float>& radii) const;

  HandModel model_;
  OuterHandOptions options_;
  Pose drawnOffset_{};  // OuterHandInput::drawnOffset of the update in progress
  std::array<FingerRig, kFingerCount> rigs_{};

  bool engaged_ = false;  // history exists
  Pose shown_;            // last shown wrist, world
  Pose lastTracked_;
  std::array<bool, kFingerCount> capped_{};
  std::array<float, kFingerCount> curl_{};  // last shown curl per finger
  // The hand's own rigid parts (wrist frame) in the last update: what a target that moves into
  // the hand is tested against, at shown_ (empty: no update since the last reset).
  std::vector<glm::vec3> shownRigid_;
  std::vector<float> shownRigidRadius_;
  glm::vec3 shownPivot_{0.0f};      // the palm then (wrist frame): where a push turns about
  bool shownRigidFingers_ = false;  // the fingers were a grasp's (OuterHandInput::rigidFingers)
  bool released_ = false;
  bool blending_ = false;
  double blendStart_ = 0.0;
  Pose blendFrom_;
};

}  // namespace sdfg
