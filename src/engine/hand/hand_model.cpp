// Kinematic hand model: default adult rig, forward kinematics, tip curves, fitting to tracked
// joints and curl estimation. Geometry, sources and poses are described in docs/hand-model.md.
#include "hand/hand_model.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtx/quaternion.hpp>

namespace sdfg {
namespace {

constexpr std::array<Joint, 4> kThumbJoints{Joint::thumb_metacarpal, Joint::thumb_proximal,
                                            Joint::thumb_distal, Joint::thumb_tip};
constexpr std::array<Joint, 5> kIndexJoints{Joint::index_metacarpal, Joint::index_proximal,
                                            Joint::index_intermediate, Joint::index_distal,
                                            Joint::index_tip};
constexpr std::array<Joint, 5> kMiddleJoints{Joint::middle_metacarpal, Joint::middle_proximal,
                                             Joint::middle_intermediate, Joint::middle_distal,
                                             Joint::middle_tip};
constexpr std::array<Joint, 5> kRingJoints{Joint::ring_metacarpal, Joint::ring_proximal,
                                           Joint::ring_intermediate, Joint::ring_distal,
                                           Joint::ring_tip};
constexpr std::array<Joint, 5> kLittleJoints{Joint::little_metacarpal, Joint::little_proximal,
                                             Joint::little_intermediate, Joint::little_distal,
                                             Joint::little_tip};

constexpr int kMaxFingerJoints = 5;

int idx(Joint j) {
  return static_cast<int>(j);
}

// Axes of XR_EXT_hand_tracking: -Z along the bone, +Y out of the back of the hand. Flexion
// turns -Z toward -Y (the palm), a rotation about -X.
glm::quat flexion(float degrees) {
  return glm::angleAxis(glm::radians(degrees), glm::vec3(-1.0f, 0.0f, 0.0f));
}
// Spread toward -X, the thumb side of a right hand (negative: toward the little finger).
glm::quat spreadTowardThumb(float degrees) {
  return glm::angleAxis(glm::radians(degrees), glm::vec3(0.0f, 1.0f, 0.0f));
}
// Rotation about the bone's own axis; positive turns +Y (the nail) toward -X.
glm::quat twist(float degrees) {
  return glm::angleAxis(glm::radians(degrees), glm::vec3(0.0f, 0.0f, 1.0f));
}

bool finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
bool finite(const glm::quat& q) {
  return std::isfinite(q.w) && std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z);
}

// NaN reads as 0 (open): a bad curl must never produce a NaN pose.
float clampCurl(float a) {
  return a > 0.0f ? (a < 1.0f ? a : 1.0f) : 0.0f;
}

// Right hand -> left hand: reflection in X. Positions x -> -x; a rotation about axis n by
// angle t becomes a rotation about (n.x, -n.y, -n.z) by t, i.e. (w, x, y, z) -> (w, x, -y, -z).
glm::vec3 mirror(const glm::vec3& v) {
  return {-v.x, v.y, v.z};
}
glm::quat mirror(const glm::quat& q) {
  return glm::quat(q.w, q.x, -q.y, -q.z);
}

// ---- Default adult hand --------------------------------------------------------------------
// Hand length (wrist crease to middle fingertip) of the reference adult, metres; see the doc.
constexpr float kHandLength = 0.190f;

// Segment lengths as fractions of hand length, Buchholz, Armstrong & Goldstein (1992):
// metacarpal, proximal, intermediate, distal (to the fingertip). The thumb has no
// intermediate phalanx: metacarpal, proximal, distal.
constexpr float kThumbRatio[3] = {0.251f, 0.196f, 0.158f};
constexpr float kFingerRatio[4][4] = {
    {0.374f, 0.265f, 0.143f, 0.097f},  // index
    {0.373f, 0.277f, 0.170f, 0.108f},  // middle
    {0.336f, 0.259f, 0.165f, 0.107f},  // ring
    {0.295f, 0.206f, 0.117f, 0.093f},  // little
};
// The middle finger's CMC joint lies 0.073 hand lengths distal of the wrist crease in the same
// data (the five middle-finger segments then sum to 1.0).
constexpr float kCmcDistal = 0.073f;

// Right hand, metres at scale 1. CMC bases across the carpus and knuckle (MCP) positions across
// the palm; the metacarpals splay from one to the other.
constexpr float kCmcX[4] = {-0.011f, 0.0f, 0.011f, 0.020f};
constexpr float kKnuckleX[4] = {-0.022f, 0.0f, 0.019f, 0.036f};
// Extra spread of the open proximal phalanx relative to its metacarpal (toward the thumb).
constexpr float kOpenSpread[4] = {0.0f, 0.0f, -3.0f, -3.0f};
// Closed fist, flexion in degrees: MCP, PIP, DIP. Tuned per finger so the closed tip sphere
// rests on the palm surface instead of sinking into it.
constexpr float kClosedFlex[4][3] = {
    {90.0f, 100.0f, 70.0f},  // index
    {90.0f, 100.0f, 70.0f},  // middle
    {88.0f, 100.0f, 70.0f},  // ring
    {82.0f, 100.0f, 68.0f},  // little
};

// Joint radii (metres at scale 1): half the finger breadth at each joint, rounded adult values.
constexpr float kPalmRadius = 0.015f;
constexpr float kWristRadius = 0.020f;
constexpr float kThumbRadius[4] = {0.015f, 0.0115f, 0.0105f, 0.0090f};
constexpr float kFingerRadius[4][5] = {
    {0.013f, 0.0105f, 0.0100f, 0.0090f, 0.0075f},  // index
    {0.013f, 0.0105f, 0.0103f, 0.0092f, 0.0078f},  // middle
    {0.012f, 0.0100f, 0.0097f, 0.0086f, 0.0073f},  // ring
    {0.012f, 0.0090f, 0.0085f, 0.0076f, 0.0066f},  // little
};

// Thumb, right hand: CMC base position and the metacarpal's orientation relative to the wrist,
// built as yaw (toward the thumb side) * pitch (toward the palm) * twist (nail turned radially).
constexpr glm::vec3 kThumbBase{-0.019f, -0.012f, -0.016f};
struct ThumbPose {
  float yaw, pitch, roll;  // metacarpal: toward the thumb side, toward the palm, nail radially
  float mcpFlex, ipFlex;   // proximal and distal phalanx flexion
  float mcpSpread;         // proximal spread toward the thumb side (open pose only)
};
constexpr ThumbPose kThumbOpen{40.0f, 0.0f, 60.0f, 0.0f, 0.0f, 0.0f};
constexpr ThumbPose kThumbClosed{22.0f, 36.5f, 62.5f, 29.0f, 80.0f, 0.0f};

glm::quat thumbMetacarpal(const ThumbPose& t) {
  return spreadTowardThumb(t.yaw) * flexion(t.pitch) * twist(t.roll);
}

}  // namespace

