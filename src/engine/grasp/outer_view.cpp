#include "grasp/outer_view.h"

#include <algorithm>

#include "hand/hand_synthesis.h"

namespace sdfg {

OuterNow resolveOuter(const OuterView& view) {
  if (!view.active) return OuterNow{};
  if (view.mailbox != nullptr) {
    const std::shared_ptr<const GraspWorker::OuterDone> done = view.mailbox->latest.load();
    if (done != nullptr && done->ticket == view.ticket && done->status == Status::ok) {
      OuterNow now;
      now.changes = done->result.constrained ||
                    std::any_of(done->result.capped.begin(), done->result.capped.end(),
                                [](bool c) { return c; });
      now.offset = done->result.offset;
      now.capped = done->result.capped;
      now.curl = done->result.curl;
      now.onTime = true;
      return now;
    }
  }
  return view.fallback;
}

void capFingers(const HandModel& model, const OuterNow& now, const Pose& baseFromWrist,
                JointPoses& joints) {
  if (std::none_of(now.capped.begin(), now.capped.end(), [](bool c) { return c; })) return;
  FingerJointCurls curls{};
  for (int f = 0; f < kFingerCount; ++f) curls[size_t(f)].fill(now.curl[size_t(f)]);
  replaceFingers(model, curls, now.capped, baseFromWrist, joints);
}

}  // namespace sdfg
