#include "scene/scene_index.h"

#include <algorithm>
#include <limits>

#include <glm/common.hpp>

namespace sdfg {

Aabb transformedBounds(const Pose& parentFromChild, const Aabb& b) {
  glm::vec3 lo(std::numeric_limits<float>::infinity()), hi(-lo);
  for (int c = 0; c < 8; ++c) {
    const glm::vec3 corner((c & 1) ? b.max.x : b.min.x, (c & 2) ? b.max.y : b.min.y,
                           (c & 4) ? b.max.z : b.min.z);
    const glm::vec3 p = parentFromChild.transformPoint(corner);
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  return Aabb{lo, hi};
}

void SceneIndex::attach(uint64_t target, Entry& e) {
  Group& g = groups_[e.space];
  if (e.bounds) {
    e.proxy = g.tree.insert(transformedBounds(e.spaceFromObject, *e.bounds), target);
  } else {
    g.planes.push_back(target);
  }
}

void SceneIndex::detach(uint64_t target, Entry& e) {
  auto it = groups_.find(e.space);
  if (it == groups_.end()) return;
  if (e.proxy != AabbTree::kNone) {
    it->second.tree.remove(e.proxy);
    e.proxy = AabbTree::kNone;
  } else {
    std::erase(it->second.planes, target);
  }
  if (it->second.tree.size() == 0 && it->second.planes.empty()) groups_.erase(it);
}

void SceneIndex::place(uint64_t target, uint64_t space, const Pose& spaceFromObject,
                       const std::optional<Aabb>& bounds) {
  auto it = targets_.find(target);
  if (it != targets_.end()) {
    Entry& e = it->second;
    // The same space and a box still bounded: the tree keeps its leaf while the new bounds fit.
    if (e.space == space && e.bounds && bounds) {
      e.spaceFromObject = spaceFromObject;
      e.bounds = bounds;
      groups_[space].tree.update(e.proxy, transformedBounds(spaceFromObject, *bounds));
      return;
    }
    detach(target, e);
    targets_.erase(it);
  }
  Entry e;
  e.space = space;
  e.spaceFromObject = spaceFromObject;
  e.bounds = bounds;
  attach(target, e);
  targets_.emplace(target, e);
}

void SceneIndex::setBounds(uint64_t target, const Aabb& bounds) {
  auto it = targets_.find(target);
  if (it == targets_.end() || !it->second.bounds) return;
  place(target, it->second.space, it->second.spaceFromObject, bounds);
}

void SceneIndex::remove(uint64_t target) {
  auto it = targets_.find(target);
  if (it == targets_.end()) return;
  detach(target, it->second);
  targets_.erase(it);
}

void SceneIndex::setSpaces(std::span<const SpaceFrame> spaces) {
  located_.clear();
  for (const SpaceFrame& s : spaces) {
    if (s.valid) located_[s.space] = s.worldFromSpace;
  }
}

std::optional<Pose> SceneIndex::worldFromObject(uint64_t target) const {
  auto it = targets_.find(target);
  if (it == targets_.end()) return std::nullopt;
  auto at = located_.find(it->second.space);
  if (at == located_.end()) return std::nullopt;
  return at->second * it->second.spaceFromObject;
}

std::optional<Aabb> SceneIndex::bounds(uint64_t target, bool* plane) const {
  auto it = targets_.find(target);
  if (plane != nullptr) *plane = it != targets_.end() && !it->second.bounds;
  if (it == targets_.end()) return std::nullopt;
  return it->second.bounds;
}

void SceneIndex::query(const Pose& worldFromBox, const glm::vec3& half,
                       std::vector<SceneHit>& out) const {
  const size_t first = out.size();
  const Aabb boxLocal{-half, half};
  for (const auto& [space, group] : groups_) {
    auto at = located_.find(space);
    if (at == located_.end()) continue;
    const Pose& worldFromSpace = at->second;
    const Pose spaceFromBox = worldFromSpace.inverse() * worldFromBox;
    const Pose boxFromSpace = spaceFromBox.inverse();
    group.tree.query(transformedBounds(spaceFromBox, boxLocal), [&](uint64_t target) {
      const Entry& e = targets_.at(target);
      // The target's bounds seen from the box: a box-space AABB of its eight corners.
      const Aabb seen = transformedBounds(boxFromSpace * e.spaceFromObject, *e.bounds);
      if (overlaps(seen, boxLocal))
        out.push_back(SceneHit{target, worldFromSpace * e.spaceFromObject});
    });
    for (uint64_t target : group.planes) {
      const Entry& e = targets_.at(target);
      const Pose planeFromBox = e.spaceFromObject.inverse() * spaceFromBox;
      float lowest = std::numeric_limits<float>::infinity();
      for (int c = 0; c < 8; ++c) {
        const glm::vec3 corner((c & 1) ? half.x : -half.x, (c & 2) ? half.y : -half.y,
                               (c & 4) ? half.z : -half.z);
        lowest = std::min(lowest, planeFromBox.transformPoint(corner).y);
      }
      if (lowest <= 0.0f) out.push_back(SceneHit{target, worldFromSpace * e.spaceFromObject});
    }
  }
  std::sort(out.begin() + std::ptrdiff_t(first), out.end(),
            [](const SceneHit& a, const SceneHit& b) { return a.target < b.target; });
}

}  // namespace sdfg
