// The hand's offset off its tracked pose (issue 21: the hand never starts inside). A grasp of
// "ours" may move the open hand out of the object before the fingers close
// (GraspResult::handCorrection); the layer shows that by moving all 26 joints in the wrist frame,
// blended in over a short time at the grab and out after the release so the hand never pops, and
// reports it (XrGraspHandOffsetSDFG) so an app can move its own controller or arm with it.
#pragma once

#include <array>

#include "base/pose.h"
#include "grasp/grasp_session.h"
#include "hand/hand_model.h"
#include "xr_includes.h"

namespace sdfg::layer {

struct SessionState;

// One hand's offset: what is shown and toward what it blends.
struct HandOffset {
  Pose solved;  // the held grasp's correction; after the release, the last one
  // What a full blend shows: follows `solved` over the blend time when a held grasp is solved
  // again (the target moved relative to the hand), so a new correction never pops either.
  Pose current;
  float blend = 0.0f;  // 0..1: how much of `current` is shown
  XrTime last = 0;     // the predicted time of the last advance (0: none yet)
  float openClearance = 0.0f;
  float displacement = 0.0f;
  bool exceeded = false;
};

struct HandOffsets {
  std::array<HandOffset, 2> hands{};  // left, right
  float blendTime = 0.1f;             // seconds for a full blend in or out (0: at once)
};

// What XrGraspClearanceOptionsSDFG asked for, checked; applied to the settings by apply().
struct ClearanceRequest {
  bool present = false;
  XrGraspClearanceOptionsSDFG options{};
  void apply(GraspSettings& settings, float& blendTime) const;
};

// Advances hand `h`'s offset by the frame time since its last advance, toward the grasp's
// correction while it holds and toward identity otherwise. Called with the session locked, once
// per hand per xrSyncActions, after the grasp update.
void advanceHandOffset(SessionState& s, int h);

// The offset shown now, in the wrist frame (identity when nothing is blended in).
Pose shownHandOffset(const HandOffset& offset);

// Moves every joint (any base space; the wrist is joints[wrist]) by `offset` in the wrist frame.
void applyHandOffset(const Pose& offset, JointPoses& joints);

// Fills the XrGraspHandOffsetSDFG chained on `next`, if any, for hand `h`.
void writeHandOffset(const SessionState& s, int h, void* next);

// Checks the XrGraspClearanceOptionsSDFG chained on `next`, if any: XR_SUCCESS (and `out` set)
// or XR_ERROR_VALIDATION_FAILURE, logged under `cmd`.
XrResult readClearanceOptions(const char* cmd, const void* next, ClearanceRequest& out);

}  // namespace sdfg::layer