// ---- Names and tables -----------------------------------------------------------------------

const char* jointName(Joint joint) {
  static constexpr const char* kNames[kJointCount] = {
      "palm",
      "wrist",
      "thumb_metacarpal",
      "thumb_proximal",
      "thumb_distal",
      "thumb_tip",
      "index_metacarpal",
      "index_proximal",
      "index_intermediate",
      "index_distal",
      "index_tip",
      "middle_metacarpal",
      "middle_proximal",
      "middle_intermediate",
      "middle_distal",
      "middle_tip",
      "ring_metacarpal",
      "ring_proximal",
      "ring_intermediate",
      "ring_distal",
      "ring_tip",
      "little_metacarpal",
      "little_proximal",
      "little_intermediate",
      "little_distal",
      "little_tip",
  };
  const int i = idx(joint);
  return i >= 0 && i < kJointCount ? kNames[i] : "unknown";
}

const char* fingerName(Finger finger) {
  switch (finger) {
    case Finger::thumb:
      return "thumb";
    case Finger::index:
      return "index";
    case Finger::middle:
      return "middle";
    case Finger::ring:
      return "ring";
    case Finger::little:
      return "little";
  }
  return "unknown";
}

std::span<const Joint> fingerJoints(Finger finger) {
  switch (finger) {
    case Finger::thumb:
      return kThumbJoints;
    case Finger::index:
      return kIndexJoints;
    case Finger::middle:
      return kMiddleJoints;
    case Finger::ring:
      return kRingJoints;
    case Finger::little:
      return kLittleJoints;
  }
  return {};
}

Joint tipJoint(Finger finger) {
  const auto joints = fingerJoints(finger);
  return joints.empty() ? Joint::wrist : joints.back();
}

// ---- Construction ---------------------------------------------------------------------------

