// The hand's offset off its tracked pose, as it is shown (issue 21: the hand never starts
// inside). A grasp of "ours" may move the open hand out of the object before the fingers close
// (GraspResult::handCorrection); the hand is drawn moved by it, all 26 joints in the wrist
// frame, blended in over a short time at the grab and out after the release so it never pops,
// and a new correction of a held grasp (re-solved as the target moves) is followed over the same
// time, never jumped to.
#pragma once

#include <cstdint>

#include "base/pose.h"
#include "grasp/grasp_session.h"
#include "hand/hand_model.h"

namespace sdfg {

// One hand's offset: what is shown and toward what it blends.
struct HandOffset {
  Pose solved;  // the held grasp's correction; after the release, the last one
  // What a full blend shows: follows `solved` over the blend time when a held grasp is solved
  // again, so a new correction never pops either.
  Pose current;
  float blend = 0.0f;  // 0..1: how much of `current` is shown
  int64_t last = 0;    // the time of the last advance, nanoseconds (0: none yet)
  // The shown grasp's report (XrGraspHandOffsetSDFG): the open hand's clearance, how far the
  // correction moved the hand, whether it needed more than the bound.
  float openClearance = 0.0f;
  float displacement = 0.0f;
  bool exceeded = false;
};

// Advances `offset` to time `now` (nanoseconds, any clock that only moves forward; the layer
// passes the frame's predicted display time): toward the grasp's correction while `grasp` is
// shown, toward identity otherwise, a full blend taking `blendTime` seconds (0: at once). Time,
// not updates: the blend takes as long at 60 Hz as at 120 Hz; a stalled caller (a long gap)
// steps at most a quarter second.
void advanceHandOffset(HandOffset& offset, const HandGrasp& grasp, int64_t now, float blendTime);

// The offset shown now, in the wrist frame (identity when nothing is blended in).
Pose shownHandOffset(const HandOffset& offset);

// How far a new grasp's fingers are shown closed, 0..1: they close while the hand moves to the
// grasp's correction (the same smoothstep), since the solve put them on the surface from the
// corrected hand; closed at the uncorrected one they would be inside (by as much as the hand is
// still to move). 1 when the correction moves the hand by nothing.
float shownClosing(const HandOffset& offset);

// Moves every joint (any base space; the wrist is joints[wrist]) by `offset` in the wrist frame.
void applyHandOffset(const Pose& offset, JointPoses& joints);

}  // namespace sdfg
