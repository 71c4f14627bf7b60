// The hand's offset off its tracked pose as the extension sees it (issue 21: the hand never
// starts inside; issue 27: the outer hand stays out in every frame): the options that shape it
// (XrGraspClearanceOptionsSDFG, XrGraspOuterHandOptionsSDFG) and the report of it
// (XrGraspHandOffsetSDFG). The offset itself, its blend and how it moves the joints are the
// engine's (grasp/hand_offset_blend.h).
#pragma once

#include <array>

#include "base/pose.h"
#include "grasp/grasp_session.h"
#include "grasp/hand_offset_blend.h"
#include "xr_includes.h"

namespace sdfg::layer {

struct SessionState;

struct HandOffsets {
  std::array<HandOffset, 2> hands{};  // left, right
  float blendTime = 0.1f;             // seconds for a full blend in or out (0: at once)
};

// What XrGraspClearanceOptionsSDFG asked for, checked; applied to the settings by apply().
struct ClearanceRequest {
  bool present = false;
  XrGraspClearanceOptionsSDFG options{};
  // Absent, the clearance options of `current` (and its blend time) are kept: a call of
  // xrSetGraspOptionsSDFG without the struct leaves them as they are.
  void apply(GraspSettings& settings, float& blendTime, const GraspSettings& current,
             float currentBlendTime) const;
};

// What XrGraspOuterHandOptionsSDFG asked for, checked; applied to the settings by apply().
struct OuterHandRequest {
  bool present = false;
  XrGraspOuterHandOptionsSDFG options{};
  // Absent, the outer-hand options of `current` are kept.
  void apply(GraspSettings& settings, const GraspSettings& current) const;
};

// Checks the XrGraspOuterHandOptionsSDFG chained on `next`, if any: XR_SUCCESS (and `out` set)
// or XR_ERROR_VALIDATION_FAILURE, logged under `cmd`.
XrResult readOuterHandOptions(const char* cmd, const void* next, OuterHandRequest& out);

// Fills the XrGraspHandOffsetSDFG chained on `next`, if any, for hand `h`. The caller holds the
// session's mutex.
void writeHandOffset(const SessionState& s, int h, void* next);

// Checks the XrGraspClearanceOptionsSDFG chained on `next`, if any: XR_SUCCESS (and `out` set)
// or XR_ERROR_VALIDATION_FAILURE, logged under `cmd`.
XrResult readClearanceOptions(const char* cmd, const void* next, ClearanceRequest& out);

}  // namespace sdfg::layer