HandModel HandModel::defaultAdult(Hand side, float scale) {
  if (!(scale > 0.0f) || !std::isfinite(scale)) scale = 1.0f;
  HandModel m;
  m.side_ = side;
  auto& rig = m.rig_;
  const float L = kHandLength * scale;

  rig[idx(Joint::wrist)].radius = kWristRadius * scale;

  // Thumb.
  {
    const auto& j = kThumbJoints;
    rig[idx(j[0])].offset = kThumbBase * scale;
    rig[idx(j[0])].openRotation = thumbMetacarpal(kThumbOpen);
    rig[idx(j[0])].closedRotation = thumbMetacarpal(kThumbClosed);
    rig[idx(j[1])].openRotation =
        spreadTowardThumb(kThumbOpen.mcpSpread) * flexion(kThumbOpen.mcpFlex);
    rig[idx(j[1])].closedRotation =
        spreadTowardThumb(kThumbClosed.mcpSpread) * flexion(kThumbClosed.mcpFlex);
    rig[idx(j[2])].openRotation = flexion(kThumbOpen.ipFlex);
    rig[idx(j[2])].closedRotation = flexion(kThumbClosed.ipFlex);
    for (int b = 0; b < 3; ++b) {
      rig[idx(j[b + 1])].offset = glm::vec3(0.0f, 0.0f, -kThumbRatio[b] * L);
    }
    for (int k = 0; k < 4; ++k) rig[idx(j[k])].radius = kThumbRadius[k] * scale;
  }

  // Index to little.
  for (int f = 0; f < 4; ++f) {
    const auto joints = fingerJoints(static_cast<Finger>(f + 1));
    const float mcLength = kFingerRatio[f][0] * L;
    const float lateral = (kKnuckleX[f] - kCmcX[f]) * scale;
    const float splay = glm::degrees(std::asin(std::clamp(lateral / mcLength, -1.0f, 1.0f)));
    JointRig& mc = rig[idx(joints[0])];
    mc.offset = glm::vec3(kCmcX[f], 0.0f, -kCmcDistal * kHandLength) * scale;
    // A positive lateral step is toward +X, the little-finger side of a right hand.
    mc.openRotation = spreadTowardThumb(-splay);
    mc.closedRotation = mc.openRotation;  // the carpometacarpal joints are held fixed
    JointRig& pp = rig[idx(joints[1])];
    pp.openRotation = spreadTowardThumb(kOpenSpread[f]);
    pp.closedRotation = pp.openRotation * flexion(kClosedFlex[f][0]);
    rig[idx(joints[2])].closedRotation = flexion(kClosedFlex[f][1]);
    rig[idx(joints[3])].closedRotation = flexion(kClosedFlex[f][2]);
    for (int b = 0; b < 4; ++b) {
      rig[idx(joints[b + 1])].offset = glm::vec3(0.0f, 0.0f, -kFingerRatio[f][b] * L);
    }
    for (int k = 0; k < 5; ++k) rig[idx(joints[k])].radius = kFingerRadius[f][k] * scale;
  }

  // Palm: centre of the middle metacarpal, oriented like it.
  {
    const JointRig& mc = rig[idx(Joint::middle_metacarpal)];
    const float len = glm::length(rig[idx(Joint::middle_proximal)].offset);
    JointRig& palm = rig[idx(Joint::palm)];
    palm.offset = mc.offset + mc.openRotation * glm::vec3(0.0f, 0.0f, -0.5f * len);
    palm.openRotation = mc.openRotation;
    palm.closedRotation = mc.openRotation;
    palm.radius = kPalmRadius * scale;
  }

  if (side == Hand::left) {
    for (JointRig& r : rig) {
      r.offset = mirror(r.offset);
      r.openRotation = mirror(r.openRotation);
      r.closedRotation = mirror(r.closedRotation);
    }
  }
  m.updateCurlSteps();
  return m;
}

void HandModel::updateCurlSteps() {
  for (int j = 0; j < kJointCount; ++j) {
    glm::quat open = glm::normalize(rig_[j].openRotation);
    glm::quat closed = glm::normalize(rig_[j].closedRotation);
    // Shortest path, as glm::slerp: q and -q are the same rotation.
    if (glm::dot(open, closed) < 0.0f) closed = -closed;
    rig_[j].openRotation = open;
    rig_[j].closedRotation = closed;
    const glm::quat delta = glm::conjugate(open) * closed;
    const glm::vec3 v(delta.x, delta.y, delta.z);
    const float s = glm::length(v);
    CurlStep step;
    if (s > 1e-7f) {
      step.axis = v / s;
      step.angle = 2.0f * std::atan2(s, delta.w);
    }
    curl_[j] = step;
  }
}

