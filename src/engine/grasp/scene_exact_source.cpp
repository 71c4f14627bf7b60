#include "grasp/scene_exact_source.h"

#include <algorithm>
#include <cmath>

namespace sdfg {

SceneExactSource::SceneExactSource(std::span<const SceneMember> members)
    : members_(members.first(std::min(members.size(), kMaxSceneMembers))) {
  handFromObject_.reserve(members_.size());
  for (const SceneMember& m : members_) handFromObject_.push_back(m.objectFromHand.inverse());
}

void SceneExactSource::sample(std::span<const glm::vec3> handPoints,
                              std::span<const float> maxDistances,
                              std::span<ExactSample> out) const {
  if (handPoints.size() != maxDistances.size() || handPoints.size() != out.size()) return;
  constexpr uint32_t kTriangleMask = (1u << kTriangleBits) - 1u;
  for (size_t i = 0; i < handPoints.size(); ++i) {
    ExactSample& o = out[i];
    const uint32_t hintMember = memberOf(o.feature);
    const uint32_t hintTriangle = o.feature & kTriangleMask;
    o = ExactSample{};
    for (size_t m = 0; m < members_.size(); ++m) {
      const SceneMember& member = members_[m];
      const glm::vec3 p = member.objectFromHand.transformPoint(handPoints[i]);
      glm::vec3 closest(0.0f);
      float d;
      uint32_t triangle = 0;
      if (member.mesh != nullptr) {
        d = member.mesh->localSignedDistanceNear(
            p, maxDistances[i], hintMember == m ? hintTriangle : kNoFeature, &closest, &triangle);
      } else {
        d = closestOfSolid(member, p, closest);
        // A volume knows of no surface farther than its band (it reads the band's edge there).
        const bool beyondBand = member.volume != nullptr && d >= member.volume->truncation();
        if (std::abs(d) > maxDistances[i] || beyondBand) d = std::numeric_limits<float>::infinity();
      }
      // The union's signed distance is the least of the members'.
      if (!(d < o.distance)) continue;
      o.distance = d;
      o.closest = handFromObject_[m].transformPoint(closest);
      o.member = uint32_t(m);
      o.feature = (uint32_t(m) << kTriangleBits) | (triangle & kTriangleMask);
    }
  }
}

}  // namespace sdfg
