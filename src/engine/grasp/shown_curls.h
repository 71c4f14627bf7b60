// The finger curls a held hand shows: per joint the lesser of the user's own curl and the grasp's
// contact curl, so a finger never curls past the surface it stopped on, and never further than
// the user holds it either. A finger the user holds more open than its contact keeps the user's
// pose (replace false): a tracked hand's own joints are then left bit-identical.
#pragma once

#include <array>

#include "grasp/solver.h"
#include "hand/hand_model.h"
#include "hand/hand_synthesis.h"

namespace sdfg {

struct ShownCurls {
  FingerJointCurls curls{};                  // per finger and rotating joint
  std::array<bool, kFingerCount> replace{};  // the finger's joints come from `curls`
};

// `grasp`: the solve shown; `user`: the user's own curl per finger (squeeze, or estimateCurls of a
// tracked hand); `closing` (0..1): how far toward the contact curls the fingers have closed
// (shownClosing(): while the hand moves to the grasp's correction).
ShownCurls shownCurls(const GraspResult& grasp, const FingerCurls& user, float closing = 1.0f);

}  // namespace sdfg