glm::quat HandModel::localRotation(int joint, float a) const {
  const CurlStep& step = curl_[joint];
  if (step.angle == 0.0f) return rig_[joint].openRotation;
  const float half = 0.5f * a * step.angle;
  const float s = std::sin(half);
  const glm::quat partial(std::cos(half), step.axis.x * s, step.axis.y * s, step.axis.z * s);
  return rig_[joint].openRotation * partial;
}

// ---- Queries --------------------------------------------------------------------------------

float HandModel::jointRadius(Joint joint) const {
  const int i = idx(joint);
  return i >= 0 && i < kJointCount ? rig_[i].radius : 0.0f;
}

float HandModel::boneLength(Joint joint) const {
  for (int f = 0; f < kFingerCount; ++f) {
    const auto joints = fingerJoints(static_cast<Finger>(f));
    for (size_t k = 0; k + 1 < joints.size(); ++k) {
      if (joints[k] == joint) return glm::length(rig_[idx(joints[k + 1])].offset);
    }
  }
  return 0.0f;  // palm, wrist, tips
}

// ---- Forward kinematics ---------------------------------------------------------------------

void HandModel::fingerPose(Finger finger, const JointCurls& curls, std::span<Pose> out) const {
  const auto joints = fingerJoints(finger);
  assert(out.size() >= joints.size());
  if (out.size() < joints.size()) return;
  // Parent of every metacarpal is the wrist: hand-space origin, identity orientation.
  glm::quat q(1.0f, 0.0f, 0.0f, 0.0f);
  glm::vec3 p(0.0f);
  const size_t n = joints.size();
  for (size_t k = 0; k < n; ++k) {
    const int j = idx(joints[k]);
    p += q * rig_[j].offset;
    if (k + 1 < n) q = glm::normalize(q * localRotation(j, clampCurl(curls[k])));
    out[k] = Pose{q, p};  // the tip keeps the distal phalanx's orientation
  }
}

void HandModel::fingerPose(Finger finger, float a, std::span<Pose> out) const {
  const float c = clampCurl(a);
  fingerPose(finger, JointCurls{c, c, c, c}, out);
}

glm::vec3 HandModel::tipPosition(Finger finger, float a) const {
  std::array<Pose, kMaxFingerJoints> joints;
  fingerPose(finger, a, joints);
  return joints[fingerJoints(finger).size() - 1].position;
}

void HandModel::pose(const FingerCurls& curls, JointPoses& out) const {
  out[idx(Joint::wrist)] = Pose{};
  out[idx(Joint::palm)] = Pose{rig_[idx(Joint::palm)].openRotation, rig_[idx(Joint::palm)].offset};
  std::array<Pose, kMaxFingerJoints> joints;
  for (int f = 0; f < kFingerCount; ++f) {
    const Finger finger = static_cast<Finger>(f);
    fingerPose(finger, curls[f], joints);
    const auto ids = fingerJoints(finger);
    for (size_t k = 0; k < ids.size(); ++k) out[idx(ids[k])] = joints[k];
  }
}

// ---- Curves and surface spheres -------------------------------------------------------------

std::vector<float> HandModel::curveParameters(float da) {
  std::vector<float> params;
  if (!(da > 0.0f) || !(da <= 1.0f) || da < kMinCurveStep) return params;
  // Integer k, not an accumulated sum: the last sample is exactly 1 whatever da is. Products
  // within 1e-6 of 1 count as 1, so float rounding never adds a sliver step before the end.
  const double step = da;
  const auto last = static_cast<long>(std::ceil((1.0 - 1e-6) / step));
  params.reserve(static_cast<size_t>(last) + 1);
  for (long k = 0; k < last; ++k) params.push_back(static_cast<float>(k * step));
  params.push_back(1.0f);
  return params;
}

std::vector<glm::vec3> HandModel::tipCurve(Finger finger, float da) const {
  const std::vector<float> params = curveParameters(da);
  std::vector<glm::vec3> curve;
  curve.reserve(params.size());
  for (float a : params) curve.push_back(tipPosition(finger, a));
  return curve;
}

