#include "hand/hand_synthesis.h"

#include <algorithm>
#include <cmath>

#include <glm/mat3x3.hpp>

namespace sdfg {
namespace {

// How far the grip origin sits below the palm joint, toward the palm (the controller handle's
// axis is inside the curled fingers, not on the skin).
constexpr float kGripBelowPalm = 0.025f;

}  // namespace

Pose wristFromGrip(const HandModel& model) {
  // Columns: the grip's X, Y, Z axes in wrist coordinates. Both hands share the joint axes
  // (+Y back of hand, -Z toward the fingers); the thumb is +X on the left, -X on the right.
  const bool left = model.side() == Hand::left;
  const glm::mat3 axes(glm::vec3(0.0f, left ? 1.0f : -1.0f, 0.0f),   // grip +X
                       glm::vec3(0.0f, 0.0f, -1.0f),                 // grip +Y: toward fingers
                       glm::vec3(left ? -1.0f : 1.0f, 0.0f, 0.0f));  // grip +Z: thumb to little
  JointPoses open;
  model.pose(FingerCurls{}, open);
  const glm::vec3 palm = open[size_t(Joint::palm)].position;
  return Pose{glm::normalize(glm::quat_cast(axes)), palm + glm::vec3(0.0f, -kGripBelowPalm, 0.0f)};
}

FingerCurls curlsFromSqueeze(float squeeze, MotionRange range) {
  float a = std::isfinite(squeeze) ? std::clamp(squeeze, 0.0f, 1.0f) : 0.0f;
  if (range == MotionRange::conforming_to_controller) a *= kConformingMaxCurl;
  FingerCurls curls;
  curls.fill(a);
  return curls;
}

void placeJoints(const HandModel& model, const FingerCurls& curls, const Pose& baseFromWrist,
                 JointPoses& outPoses, JointRadii& outRadii) {
  JointPoses hand;
  model.pose(curls, hand);
  for (int j = 0; j < kJointCount; ++j) {
    outPoses[j] = baseFromWrist * hand[j];
    outRadii[j] = model.jointRadius(static_cast<Joint>(j));
  }
}

void replaceFingers(const HandModel& model, const FingerJointCurls& curls,
                    const std::array<bool, kFingerCount>& replace, const Pose& baseFromWrist,
                    JointPoses& inOutPoses) {
  std::array<Pose, 5> finger;
  for (int f = 0; f < kFingerCount; ++f) {
    if (!replace[f]) continue;
    const auto joints = fingerJoints(static_cast<Finger>(f));
    model.fingerPose(static_cast<Finger>(f), curls[f],
                     std::span<Pose>(finger.data(), joints.size()));
    for (size_t k = 0; k < joints.size(); ++k)
      inOutPoses[size_t(joints[k])] = baseFromWrist * finger[k];
  }
}

}  // namespace sdfg
