// A dynamic tree of axis-aligned boxes: which of many items' bounds overlap a query box, in
// O(log n + hits) instead of a loop over all of them. The broad phase of the grasp scene: a room
// of a thousand registered targets, of which the few near a hand take part in its grasp.
//
// Leaves hold "fat" boxes (the item's bounds grown by a margin), so an item that moves a little
// changes nothing in the tree; one that leaves its fat box is removed and inserted again. A new
// leaf goes where it enlarges the tree's total box surface least (the surface-area heuristic of
// physics engines' broad phases), which keeps the tree shallow for items inserted in any order.
// Not thread-safe: its owner serializes calls.
#pragma once

#include <cstdint>
#include <vector>

#include "mesh/mesh.h"

namespace sdfg {

class AabbTree {
 public:
  using Proxy = int32_t;
  static constexpr Proxy kNone = -1;

  // `margin`: metres the fat boxes extend beyond the items' bounds on every side.
  explicit AabbTree(float margin = 0.02f) : margin_(margin) {}

  // Adds an item with bounds `box` (min <= max); returns its proxy, valid until remove().
  Proxy insert(const Aabb& box, uint64_t item);
  void remove(Proxy proxy);
  // New bounds of an item. Returns true when its leaf moved (the bounds left its fat box).
  bool update(Proxy proxy, const Aabb& box);

  // Calls visit(item) for every item whose fat box overlaps `box` (a superset of the items whose
  // bounds do; callers test the bounds they care about). Allocates nothing once warm.
  template <class Visit>
  void query(const Aabb& box, Visit&& visit) const;

  size_t size() const { return leaves_; }
  // The tree's height (0 empty, 1 a single leaf), for tests.
  int height() const;
  const Aabb& fatBox(Proxy proxy) const { return nodes_[size_t(proxy)].box; }

 private:
  struct Node {
    Aabb box;
    uint64_t item = 0;
    int32_t parent = kNone;
    int32_t left = kNone;  // kNone on leaves
    int32_t right = kNone;
    int32_t nextFree = kNone;
    bool leaf() const { return left == kNone; }
  };

  int32_t allocate();
  void release(int32_t node);
  void insertLeaf(int32_t leaf);
  void removeLeaf(int32_t leaf);
  void refitUp(int32_t node);
  int heightOf(int32_t node) const;

  float margin_;
  std::vector<Node> nodes_;
  int32_t root_ = kNone;
  int32_t free_ = kNone;
  size_t leaves_ = 0;
  mutable std::vector<int32_t> stack_;  // query's traversal stack, kept between calls
};

inline bool overlaps(const Aabb& a, const Aabb& b) {
  return a.min.x <= b.max.x && b.min.x <= a.max.x && a.min.y <= b.max.y && b.min.y <= a.max.y &&
         a.min.z <= b.max.z && b.min.z <= a.max.z;
}

template <class Visit>
void AabbTree::query(const Aabb& box, Visit&& visit) const {
  if (root_ == kNone) return;
  stack_.clear();
  stack_.push_back(root_);
  while (!stack_.empty()) {
    const Node& n = nodes_[size_t(stack_.back())];
    stack_.pop_back();
    if (!overlaps(n.box, box)) continue;
    if (n.leaf()) {
      visit(n.item);
    } else {
      stack_.push_back(n.left);
      stack_.push_back(n.right);
    }
  }
}

}  // namespace sdfg
