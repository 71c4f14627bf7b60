#include "grasp/shown_hand.h"

#include "grasp/shown_curls.h"

namespace sdfg {

ShownHand takeShownHand(const GraspSession& session, Hand hand, const HandOffset& offset,
                        float squeeze) {
  const HandGrasp& g = session.grasp(hand);
  ShownHand v;
  v.shown = g.shown();
  if (v.shown) v.result = g.result;
  v.model = session.model(hand);
  v.repose = session.reposeCorrection(hand);
  v.offsetShown = offset.blend > 0.0f;
  v.offset = shownHandOffset(offset);
  v.closing = shownClosing(offset);
  v.squeeze = squeeze;
  v.outer = session.outerView(hand);
  return v;
}

Pose shownWholeOffset(const ShownHand& view) {
  const OuterNow outer = resolveOuter(view.outer);
  Pose offset = outer.changes ? outer.offset : Pose{};
  if (view.offsetShown) offset = offset * view.offset;
  return offset;
}

bool drawTrackedHand(const ShownHand& view, JointPoses& joints,
                     std::array<bool, kJointCount>& changed) {
  changed.fill(false);
  if (!view.changesHand()) return true;
  const OuterNow outer = resolveOuter(view.outer);
  if (outer.withhold) return false;
  if (!view.shown && !view.offsetShown && !view.repose && !outer.changes) return true;
  const Pose wristFromBase = joints[size_t(Joint::wrist)].inverse();
  JointPoses local;
  for (int j = 0; j < kJointCount; ++j) local[size_t(j)] = wristFromBase * joints[size_t(j)];
  Pose baseFromWrist = joints[size_t(Joint::wrist)];
  bool whole = view.offsetShown;
  // The outer hand first: the whole hand where it is kept out of the scene; the grasp was solved
  // on the hand there.
  if (outer.changes) baseFromWrist = baseFromWrist * outer.offset;
  // A re-solve is on its way: the whole hand follows the target since the shown solve.
  if (view.repose) baseFromWrist = baseFromWrist * *view.repose;
  if (outer.changes || view.repose) {
    for (int j = 0; j < kJointCount; ++j) joints[size_t(j)] = baseFromWrist * local[size_t(j)];
    whole = true;
  }
  if (view.shown) {
    const ShownCurls c = shownCurls(view.result, view.model.estimateCurls(local), view.closing);
    replaceFingers(view.model, c.curls, c.replace, baseFromWrist, joints);
    for (int f = 0; f < kFingerCount; ++f) {
      if (!c.replace[size_t(f)]) continue;
      for (Joint j : fingerJoints(static_cast<Finger>(f))) changed[size_t(j)] = true;
    }
  }
  // A shown grasp's fingers are the solve's, clear of the scene (the outer hand moves them with
  // the hand): a result that capped fingers before the grasp was shown must not re-curl them.
  if (outer.changes && !view.shown) capFingers(view.outer.model, outer, baseFromWrist, joints);
  // The whole hand moves out of the object, every joint (wrist and palm too).
  if (view.offsetShown) applyHandOffset(view.offset, joints);
  if (whole) changed.fill(true);
  return true;
}

bool drawGripHand(const ShownHand& view, const Pose& baseFromGrip, MotionRange range,
                  JointPoses& joints, JointRadii& radii) {
  const OuterNow outer = resolveOuter(view.outer);
  Pose baseFromWrist = baseFromGrip * wristFromGrip(view.model).inverse();
  if (outer.changes) baseFromWrist = baseFromWrist * outer.offset;
  // A re-solve is on its way: the hand follows the target since the shown solve, so its contacts
  // stay on the surface (docs/threading.md).
  if (view.repose) baseFromWrist = baseFromWrist * *view.repose;
  const FingerCurls user = curlsFromSqueeze(view.squeeze, range);
  placeJoints(view.model, user, baseFromWrist, joints, radii);
  if (view.shown) {
    const ShownCurls c = shownCurls(view.result, user, view.closing);
    replaceFingers(view.model, c.curls, c.replace, baseFromWrist, joints);
  }
  if (outer.changes && !view.shown) capFingers(view.outer.model, outer, baseFromWrist, joints);
  if (view.offsetShown) applyHandOffset(view.offset, joints);
  return !outer.withhold;
}

}  // namespace sdfg
