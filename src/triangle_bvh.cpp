#include "triangle_bvh.h"

#include <algorithm>
#include <array>
#include <numeric>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

namespace sdfg {

TriangleClosest closestPointOnTriangle(const glm::dvec3& p, const glm::dvec3& a,
                                       const glm::dvec3& b, const glm::dvec3& c) {
  // Ericson's region tests. The feature is decided by the same comparisons that pick the
  // point, so a point whose nearest location is exactly on an edge or vertex reports that
  // edge or vertex (the sign then comes from the right pseudo-normal).
  const auto result = [&p](const glm::dvec3& q, TriangleFeature f) {
    const glm::dvec3 d = p - q;
    return TriangleClosest{q, glm::dot(d, d), f};
  };
  const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) return result(a, TriangleFeature::vertex0);

  const glm::dvec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) return result(b, TriangleFeature::vertex1);

  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double v = d1 / (d1 - d3);
    return result(a + v * ab, TriangleFeature::edge0);
  }

  const glm::dvec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) return result(c, TriangleFeature::vertex2);

  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double w = d2 / (d2 - d6);
    return result(a + w * ac, TriangleFeature::edge2);
  }

  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return result(b + w * (c - b), TriangleFeature::edge1);
  }

  const double denom = 1.0 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  return result(a + ab * v + ac * w, TriangleFeature::face);
}

namespace {

constexpr int kBins = 16;
// Past this depth nodes split by count, which bounds the depth (and the query stack) by
// kMedianDepth + log2(triangles) whatever the triangle distribution.
constexpr uint32_t kMedianDepth = 96;
constexpr size_t kStackSize = 128;

struct Box {
  glm::vec3 min{std::numeric_limits<float>::max()};
  glm::vec3 max{-std::numeric_limits<float>::max()};
  void grow(const glm::vec3& p) {
    min = glm::min(min, p);
    max = glm::max(max, p);
  }
  void grow(const Box& b) {
    min = glm::min(min, b.min);
    max = glm::max(max, b.max);
  }
  float halfArea() const {
    const glm::vec3 e = glm::max(max - min, glm::vec3(0.0f));
    return e.x * e.y + e.y * e.z + e.z * e.x;
  }
};

inline float boxDistanceSquared(const glm::vec3& p, const glm::vec3& mn, const glm::vec3& mx) {
  const glm::vec3 d = glm::max(glm::max(mn - p, p - mx), glm::vec3(0.0f));
  return glm::dot(d, d);
}

}  // namespace

void TriangleBvh::build(std::span<const glm::vec3> positions, std::span<const uint32_t> indices,
                        uint32_t maxLeafSize) {
  const size_t n = indices.size() / 3;
  maxLeafSize = std::max(maxLeafSize, 1u);
  nodes_.clear();
  order_.resize(n);
  std::iota(order_.begin(), order_.end(), 0u);
  if (n == 0) {
    corners_.clear();
    slotOf_.clear();
    return;
  }

  std::vector<Box> triBox(n);
  std::vector<glm::vec3> centroid(n);
  for (size_t t = 0; t < n; ++t) {
    for (int k = 0; k < 3; ++k) triBox[t].grow(positions[indices[3 * t + k]]);
    centroid[t] = triBox[t].min * 0.5f + triBox[t].max * 0.5f;
  }

  struct Task {
    uint32_t node;
    uint32_t depth;
  };
  nodes_.reserve(2 * n);
  nodes_.push_back(Node{{}, 0u, {}, uint32_t(n)});
  std::vector<Task> tasks{{0u, 0u}};
  while (!tasks.empty()) {
    const Task task = tasks.back();
    tasks.pop_back();
    const uint32_t first = nodes_[task.node].first;
    const uint32_t count = nodes_[task.node].count;
    if (count <= maxLeafSize) continue;

    Box centroidBox;
    for (uint32_t s = first; s < first + count; ++s) centroidBox.grow(centroid[order_[s]]);

    // Binned SAH over all three axes: the split with the least
    // area(left) * count(left) + area(right) * count(right).
    int bestAxis = -1, bestSplit = 0;
    float bestCost = std::numeric_limits<float>::max();
    if (task.depth < kMedianDepth) {
      for (int axis = 0; axis < 3; ++axis) {
        const float lo = centroidBox.min[axis], extent = centroidBox.max[axis] - lo;
        if (!(extent > 0.0f)) continue;
        const float scale = float(kBins) / extent;
        std::array<Box, kBins> bins{};
        std::array<uint32_t, kBins> counts{};
        for (uint32_t s = first; s < first + count; ++s) {
          const uint32_t t = order_[s];
          const int bin = std::min(kBins - 1, int((centroid[t][axis] - lo) * scale));
          bins[bin].grow(triBox[t]);
          ++counts[bin];
        }
        std::array<float, kBins> rightCost{};
        Box acc;
        uint32_t accCount = 0;
        for (int b = kBins - 1; b > 0; --b) {
          acc.grow(bins[b]);
          accCount += counts[b];
          rightCost[b] = accCount == 0 ? 0.0f : acc.halfArea() * float(accCount);
        }
        acc = Box{};
        accCount = 0;
        for (int b = 1; b < kBins; ++b) {
          acc.grow(bins[b - 1]);
          accCount += counts[b - 1];
          if (accCount == 0 || accCount == count) continue;
          const float cost = acc.halfArea() * float(accCount) + rightCost[b];
          if (cost < bestCost) {
            bestCost = cost;
            bestAxis = axis;
            bestSplit = b;
          }
        }
      }
    }

    uint32_t mid;
    if (bestAxis >= 0) {
      const float lo = centroidBox.min[bestAxis];
      const float scale = float(kBins) / (centroidBox.max[bestAxis] - lo);
      const auto it =
          std::partition(order_.begin() + first, order_.begin() + first + count, [&](uint32_t t) {
            return std::min(kBins - 1, int((centroid[t][bestAxis] - lo) * scale)) < bestSplit;
          });
      mid = uint32_t(it - order_.begin());
    } else {
      // All centroids coincide (or the tree is too deep): any split by count is as good.
      mid = first + count / 2;
    }
    const uint32_t left = uint32_t(nodes_.size());
    nodes_.push_back(Node{{}, first, {}, mid - first});
    nodes_.push_back(Node{{}, mid, {}, first + count - mid});
    nodes_[task.node].first = left;
    nodes_[task.node].count = 0;
    tasks.push_back({left, task.depth + 1});
    tasks.push_back({left + 1, task.depth + 1});
  }

  slotOf_.resize(n);
  for (uint32_t s = 0; s < n; ++s) slotOf_[order_[s]] = s;
  corners_.resize(n);
  refit(positions, indices);
}

