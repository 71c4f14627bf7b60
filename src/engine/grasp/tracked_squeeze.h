// The grab input of a tracked hand with no controller: how closed the user holds it. The mean
// curl of the four fingers (the thumb opposes whatever the grip) stands in for the squeeze value,
// so closing the hand grabs as squeezing a controller does.
#pragma once

#include "hand/hand_model.h"

namespace sdfg {

// `wristSpaceJoints`: the 26 tracked joints in the wrist joint's frame; `model`: the hand they
// are read against (estimateCurls). In [0, 1].
float squeezeFromTrackedHand(const HandModel& model, const JointPoses& wristSpaceJoints);

}  // namespace sdfg