void HandModel::phalanxSpheres(Finger finger, float a, std::vector<BodySphere>& out) const {
  std::array<Pose, kMaxFingerJoints> joints;
  fingerPose(finger, a, joints);
  const auto ids = fingerJoints(finger);
  const size_t n = ids.size();
  for (size_t b = 1; b + 1 < n; ++b) {
    const glm::vec3 p0 = joints[b].position;
    const glm::vec3 p1 = joints[b + 1].position;
    const float r0 = rig_[idx(ids[b])].radius;
    const float r1 = rig_[idx(ids[b + 1])].radius;
    // Neighbours along the bone have radii >= min(r0, r1) and overlap by at least half the
    // smaller radius when their centres are at most 1.5 * min(r0, r1) apart.
    const float maxStep = 1.5f * std::max(std::min(r0, r1), 1e-5f);
    const float len = glm::length(p1 - p0);
    const int segments = std::max(1, static_cast<int>(std::ceil(len / maxStep)));
    const bool lastBone = b + 2 == n;  // only the last bone emits its end (the tip)
    const int count = lastBone ? segments + 1 : segments;
    for (int s = 0; s < count; ++s) {
      const float t = static_cast<float>(s) / static_cast<float>(segments);
      out.push_back(BodySphere{p0 + t * (p1 - p0), r0 + t * (r1 - r0), static_cast<uint8_t>(b)});
    }
  }
}

// ---- Fitting --------------------------------------------------------------------------------

Result<HandModel> HandModel::fitToJoints(Hand side, std::span<const Pose, kJointCount> joints,
                                         std::span<const float, kJointCount> radii) {
  for (int i = 0; i < kJointCount; ++i) {
    const Joint j = static_cast<Joint>(i);
    if (!finite(joints[i].position) || !finite(joints[i].orientation)) {
      return makeError(Status::invalid_argument,
                       std::string("hand fit: joint ") + jointName(j) + " is not finite");
    }
    if (glm::length(joints[i].orientation) < 0.5f) {
      return makeError(Status::invalid_argument, std::string("hand fit: joint ") + jointName(j) +
                                                     " has no valid orientation (norm < 0.5)");
    }
    if (!std::isfinite(radii[i]) || !(radii[i] > 0.0f)) {
      return makeError(Status::invalid_argument, std::string("hand fit: radius of joint ") +
                                                     jointName(j) + " is not a positive number");
    }
  }

  // Joint positions relative to the wrist: the fit is independent of the base space.
  const Pose wrist{glm::normalize(joints[idx(Joint::wrist)].orientation),
                   joints[idx(Joint::wrist)].position};
  const Pose handFromBase = wrist.inverse();
  std::array<glm::vec3, kJointCount> p;
  for (int i = 0; i < kJointCount; ++i) p[i] = handFromBase.transformPoint(joints[i].position);

  HandModel m = defaultAdult(side);
  for (int f = 0; f < kFingerCount; ++f) {
    const Finger finger = static_cast<Finger>(f);
    const auto ids = fingerJoints(finger);
    for (size_t k = 0; k + 1 < ids.size(); ++k) {
      const float len = glm::length(p[idx(ids[k + 1])] - p[idx(ids[k])]);
      if (!(len >= 1e-3f)) {
        return makeError(Status::invalid_argument,
                         std::string("hand fit: bone from ") + jointName(ids[k]) + " to " +
                             jointName(ids[k + 1]) + " is shorter than 1 mm");
      }
      m.rig_[idx(ids[k + 1])].offset = glm::vec3(0.0f, 0.0f, -len);
    }
    JointRig& mc = m.rig_[idx(ids[0])];
    mc.offset = p[idx(ids[0])];
    if (finger != Finger::thumb) {
      // Finger metacarpals do not move with curl, so their measured direction is reliable in
      // any pose: turn the model's metacarpal onto it (the curl rotations stay relative).
      const glm::vec3 measured = glm::normalize(p[idx(ids[1])] - p[idx(ids[0])]);
      const glm::vec3 model = mc.openRotation * glm::vec3(0.0f, 0.0f, -1.0f);
      const glm::quat fix = glm::rotation(model, measured);
      mc.openRotation = glm::normalize(fix * mc.openRotation);
      mc.closedRotation = glm::normalize(fix * mc.closedRotation);
    }
  }
  for (int i = 0; i < kJointCount; ++i) m.rig_[i].radius = radii[i];
  {
    const JointRig& mc = m.rig_[idx(Joint::middle_metacarpal)];
    const float len = glm::length(m.rig_[idx(Joint::middle_proximal)].offset);
    JointRig& palm = m.rig_[idx(Joint::palm)];
    palm.offset = mc.offset + mc.openRotation * glm::vec3(0.0f, 0.0f, -0.5f * len);
    palm.openRotation = mc.openRotation;
    palm.closedRotation = mc.openRotation;
  }
  m.updateCurlSteps();
  return m;
}

