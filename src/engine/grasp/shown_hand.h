// What one hand shows, as of one grab update, and how it is drawn.
//
// The owner of a GraspSession (the layer, in xrSyncActions) takes a ShownHand of each hand after
// each update and publishes it; it never changes afterwards. The thread that draws hands (an
// app's render thread in xrLocateHandJointsEXT) reads the newest one without waiting for the
// thread that updates them, and draws one consistent grasp: result, model, correction and offset
// from the same update.
#pragma once

#include <array>
#include <optional>

#include "base/pose.h"
#include "grasp/grasp_session.h"
#include "grasp/hand_offset_blend.h"
#include "grasp/outer_view.h"
#include "hand/hand_model.h"
#include "hand/hand_synthesis.h"

namespace sdfg {

struct ShownHand {
  bool shown = false;    // HandGrasp::shown(): the fingers close onto `result`
  GraspResult result{};  // the shown solve
  HandModel model = HandModel::defaultAdult(Hand::right);
  // GraspSession::reposeCorrection: the hand drawn where it was relative to the target at the
  // solve, while a re-solve is on its way.
  std::optional<Pose> repose;
  Pose offset;               // shownHandOffset(): the whole hand moves by it (wrist frame)
  bool offsetShown = false;  // blend > 0
  float closing = 1.0f;      // shownClosing(): how far the grasp's fingers are closed
  float squeeze = 0.0f;      // the grab input at the update: a synthesized hand's curl
  // The outer hand (grasp/outer_view.h): applied first, the grasp drawn on the hand it shows.
  OuterView outer;
  // Whether drawing may change a tracked hand at all (if not, its joints pass through untouched;
  // an active outer hand that finds the hand clear leaves them untouched too).
  bool changesHand() const { return shown || offsetShown || outer.active; }
};

// The whole hand's offset drawn now, in the tracked wrist's frame: the outer hand's, then the
// grasp's (XrGraspHandOffsetSDFG::offset).
Pose shownWholeOffset(const ShownHand& view);

// The snapshot of `hand` after `session`'s update, with the hand's offset and squeeze.
ShownHand takeShownHand(const GraspSession& session, Hand hand, const HandOffset& offset,
                        float squeeze);

// A tracked hand: `joints` (26, any base space) are the runtime's; rewritten as `view` shows the
// hand (re-posed onto the target, fingers stopped on it, moved by the offset). `changed[j]` says
// which joints were rewritten; the others are left bit-identical. Returns false when there is no
// hand to show now (OuterNow::withhold: the joints are left as given and none is changed); the
// caller reports the hand as not tracked this frame.
bool drawTrackedHand(const ShownHand& view, JointPoses& joints,
                     std::array<bool, kJointCount>& changed);

// A hand synthesized from a controller: all 26 joints and radii from the grip pose
// `baseFromGrip` (any base space), the fingers curled by the squeeze within `range`, then drawn
// as `view` shows it. Returns false when there is no hand to show now (as drawTrackedHand).
bool drawGripHand(const ShownHand& view, const Pose& baseFromGrip, MotionRange range,
                  JointPoses& joints, JointRadii& radii);

}  // namespace sdfg
