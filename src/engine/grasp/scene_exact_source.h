// The exact distance of a whole grasp scene: at each point, the nearest surface of any member
// (mesh or analytic shape), signed as the union of their solids (the least signed distance), and
// which member it belongs to. "ours" checks its stops and clears the hand on it, so no hand part
// ends inside any object in the box, whoever owns it; target_choice.h reads the owners.
#pragma once

#include <limits>
#include <span>
#include <vector>

#include "grasp/solver.h"
#include "scene/scene.h"

namespace sdfg {

class SceneExactSource final : public ExactDistanceSource {
 public:
  // Keeps a reference to `members` (and through them to their meshes and shapes): the caller
  // keeps them alive and unchanged while solves run. At most kMaxSceneMembers.
  explicit SceneExactSource(std::span<const SceneMember> members);
  // ExactSample::member is the index into `members`; `feature` packs it with the member's own
  // feature (a mesh's triangle), so a hint finds its member again.
  void sample(std::span<const glm::vec3> handPoints, std::span<const float> maxDistances,
              std::span<ExactSample> out) const override;

  std::span<const SceneMember> members() const { return members_; }
  // The member a feature id belongs to (max() for none).
  static uint32_t memberOf(uint32_t feature) {
    return feature == kNoFeature ? kNoFeature : feature >> kTriangleBits;
  }

 private:
  static constexpr uint32_t kNoFeature = std::numeric_limits<uint32_t>::max();
  static constexpr int kTriangleBits = 24;  // meshes have fewer than 2^24 triangles
  std::span<const SceneMember> members_;
  std::vector<Pose> handFromObject_;
};

}  // namespace sdfg
