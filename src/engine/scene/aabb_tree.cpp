#include "scene/aabb_tree.h"

#include <algorithm>
#include <cassert>

#include <glm/common.hpp>

namespace sdfg {
namespace {

Aabb merged(const Aabb& a, const Aabb& b) {
  return Aabb{glm::min(a.min, b.min), glm::max(a.max, b.max)};
}

// Half the surface area: the cost a box adds to every query that reaches it.
float halfArea(const Aabb& b) {
  const glm::vec3 e = b.max - b.min;
  return e.x * e.y + e.y * e.z + e.z * e.x;
}

bool contains(const Aabb& outer, const Aabb& inner) {
  return outer.min.x <= inner.min.x && outer.min.y <= inner.min.y && outer.min.z <= inner.min.z &&
         inner.max.x <= outer.max.x && inner.max.y <= outer.max.y && inner.max.z <= outer.max.z;
}

}  // namespace

int32_t AabbTree::allocate() {
  if (free_ != kNone) {
    const int32_t n = free_;
    free_ = nodes_[size_t(n)].nextFree;
    nodes_[size_t(n)] = Node{};
    return n;
  }
  nodes_.push_back(Node{});
  return int32_t(nodes_.size() - 1);
}

void AabbTree::release(int32_t node) {
  nodes_[size_t(node)] = Node{};
  nodes_[size_t(node)].nextFree = free_;
  free_ = node;
}

AabbTree::Proxy AabbTree::insert(const Aabb& box, uint64_t item) {
  const int32_t leaf = allocate();
  Node& n = nodes_[size_t(leaf)];
  n.box = Aabb{box.min - glm::vec3(margin_), box.max + glm::vec3(margin_)};
  n.item = item;
  insertLeaf(leaf);
  ++leaves_;
  return leaf;
}

void AabbTree::remove(Proxy proxy) {
  removeLeaf(proxy);
  release(proxy);
  --leaves_;
}

bool AabbTree::update(Proxy proxy, const Aabb& box) {
  if (contains(nodes_[size_t(proxy)].box, box)) return false;
  removeLeaf(proxy);
  nodes_[size_t(proxy)].box = Aabb{box.min - glm::vec3(margin_), box.max + glm::vec3(margin_)};
  insertLeaf(proxy);
  return true;
}

void AabbTree::insertLeaf(int32_t leaf) {
  if (root_ == kNone) {
    root_ = leaf;
    nodes_[size_t(leaf)].parent = kNone;
    return;
  }
  // Walk down to the sibling that makes the tree's surface grow least: at each node, compare
  // making the new leaf its sibling here with descending into either child (the child's own
  // growth, plus the growth every ancestor on the way takes anyway).
  const Aabb leafBox = nodes_[size_t(leaf)].box;
  int32_t index = root_;
  while (!nodes_[size_t(index)].leaf()) {
    const Node& n = nodes_[size_t(index)];
    const float area = halfArea(n.box);
    const float combined = halfArea(merged(n.box, leafBox));
    const float here = 2.0f * combined;
    const float inherited = 2.0f * (combined - area);
    auto descendCost = [&](int32_t child) {
      const Aabb& c = nodes_[size_t(child)].box;
      const float grown = halfArea(merged(c, leafBox));
      return nodes_[size_t(child)].leaf() ? grown + inherited : grown - halfArea(c) + inherited;
    };
    const float costLeft = descendCost(n.left);
    const float costRight = descendCost(n.right);
    if (here < costLeft && here < costRight) break;
    index = costLeft < costRight ? n.left : n.right;
  }
  const int32_t sibling = index;
  const int32_t oldParent = nodes_[size_t(sibling)].parent;
  const int32_t parent = allocate();  // may reallocate nodes_: no references held across it
  nodes_[size_t(parent)].parent = oldParent;
  nodes_[size_t(parent)].box = merged(leafBox, nodes_[size_t(sibling)].box);
  nodes_[size_t(parent)].left = sibling;
  nodes_[size_t(parent)].right = leaf;
  nodes_[size_t(sibling)].parent = parent;
  nodes_[size_t(leaf)].parent = parent;
  if (oldParent == kNone) {
    root_ = parent;
  } else if (nodes_[size_t(oldParent)].left == sibling) {
    nodes_[size_t(oldParent)].left = parent;
  } else {
    nodes_[size_t(oldParent)].right = parent;
  }
  refitUp(nodes_[size_t(parent)].parent);
}

void AabbTree::removeLeaf(int32_t leaf) {
  if (leaf == root_) {
    root_ = kNone;
    return;
  }
  const int32_t parent = nodes_[size_t(leaf)].parent;
  const int32_t grand = nodes_[size_t(parent)].parent;
  const int32_t sibling = nodes_[size_t(parent)].left == leaf ? nodes_[size_t(parent)].right
                                                              : nodes_[size_t(parent)].left;
  if (grand == kNone) {
    root_ = sibling;
    nodes_[size_t(sibling)].parent = kNone;
  } else {
    if (nodes_[size_t(grand)].left == parent)
      nodes_[size_t(grand)].left = sibling;
    else
      nodes_[size_t(grand)].right = sibling;
    nodes_[size_t(sibling)].parent = grand;
    refitUp(grand);
  }
  release(parent);
  nodes_[size_t(leaf)].parent = kNone;
}

void AabbTree::refitUp(int32_t node) {
  for (int32_t i = node; i != kNone; i = nodes_[size_t(i)].parent) {
    Node& n = nodes_[size_t(i)];
    n.box = merged(nodes_[size_t(n.left)].box, nodes_[size_t(n.right)].box);
  }
}

int AabbTree::heightOf(int32_t node) const {
  if (node == kNone) return 0;
  const Node& n = nodes_[size_t(node)];
  if (n.leaf()) return 1;
  return 1 + std::max(heightOf(n.left), heightOf(n.right));
}

int AabbTree::height() const {
  return heightOf(root_);
}

}  // namespace sdfg
