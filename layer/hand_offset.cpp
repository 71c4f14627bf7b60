// The hand's offset as the extension sees it: its options and its report (hand_offset.h).
#include "hand_offset.h"

#include <algorithm>
#include <cmath>

#include "log.h"
#include "state.h"

namespace sdfg::layer {
namespace {

// Enums compared as integers: an app may pass any value.
bool isSwitch(XrGraspSwitchSDFG v) {
  const int i = int(v);
  return i >= int(XR_GRASP_SWITCH_DEFAULT_SDFG) && i <= int(XR_GRASP_SWITCH_ON_SDFG);
}

// 0 (the default) or a value in (0, hi].
bool zeroOrUpTo(float v, float hi) {
  return v == 0.0f || (v > 0.0f && v <= hi);
}

}  // namespace

void ClearanceRequest::apply(GraspSettings& settings, float& blendTime,
                             const GraspSettings& current, float currentBlendTime) const {
  SolverOptions& so = settings.solverOptions;
  if (!present) {
    const SolverOptions& was = current.solverOptions;
    so.clearance = was.clearance;
    so.clearanceBound = was.clearanceBound;
    so.approach = was.approach;
    so.approachRange = was.approachRange;
    so.approachMaxAngle = was.approachMaxAngle;
    blendTime = currentBlendTime;
    return;
  }
  const XrGraspClearanceOptionsSDFG& o = options;
  if (o.clearance != XR_GRASP_SWITCH_DEFAULT_SDFG)
    so.clearance = o.clearance == XR_GRASP_SWITCH_ON_SDFG;
  if (o.maxCorrection != 0.0f) so.clearanceBound = o.maxCorrection;
  if (o.approach != XR_GRASP_SWITCH_DEFAULT_SDFG)
    so.approach = o.approach == XR_GRASP_SWITCH_ON_SDFG;
  if (o.approachRange != 0.0f) so.approachRange = o.approachRange;
  if (o.approachMaxAngle != 0.0f) so.approachMaxAngle = o.approachMaxAngle;
  if (o.blendTime != 0.0f) blendTime = o.blendTime;
}

void writeHandOffset(const SessionState& s, int h, void* next) {
  auto* out = findInChain<XrGraspHandOffsetSDFG>(next, XR_TYPE_GRASP_HAND_OFFSET_SDFG);
  if (out == nullptr) return;
  const HandOffset& o = s.offsets.hands[size_t(h)];
  const bool held = s.grasp->grasp(h == 0 ? Hand::left : Hand::right).shown();
  // The whole offset drawn now: the outer hand's, then the grasp's (the published view's).
  const std::shared_ptr<const ShownHand> view = s.shown[size_t(h)].load();
  out->offset = toXr(view != nullptr ? shownWholeOffset(*view) : shownHandOffset(o));
  out->solvedOffset = toXr(held ? o.solved : Pose{});
  out->blend = o.blend;
  out->openClearance = held ? o.openClearance : 0.0f;
  out->displacement = held ? o.displacement : 0.0f;
  out->exceeded = held && o.exceeded ? XR_TRUE : XR_FALSE;
}

XrResult readClearanceOptions(const char* cmd, const void* next, ClearanceRequest& out) {
  const auto* c =
      findInChain<const XrGraspClearanceOptionsSDFG>(next, XR_TYPE_GRASP_CLEARANCE_OPTIONS_SDFG);
  out = ClearanceRequest{};
  if (c == nullptr) return XR_SUCCESS;
  if (!isSwitch(c->clearance))
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(clearanceOptions->clearance) is %d",
                    int(c->clearance));
  if (!isSwitch(c->approach))
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(clearanceOptions->approach) is %d",
                    int(c->approach));
  if (!zeroOrUpTo(c->maxCorrection, 0.2f))
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd,
                    "(clearanceOptions->maxCorrection) must be 0 or in (0, 0.2]");
  if (!zeroOrUpTo(c->approachRange, 0.2f))
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd,
                    "(clearanceOptions->approachRange) must be 0 or in (0, 0.2]");
  if (!zeroOrUpTo(c->approachMaxAngle, 3.1416f))
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd,
                    "(clearanceOptions->approachMaxAngle) must be 0 or in (0, pi]");
  if (!zeroOrUpTo(c->blendTime, 2.0f))
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd,
                    "(clearanceOptions->blendTime) must be 0 or in (0, 2]");
  out.present = true;
  out.options = *c;
  return XR_SUCCESS;
}

void OuterHandRequest::apply(GraspSettings& settings, const GraspSettings& current) const {
  if (!present) {
    settings.outerHand = current.outerHand;
    settings.outerOptions = current.outerOptions;
    return;
  }
  if (options.outerHand != XR_GRASP_SWITCH_DEFAULT_SDFG)
    settings.outerHand = options.outerHand == XR_GRASP_SWITCH_ON_SDFG;
  if (options.releaseDistance != 0.0f)
    settings.outerOptions.releaseDistance = options.releaseDistance;
  if (options.blendTime != 0.0f) settings.outerOptions.blendTime = options.blendTime;
}

XrResult readOuterHandOptions(const char* cmd, const void* next, OuterHandRequest& out) {
  const auto* o =
      findInChain<const XrGraspOuterHandOptionsSDFG>(next, XR_TYPE_GRASP_OUTER_HAND_OPTIONS_SDFG);
  out = OuterHandRequest{};
  if (o == nullptr) return XR_SUCCESS;
  if (!isSwitch(o->outerHand))
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd, "(outerHandOptions->outerHand) is %d",
                    int(o->outerHand));
  if (!zeroOrUpTo(o->releaseDistance, 1.0f))
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd,
                    "(outerHandOptions->releaseDistance) must be 0 or in (0, 1]");
  if (!zeroOrUpTo(o->blendTime, 2.0f))
    return logError(XR_ERROR_VALIDATION_FAILURE, cmd,
                    "(outerHandOptions->blendTime) must be 0 or in (0, 2]");
  out.present = true;
  out.options = *o;
  return XR_SUCCESS;
}

}  // namespace sdfg::layer
