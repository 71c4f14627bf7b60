// Kinematic hand model: the 26 joints of XR_EXT_hand_tracking, finger curl and its curves.
//
// Joint order and axes follow XR_EXT_hand_tracking: per joint, -Z points along the bone toward
// the fingertip, +Y out of the back of the hand (the nail side), X = Y x Z. Hand space is the
// wrist joint's frame. The left hand is the right hand mirrored in X.
//
// Each finger has an open and a closed pose (local joint rotations; the thumb opposes). A curl
// `a` in [0,1] blends them per joint with slerp, and forward kinematics gives every joint, so
// each point of a finger moves on a fixed curve in hand space as `a` goes from 0 to 1.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "base/pose.h"
#include "base/status.h"

namespace sdfg {

enum class Hand : uint8_t { left, right };

// Same values as XrHandJointEXT.
enum class Joint : uint8_t {
  palm = 0,
  wrist,
  thumb_metacarpal,
  thumb_proximal,
  thumb_distal,
  thumb_tip,
  index_metacarpal,
  index_proximal,
  index_intermediate,
  index_distal,
  index_tip,
  middle_metacarpal,
  middle_proximal,
  middle_intermediate,
  middle_distal,
  middle_tip,
  ring_metacarpal,
  ring_proximal,
  ring_intermediate,
  ring_distal,
  ring_tip,
  little_metacarpal,
  little_proximal,
  little_intermediate,
  little_distal,
  little_tip,
};
inline constexpr int kJointCount = 26;

enum class Finger : uint8_t { thumb, index, middle, ring, little };
inline constexpr int kFingerCount = 5;

using JointPoses = std::array<Pose, kJointCount>;
using FingerCurls = std::array<float, kFingerCount>;
// Curl of each rotating joint of one finger, in fingerJoints() order without the tip
// (metacarpal, proximal, [intermediate,] distal); the thumb uses the first three. Whole-finger
// strategies stop each joint on its own; a single curl `a` means all entries equal `a`.
using JointCurls = std::array<float, 4>;

const char* jointName(Joint joint);
const char* fingerName(Finger finger);

// The unit direction the palm side of the hand faces, from the palm joint's pose: its -Y (the
// OpenXR hand joints' convention).
inline glm::vec3 palmFacing(const Pose& palm) {
  return palm.transformVector(glm::vec3(0.0f, -1.0f, 0.0f));
}

// Joints of a finger from its metacarpal to its tip: 4 for the thumb (it has no intermediate
// phalanx), 5 for the others.
std::span<const Joint> fingerJoints(Finger finger);
Joint tipJoint(Finger finger);

// A sphere on the surface model of the hand: joint spheres and points between them.
struct BodySphere {
  glm::vec3 center{0.0f};  // hand space
  float radius = 0.0f;
  uint8_t bone = 0;  // index into fingerJoints(): the sphere lies on the bone that starts there
};

class HandModel {
 public:
  // A default adult hand. Bone lengths and joint radii from anthropometric data (see
  // docs/hand-model.md for sources); `scale` multiplies every length and radius.
  static HandModel defaultAdult(Hand side, float scale = 1.0f);

  // Fits bone lengths and joint radii to a measured hand: 26 tracked joint poses in any common
  // space (an open, flat hand gives the best fit) and their radii. Keeps this model's curl poses.
  // Fails on non-finite input or bones shorter than a millimetre.
  static Result<HandModel> fitToJoints(Hand side, std::span<const Pose, kJointCount> joints,
                                       std::span<const float, kJointCount> radii);

  Hand side() const { return side_; }
  float jointRadius(Joint joint) const;
  float tipRadius(Finger finger) const { return jointRadius(tipJoint(finger)); }
  // Length of the bone from `joint` to the next joint toward the tip (0 for tips).
  float boneLength(Joint joint) const;

  // All 26 joints in hand space for the given per-finger curls (clamped to [0,1]).
  void pose(const FingerCurls& curls, JointPoses& out) const;

  // One finger's joints (fingerJoints(finger) order) in hand space at curl `a`.
  // `out` must hold fingerJoints(finger).size() poses.
  void fingerPose(Finger finger, float a, std::span<Pose> out) const;

  // Same, with a curl per joint.
  void fingerPose(Finger finger, const JointCurls& curls, std::span<Pose> out) const;

  glm::vec3 tipPosition(Finger finger, float a) const;

  // The tip's curve sampled at a_k = min(k * da, 1), k = 0, 1, ... up to and including a = 1.
  // Any da in (0, 1]; returns an empty vector otherwise, and for da < kMinCurveStep (more than
  // 100001 samples), so a stray tiny step cannot exhaust memory.
  std::vector<glm::vec3> tipCurve(Finger finger, float da) const;
  // Curl values of tipCurve() samples: a_k = min(k * da, 1).
  static std::vector<float> curveParameters(float da);
  static constexpr float kMinCurveStep = 1e-5f;

  // Spheres covering every phalanx of the finger at curl `a` (from the proximal phalanx to the
  // tip), spaced so neighbours overlap by at least half the smaller radius. Appends to `out`.
  void phalanxSpheres(Finger finger, float a, std::vector<BodySphere>& out) const;

  // The user's own curl per finger, estimated from tracked joints expressed in this hand's
  // space: the curl whose pose best matches the measured flexion. Used to never open a finger
  // further than the user holds it.
  FingerCurls estimateCurls(std::span<const Pose, kJointCount> handSpaceJoints) const;
  // The same for one finger (a fifth of the work: a search over the curl, tens of microseconds
  // for the whole hand).
  float estimateCurl(Finger finger, std::span<const Pose, kJointCount> handSpaceJoints) const;

 private:
  struct JointRig {
    glm::vec3 offset{0.0f};                // position in the parent joint's frame
    glm::quat openRotation{1, 0, 0, 0};    // local rotation relative to the parent, a = 0
    glm::quat closedRotation{1, 0, 0, 0};  // local rotation relative to the parent, a = 1
    float radius = 0.0f;
  };

  // Precomputed form of the slerp from openRotation to closedRotation (shortest path):
  // local(a) = openRotation * angleAxis(a * angle, axis). Keeps acos out of the solver loops.
  struct CurlStep {
    glm::vec3 axis{1.0f, 0.0f, 0.0f};
    float angle = 0.0f;
  };

  void updateCurlSteps();
  glm::quat localRotation(int joint, float a) const;

  Hand side_ = Hand::right;
  std::array<JointRig, kJointCount> rig_{};
  std::array<CurlStep, kJointCount> curl_{};
};

}  // namespace sdfg
