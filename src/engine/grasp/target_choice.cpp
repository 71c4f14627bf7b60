#include "grasp/target_choice.h"

#include <array>
#include <cmath>
#include <limits>

namespace sdfg {
namespace {

// Unsigned distance from a hand-space point to one member's surface.
float distanceTo(const SceneMember& m, const glm::vec3& hand) {
  const glm::vec3 p = m.objectFromHand.transformPoint(hand);
  if (m.mesh != nullptr) return m.mesh->closest(p).distance;
  glm::vec3 unused;
  return std::abs(closestOfSolid(m, p, unused));
}

// The member whose surface the ray from `origin` along `direction` meets first within
// kFacingRange (sphere tracing on the exact distances); -1 when none.
int facedMember(size_t count, const ExactDistanceSource& scene, const glm::vec3& origin,
                const glm::vec3& direction) {
  constexpr float kHit = 0.001f;  // metres: the ray has met a surface
  constexpr int kSteps = 128;
  std::array<glm::vec3, 1> point{};
  std::array<float, 1> bound{};
  std::array<ExactSample, 1> found{};
  float t = 0.0f;
  for (int step = 0; step < kSteps && t < kFacingRange; ++step) {
    point[0] = origin + direction * t;
    bound[0] = kFacingRange - t;
    found[0] = ExactSample{};
    scene.sample(point, bound, found);
    if (!std::isfinite(found[0].distance) || found[0].member >= count) return -1;
    const float d = std::abs(found[0].distance);
    if (d < kHit) return int(found[0].member);
    t += d;
  }
  return -1;
}

}  // namespace

GraspChoice chooseTarget(std::span<const SceneMember> members, const ExactDistanceSource& scene,
                         const GraspResult& result, const glm::vec3& palm, float palmRadius,
                         const glm::vec3& palmNormal, float reach) {
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
  out.faced = facedMember(members.size(), scene, palmScene,
                          glm::normalize(result.handCorrection.transformVector(palmNormal)));
  if (out.faced >= 0 && members[size_t(out.faced)].graspable) {
    const size_t m = size_t(out.faced);
    if (count[m] > 0 || distanceTo(members[m], palmScene) - palmRadius <= kFacedTouch) {
      out.member = out.faced;
      out.fingersOnChoice = count[m];
      return out;
    }
  }
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