// ---- Curl estimation ------------------------------------------------------------------------

namespace {

// Flexion features of one finger from its joints (fingerJoints order): the angle of the
// metacarpal away from `restMetacarpal` (the thumb's opposition; ~0 for the other fingers),
// then the signed flexion at each following joint, positive toward the palm.
int flexionFeatures(std::span<const Pose> joints, const glm::vec3& restMetacarpal,
                    float out[kMaxFingerJoints]) {
  const size_t n = joints.size();
  glm::vec3 dirs[kMaxFingerJoints];
  for (size_t k = 0; k + 1 < n; ++k) {
    const glm::vec3 d = joints[k + 1].position - joints[k].position;
    const float len = glm::length(d);
    dirs[k] = len > 0.0f ? d / len : glm::vec3(0.0f, 0.0f, -1.0f);
  }
  int count = 0;
  out[count++] = std::acos(std::clamp(glm::dot(dirs[0], restMetacarpal), -1.0f, 1.0f));
  for (size_t k = 1; k + 1 < n; ++k) {
    // Flexion turns -Z toward -Y: a rotation about the joint's -X axis.
    const glm::vec3 flexAxis = joints[k].orientation * glm::vec3(-1.0f, 0.0f, 0.0f);
    const float s = glm::dot(glm::cross(dirs[k - 1], dirs[k]), flexAxis);
    const float c = glm::dot(dirs[k - 1], dirs[k]);
    out[count++] = std::atan2(s, c);
  }
  return count;
}

}  // namespace

float HandModel::estimateCurl(Finger finger,
                              std::span<const Pose, kJointCount> handSpaceJoints) const {
  std::array<Pose, kMaxFingerJoints> model;
  std::array<Pose, kMaxFingerJoints> measured;
  const auto ids = fingerJoints(finger);
  const size_t n = ids.size();
  for (size_t k = 0; k < n; ++k) {
    measured[k] = handSpaceJoints[idx(ids[k])];
    // Curl 0: never hold a finger closed on bad data.
    if (!finite(measured[k].position) || !finite(measured[k].orientation)) return 0.0f;
  }

  fingerPose(finger, 0.0f, model);
  const glm::vec3 rest = glm::normalize(model[1].position - model[0].position);
  float target[kMaxFingerJoints];
  const int count = flexionFeatures(std::span<const Pose>(measured.data(), n), rest, target);

  auto cost = [&](float a) {
    fingerPose(finger, a, model);
    float features[kMaxFingerJoints];
    flexionFeatures(std::span<const Pose>(model.data(), n), rest, features);
    float sum = 0.0f;
    for (int i = 0; i < count; ++i) sum += (features[i] - target[i]) * (features[i] - target[i]);
    return sum;
  };

  // Coarse scan, then golden-section search around the best sample.
  constexpr int kScan = 20;
  int best = 0;
  float bestCost = cost(0.0f);
  for (int i = 1; i <= kScan; ++i) {
    const float c = cost(static_cast<float>(i) / kScan);
    if (c < bestCost) bestCost = c, best = i;
  }
  float lo = std::max(0, best - 1) / static_cast<float>(kScan);
  float hi = std::min(kScan, best + 1) / static_cast<float>(kScan);
  constexpr float kInvPhi = 0.6180339887f;
  float x1 = hi - kInvPhi * (hi - lo);
  float x2 = lo + kInvPhi * (hi - lo);
  float c1 = cost(x1);
  float c2 = cost(x2);
  for (int it = 0; it < 24; ++it) {
    if (c1 < c2) {
      hi = x2, x2 = x1, c2 = c1;
      x1 = hi - kInvPhi * (hi - lo);
      c1 = cost(x1);
    } else {
      lo = x1, x1 = x2, c1 = c2;
      x2 = lo + kInvPhi * (hi - lo);
      c2 = cost(x2);
    }
  }
  const float refined = 0.5f * (lo + hi);
  return cost(refined) <= bestCost ? refined : static_cast<float>(best) / kScan;
}

FingerCurls HandModel::estimateCurls(std::span<const Pose, kJointCount> handSpaceJoints) const {
  FingerCurls curls{};
  for (int f = 0; f < kFingerCount; ++f) curls[f] = estimateCurl(Finger(f), handSpaceJoints);
  return curls;
}

}  // namespace sdfg
