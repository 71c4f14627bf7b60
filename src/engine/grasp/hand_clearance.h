// The open hand's clearance from the target, and the smallest rigid correction that clears it
// (issue #21: the hand never starts inside). A user reaches for an object and squeezes when the
// hand is near it, often partly in it; closing the fingers from there leaves the hand inside.
// Before the fingers close, clearHand() moves the open hand out by the smallest rigid motion
// that clears every part of it (palm, metacarpals, every phalanx), from the distance and its
// gradient at each part: the exact mesh distance where the scene has one, the grab-box field
// otherwise. Translation first; a rotation about the palm is taken where it moves the hand less
// (a plate through the fingers: turning the hand frees them with less motion than sliding it).
//
// The correction is a Pose mapping the corrected hand frame into the scene's hand frame, the
// convention of GraspResult::handCorrection. It has a bound: a hand that would need more is not
// moved (ClearanceResult::exceeded), and the fingers that can close still do.
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include <glm/vec3.hpp>

#include "base/pose.h"
#include "base/status.h"
#include "hand/hand_model.h"
#include "sdf/sdf_grid.h"

namespace sdfg {

class ExactDistanceSource;  // solver.h

// A sphere of the hand's surface model: spheres along each capsule of the joint radii cover it.
struct HandPart {
  glm::vec3 centre{0.0f};  // hand space
  float radius = 0.0f;     // the capsule's radius there
  // Grown to cover the capsule between this sphere and its neighbours (the union of spheres
  // spaced along a capsule misses a thin rim between them): the radius to keep clear.
  float coverRadius = 0.0f;
  Joint joint = Joint::palm;  // the joint the part's bone starts at (the palm: its own sphere)
};

// Most parts clearHand() takes: two hands' worth of jointParts() (the model's open hand and a
// tracked hand's own pose), each the palm and five fingers' capsules, metacarpal to tip.
inline constexpr int kMaxHandParts = 384;
using HandParts = std::array<HandPart, kMaxHandParts>;

// The parts of the hand at the given curls, hand space: the palm joint's sphere, then per finger
// spheres along every bone from the metacarpal joint to the tip, no more than 0.7 of the smaller
// joint radius apart. Writes at most kMaxHandParts parts to `out` and returns how many.
int handParts(const HandModel& hand, const FingerCurls& curls, HandParts& out);

// The same parts for any 26 joints (hand space) and their radii: a tracked hand as the user holds
// it. Writes from out[first] on, at most up to kMaxHandParts, and returns the new count.
int jointParts(std::span<const Pose, kJointCount> joints, std::span<const float, kJointCount> radii,
               HandParts& out, int first = 0);

struct ClearanceOptions {
  float margin = 0.0005f;       // clearance every part ends with, metres (>= 0)
  float maxCorrection = 0.03f;  // most any part may move, metres; a hand needing more stays
  bool rotation = true;         // allow a turn about the palm where it moves the hand less
  // The rotation is taken only where its largest part motion is below this fraction of the
  // translation's: a turn changes how the hand looks more than a slide of the same size.
  float rotationGain = 0.8f;
  int maxIterations = 12;  // linearised steps per solve (translation, then rotation)
  // Where the field was built (GraspScene::fieldFromHand): maps the scene's hand points into the
  // hand frame of the field, for a field reused while the target moved rigidly in the hand.
  Pose fieldFromHand{};
};

struct ClearanceResult {
  // Maps the corrected hand frame into the scene's hand frame; identity when the hand was clear
  // or needed more than maxCorrection.
  Pose handCorrection{};
  float clearanceBefore = 0.0f;  // smallest part clearance (distance - radius), metres
  float clearanceAfter = 0.0f;   // the same after the correction (the hand as returned)
  float displacement = 0.0f;     // largest motion of any part, metres
  bool wasInside = false;        // clearanceBefore < 0: some part of the open hand was inside
  bool exceeded = false;         // a correction within maxCorrection did not clear it: not moved
  bool rotated = false;          // the correction turns the hand
  int iterations = 0;
  int exactSamples = 0;  // points sampled on the exact source
};

// Finds the smallest rigid correction of the hand whose parts are `parts` (hand space) that
// leaves every part at least options.margin clear of the target, turning about `pivot` (hand
// space; the palm) where allowed. Distances come from `exact` where it is not null (the field
// gives the direction where the exact search finds nothing near), else from `field`; at least
// one must be given. `start` is where the hand is before the correction (an approach's
// correction, or identity): the result includes it. Fails on invalid options or no distance.
// Does not allocate.
Result<ClearanceResult> clearHand(std::span<const HandPart> parts, const glm::vec3& pivot,
                                  const SdfGrid* field, const ExactDistanceSource* exact,
                                  const ClearanceOptions& options = {}, const Pose& start = {});

}  // namespace sdfg
