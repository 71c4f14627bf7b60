#include "grasp/hand_offset_blend.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/quaternion.hpp>

namespace sdfg {

void advanceHandOffset(HandOffset& o, const HandGrasp& g, int64_t now, float blendTime) {
  const bool held = g.shown();
  if (held) {
    // Nothing shown yet: the new grasp's correction is taken whole, the blend brings it in.
    if (o.blend <= 0.0f) o.current = g.result.handCorrection;
    o.solved = g.result.handCorrection;
    o.openClearance = std::isfinite(g.result.openClearance) ? g.result.openClearance : 0.0f;
    o.displacement = g.result.handMoved;
    o.exceeded = g.result.clearanceExceeded;
  }
  const double dt = o.last == 0 || now <= o.last ? 0.0 : double(now - o.last) * 1e-9;
  o.last = now;
  const float step = blendTime > 0.0f ? float(std::min(dt, 0.25) / blendTime) : 1.0f;
  o.blend = std::clamp(o.blend + (held ? step : -step), 0.0f, 1.0f);
  const float follow = std::min(step, 1.0f);
  o.current.position = glm::mix(o.current.position, o.solved.position, follow);
  o.current.orientation =
      glm::normalize(glm::slerp(o.current.orientation, o.solved.orientation, follow));
}

namespace {

// Smoothstep: the hand starts and ends its move at rest.
float blendWeight(float blend) {
  return blend * blend * (3.0f - 2.0f * blend);
}

}  // namespace

float shownClosing(const HandOffset& o) {
  constexpr float kStill = 1e-4f;  // metres: a correction this small is shown at once
  return o.displacement <= kStill ? 1.0f : blendWeight(o.blend);
}

Pose shownHandOffset(const HandOffset& o) {
  if (o.blend <= 0.0f) return Pose{};
  const float w = blendWeight(o.blend);
  Pose p;
  p.position = o.current.position * w;
  p.orientation =
      glm::normalize(glm::slerp(glm::quat(1.0f, 0.0f, 0.0f, 0.0f), o.current.orientation, w));
  return p;
}

void applyHandOffset(const Pose& offset, JointPoses& joints) {
  const Pose wrist = joints[size_t(Joint::wrist)];
  const Pose move = wrist * offset * wrist.inverse();
  for (Pose& j : joints) j = move * j;
}

}  // namespace sdfg
