// Hands synthesized from a controller: where the wrist sits relative to the grip pose, how the
// squeeze value curls the fingers, and how solved finger curls replace tracked finger joints.
//
// Used by the layer when the runtime has no hand tracking (all 26 joints come from the model)
// and when a grasp is applied to tracked joints (only the fingers that would pass through the
// object are replaced). No OpenXR types: poses are sdfg::Pose in any common "base" space.
#pragma once

#include <array>

#include "base/pose.h"
#include "hand/hand_model.h"

namespace sdfg {

// XR_EXT_hand_joints_motion_range: how far a hand holding a controller may close.
enum class MotionRange : uint8_t {
  unobstructed,              // squeeze 1 is a full fist (the default)
  conforming_to_controller,  // fingers wrap the controller's handle and stop there
};

// Curl that squeeze 1 reaches when conforming to a controller handle.
inline constexpr float kConformingMaxCurl = 0.55f;

using JointRadii = std::array<float, kJointCount>;
using FingerJointCurls = std::array<JointCurls, kFingerCount>;

// The grip pose (OpenXR grip convention: +X out of the back of the left hand and into the right
// palm, -Z through the curled fingers from little finger to thumb, origin in the palm) in the
// wrist joint's frame of `model`.
Pose wristFromGrip(const HandModel& model);

// Per-finger curls for a squeeze value (clamped to [0, 1]).
FingerCurls curlsFromSqueeze(float squeeze, MotionRange range);

// All 26 joints of `model` at `curls`, placed in base space by `baseFromWrist`, with radii.
void placeJoints(const HandModel& model, const FingerCurls& curls, const Pose& baseFromWrist,
                 JointPoses& outPoses, JointRadii& outRadii);

// Replaces the joints of each finger f with replace[f] set by the model's pose at curls[f]
// (base space, through baseFromWrist); other joints stay bit-identical.
void replaceFingers(const HandModel& model, const FingerJointCurls& curls,
                    const std::array<bool, kFingerCount>& replace, const Pose& baseFromWrist,
                    JointPoses& inOutPoses);

}  // namespace sdfg
