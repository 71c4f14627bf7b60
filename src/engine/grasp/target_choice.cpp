#include "grasp/target_choice.h"

#include <cmath>
#include <limits>

namespace sdfg {
namespace {

// Unsigned distance from a hand-space point to one member's surface.
float distanceTo(const SceneMember& m, const glm::vec3& hand) {
  const glm::vec3 p = m.objectFromHand.transformPoint(hand);
  if (m.mesh != nullptr) return m.mesh->closest(p).distance;
  glm::vec3 unused;
  return std::abs(m.shape->closest(p, unused));
}

}  // namespace

GraspChoice chooseTarget(std::span<const SceneMember> members, const ExactDistanceSource& scene,
                         const GraspResult& result, const glm::vec3& palm, float palmRadius,
                         float reach) {
  GraspChoice out;
  std::array<glm::vec3, 1> point{};
  std::array<float, 1> bound{reach};
  std::array<ExactSample, 1> found{};
  std::vector<int> count(members.size(), 0);
  for (int f = 0; f < kFingerCount; ++f) {
    const FingerState& fs = result.fingers[size_t(f)];
    if (!fs.contact) continue;
    // Contact points are in the corrected hand frame; the source answers in the scene's.
    point[0] = result.handCorrection.transformPoint(fs.contactPoint);
    found[0] = ExactSample{};
    scene.sample(point, bound, found);
    if (found[0].member >= members.size()) continue;
    out.touched[size_t(f)] = int(found[0].member);
    ++count[found[0].member];
  }
  const glm::vec3 palmScene = result.handCorrection.transformPoint(palm);
  float bestPalm = std::numeric_limits<float>::infinity();
  for (size_t m = 0; m < members.size(); ++m) {
    if (!members[m].graspable) continue;
    if (out.member >= 0 && count[m] < out.fingersOnChoice) continue;
    const float palmDistance = distanceTo(members[m], palmScene);
    // Untouched: no finger on it, and the palm's surface not near it.
    if (count[m] == 0 && palmDistance - palmRadius > kPalmTouch) continue;
    const bool better =
        out.member < 0 || count[m] > out.fingersOnChoice || palmDistance < bestPalm ||
        (palmDistance == bestPalm && members[m].id < members[size_t(out.member)].id);
    if (!better) continue;
    out.member = int(m);
    out.fingersOnChoice = count[m];
    bestPalm = palmDistance;
  }
  return out;
}

}  // namespace sdfg
