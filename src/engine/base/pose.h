// Rigid transforms (rotation + translation) used across the core.
//
// A Pose maps points from a child frame into its parent frame: parent = R * child + t.
// Naming convention: `aFromB` maps B-space points into A-space, so
// `objectFromHand * handFromBox == objectFromBox`.
#pragma once

#include <algorithm>
#include <cmath>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

namespace sdfg {

struct Pose {
  glm::quat orientation{1.0f, 0.0f, 0.0f, 0.0f};  // unit quaternion (w, x, y, z)
  glm::vec3 position{0.0f};

  glm::vec3 transformPoint(const glm::vec3& p) const { return orientation * p + position; }
  glm::vec3 transformVector(const glm::vec3& v) const { return orientation * v; }

  Pose inverse() const {
    const glm::quat inv = glm::conjugate(orientation);
    return Pose{inv, inv * -position};
  }

  // Composition: (a * b).transformPoint(p) == a.transformPoint(b.transformPoint(p)).
  friend Pose operator*(const Pose& a, const Pose& b) {
    return Pose{glm::normalize(a.orientation * b.orientation), a.transformPoint(b.position)};
  }
};

// The angle of the rotation `q` (radians, in [0, pi]).
inline float rotationAngle(const glm::quat& q) {
  return 2.0f * std::acos(std::min(1.0f, std::abs(q.w)));
}

}  // namespace sdfg
