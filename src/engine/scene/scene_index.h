// Where a session's targets are, for finding the few near a hand among many: the broad phase.
//
// A target is placed in a space (an opaque key: the layer's XrSpace) at a pose, and its bounds
// are known in its own frame. Targets are grouped by space, and each group keeps their bounds in
// the space's frame in an AabbTree, so a target that does not move in its space costs nothing per
// frame. Each frame the owner says where each space is (SpaceFrame); a query transforms the grab
// box into each located space and walks that space's tree: O(spaces * log targets), whatever the
// number of targets. Planes have no bounds and are kept beside the trees, tested one by one.
// Not thread-safe: its owner serializes calls.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <unordered_map>
#include <vector>

#include "base/pose.h"
#include "mesh/mesh.h"
#include "scene/aabb_tree.h"

namespace sdfg {

// Where a space is this frame, in the owner's common world space; `valid` false: not located
// (its targets take part in nothing this frame).
struct SpaceFrame {
  uint64_t space = 0;
  bool valid = false;
  Pose worldFromSpace;
};

// A target found near a box, and where it is in the world this frame.
struct SceneHit {
  uint64_t target = 0;
  Pose worldFromObject;
};

class SceneIndex {
 public:
  // Places `target` (new or not) in `space` at `spaceFromObject`. `bounds`: the target's bounds in
  // its own frame; nothing: unbounded (a plane, the frame's y = 0 with the solid below).
  void place(uint64_t target, uint64_t space, const Pose& spaceFromObject,
             const std::optional<Aabb>& bounds);
  // New bounds in the target's own frame (its vertices moved); unknown targets are ignored.
  void setBounds(uint64_t target, const Aabb& bounds);
  void remove(uint64_t target);
  bool contains(uint64_t target) const { return targets_.count(target) != 0; }
  size_t size() const { return targets_.size(); }

  // The spaces' poses for the queries that follow (replaces the last ones; spaces not listed are
  // not located). Copies them.
  void setSpaces(std::span<const SpaceFrame> spaces);
  // Adds one located space to those of the last setSpaces() (the session's own, such as the world).
  void locate(uint64_t space, const Pose& worldFromSpace) { located_[space] = worldFromSpace; }
  // Where a target is in the world now (nothing: unknown, or its space is not located).
  std::optional<Pose> worldFromObject(uint64_t target) const;
  // A target's bounds in its own frame (nothing: unknown, or a plane, whose bounds are its
  // y <= 0 half-space); `plane` says which.
  std::optional<Aabb> bounds(uint64_t target, bool* plane = nullptr) const;

  // Every target whose bounds, placed where it is now, overlap the box of half extents `half`
  // centred at `worldFromBox` (an oriented box); the test is on the bounds' eight corners seen in
  // the box's frame (conservative: a target a little beside the box may be reported). Planes:
  // when a corner of the box is on or below the plane (the box reaches into the solid).
  // Appends to `out` in target order (deterministic).
  void query(const Pose& worldFromBox, const glm::vec3& half, std::vector<SceneHit>& out) const;

 private:
  struct Entry {
    uint64_t space = 0;
    Pose spaceFromObject;
    std::optional<Aabb> bounds;  // target frame; nothing: a plane
    AabbTree::Proxy proxy = AabbTree::kNone;
  };
  struct Group {
    AabbTree tree;
    std::vector<uint64_t> planes;
  };
  void attach(uint64_t target, Entry& e);
  void detach(uint64_t target, Entry& e);

  std::unordered_map<uint64_t, Entry> targets_;
  std::map<uint64_t, Group> groups_;  // by space
  std::unordered_map<uint64_t, Pose> located_;
};

// The axis-aligned bounds, in the parent frame, of box `b` seen through `parentFromChild`.
Aabb transformedBounds(const Pose& parentFromChild, const Aabb& b);

}  // namespace sdfg
