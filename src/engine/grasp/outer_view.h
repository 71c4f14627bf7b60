// What the outer hand (grasp/outer_hand.h) shows of one hand as of one grab update, and the
// correction to draw at the instant a hand is drawn.
//
// The outer hand runs on the session's worker, so an update cannot wait for it. Each update
// posts the frame's job and decides a fallback from the newest result it has (of an earlier
// frame): the tracked hand itself when that result was clear by more than the hand moved since
// (it is clear now too), else the hand held where that result showed it (clear, one frame
// behind). An app that locates its hands after the worker finished the update's own job gets
// that result instead (resolveOuter()), on time; most apps locate right after their sync and get
// the fallback. With no result of where the hand is (its first frame near a target, tracking
// found again, a jump) the fallback is the tracked hand where no target's bounds come near it,
// and no hand at all (withhold) where one does: never a hand shown inside something. Reading the
// result never waits for the worker's work (a pointer copy).
#pragma once

#include <array>
#include <cstdint>
#include <memory>

#include "base/pose.h"
#include "grasp/grasp_worker.h"
#include "hand/hand_model.h"

namespace sdfg {

// The correction to draw: the shown wrist in the tracked wrist's frame, and per finger whether it
// is shown at the model's pose at curl[f] instead of as given.
struct OuterNow {
  bool changes = false;  // false: draw the hand as given
  // No hand to show this frame: it appeared or jumped (no result of this place yet) where a
  // target's bounds may reach it, so the hand as given may be inside something. The hand is
  // reported as not tracked, as while tracking is lost, until the worker's answer places it.
  bool withhold = false;
  Pose offset;
  std::array<bool, kFingerCount> capped{};
  std::array<float, kFingerCount> curl{};
  bool onTime = false;  // from the update's own job (not the fallback)
};

struct OuterView {
  // The outer hand runs for this hand (a target is near it). False: the tracked hand, exactly.
  bool active = false;
  uint64_t ticket = 0;  // the job the update posted; its result replaces the fallback
  std::shared_ptr<const GraspWorker::OuterMailbox> mailbox;
  OuterNow fallback;  // what the update decided from an earlier result (never onTime)
  HandModel model = HandModel::defaultAdult(Hand::right);  // whose curls capped fingers take
};

// The update's own result when the worker has published it, else the fallback.
OuterNow resolveOuter(const OuterView& view);

// Replaces the joints (any base space, wrist at baseFromWrist) of each capped finger by the
// model's pose at its curl.
void capFingers(const HandModel& model, const OuterNow& now, const Pose& baseFromWrist,
                JointPoses& joints);

}  // namespace sdfg