void TriangleBvh::refit(std::span<const glm::vec3> positions, std::span<const uint32_t> indices) {
  for (size_t s = 0; s < order_.size(); ++s) {
    const uint32_t t = order_[s];
    corners_[s] = {positions[indices[3 * t]], positions[indices[3 * t + 1]],
                   positions[indices[3 * t + 2]]};
  }
  refitNodes();
}

void TriangleBvh::refitNodes() {
  // Children follow their parent, so one backward pass sees children before parents.
  for (size_t i = nodes_.size(); i-- > 0;) {
    Node& node = nodes_[i];
    Box box;
    if (node.count > 0) {
      for (uint32_t s = node.first; s < node.first + node.count; ++s) {
        box.grow(corners_[s].a);
        box.grow(corners_[s].b);
        box.grow(corners_[s].c);
      }
    } else {
      box.grow(nodes_[node.first].min);
      box.grow(nodes_[node.first].max);
      box.grow(nodes_[node.first + 1].min);
      box.grow(nodes_[node.first + 1].max);
    }
    node.min = box.min;
    node.max = box.max;
  }
}

TriangleBvh::Hit TriangleBvh::evaluate(const glm::vec3& p, uint32_t triangle) const {
  const Corners& k = corners_[slotOf_[triangle]];
  const TriangleClosest c =
      closestPointOnTriangle(glm::dvec3(p), glm::dvec3(k.a), glm::dvec3(k.b), glm::dvec3(k.c));
  return Hit{triangle, c.distanceSquared, c.point, c.feature};
}

TriangleBvh::Hit TriangleBvh::closest(const glm::vec3& p, Hit seed) const {
  Hit best = seed;
  if (nodes_.empty()) return best;
  // Float box distances can exceed the exact value by a few ulps; shrinking them keeps a
  // triangle at (nearly) the best distance from being pruned.
  constexpr float kShrink = 1.0f - 1e-6f;
  const auto prunable = [&best](float boxD2) {
    return double(boxD2 * kShrink) >= best.distanceSquared;
  };

  struct Entry {
    uint32_t node;
    float distanceSquared;
  };
  std::array<Entry, kStackSize> stack;
  size_t top = 0;
  const glm::dvec3 pd(p);

  uint32_t current = 0;
  if (prunable(boxDistanceSquared(p, nodes_[0].min, nodes_[0].max))) return best;
  for (;;) {
    const Node& node = nodes_[current];
    if (node.count > 0) {
      for (uint32_t s = node.first; s < node.first + node.count; ++s) {
        const Corners& k = corners_[s];
        const TriangleClosest c =
            closestPointOnTriangle(pd, glm::dvec3(k.a), glm::dvec3(k.b), glm::dvec3(k.c));
        if (c.distanceSquared < best.distanceSquared) {
          best = Hit{order_[s], c.distanceSquared, c.point, c.feature};
        }
      }
    } else {
      uint32_t nearChild = node.first, farChild = node.first + 1;
      float nearD = boxDistanceSquared(p, nodes_[nearChild].min, nodes_[nearChild].max);
      float farD = boxDistanceSquared(p, nodes_[farChild].min, nodes_[farChild].max);
      if (farD < nearD) {
        std::swap(nearChild, farChild);
        std::swap(nearD, farD);
      }
      if (!prunable(nearD)) {
        if (!prunable(farD)) stack[top++] = Entry{farChild, farD};
        current = nearChild;
        continue;
      }
    }
    // Next candidate from the stack that the best distance so far has not ruled out.
    bool next = false;
    while (top > 0) {
      const Entry e = stack[--top];
      if (!prunable(e.distanceSquared)) {
        current = e.node;
        next = true;
        break;
      }
    }
    if (!next) return best;
  }
}

}  // namespace sdfg
