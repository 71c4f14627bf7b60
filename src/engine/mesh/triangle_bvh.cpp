#include "mesh/triangle_bvh.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <numeric>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

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

void TriangleBvh::clear() {
  nodes_.clear();
  order_.clear();
  corners_.clear();
  frames_.clear();
  slotOf_.clear();
  slabs_.clear();
}

bool TriangleBvh::build(std::span<const glm::vec3> positions, std::span<const uint32_t> indices,
                        uint32_t maxLeafSize, const WorkLimit& limit) {
  const size_t n = indices.size() / 3;
  maxLeafSize = std::max(maxLeafSize, 1u);
  clear();
  if (n == 0) return true;
  order_.resize(n);
  std::iota(order_.begin(), order_.end(), 0u);
  // Polled per triangle in every loop below (the root alone bins and partitions all of them),
  // so the time between two looks at the limit stays bounded whatever the mesh.
  LimitPoll poll(limit);
  const auto stop = [this] {
    clear();
    return false;
  };

  std::vector<Box> triBox(n);
  std::vector<glm::vec3> centroid(n);
  for (size_t t = 0; t < n; ++t) {
    if (poll.reached()) return stop();
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
    for (uint32_t s = first; s < first + count; ++s) {
      if (poll.reached()) return stop();
      centroidBox.grow(centroid[order_[s]]);
    }

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
          if (poll.reached()) return stop();
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
      const auto left = [&](uint32_t t) {
        return std::min(kBins - 1, int((centroid[t][bestAxis] - lo) * scale)) < bestSplit;
      };
      // std::partition written out so that it can poll: the same swaps from both ends as
      // libstdc++'s, so the tree (and which of two equally close triangles a query reports) is
      // the one it always was.
      uint32_t from = first, to = first + count;
      for (;;) {
        while (from != to && left(order_[from])) {
          if (poll.reached()) return stop();
          ++from;
        }
        if (from == to) break;
        --to;
        while (from != to && !left(order_[to])) {
          if (poll.reached()) return stop();
          --to;
        }
        if (from == to) break;
        std::swap(order_[from], order_[to]);
        ++from;
      }
      mid = from;
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
  frames_.resize(n);
  if (!refit(positions, indices, limit)) return stop();
  return true;
}

bool TriangleBvh::refit(std::span<const glm::vec3> positions, std::span<const uint32_t> indices,
                        const WorkLimit& limit) {
  LimitPoll poll(limit);
  for (size_t s = 0; s < order_.size(); ++s) {
    if (poll.reached()) return false;
    const uint32_t t = order_[s];
    corners_[s] = {positions[indices[3 * t]], positions[indices[3 * t + 1]],
                   positions[indices[3 * t + 2]]};
    const glm::dvec3 a(corners_[s].a), b(corners_[s].b), c(corners_[s].c);
    const glm::dvec3 ab = b - a, bc = c - b, ca = a - c;
    const glm::dvec3 n = glm::normalize(glm::cross(ab, -ca));
    const double longest2 = std::max({glm::dot(ab, ab), glm::dot(bc, bc), glm::dot(ca, ca)});
    frames_[s] = {glm::vec3(n),
                  float(std::sqrt(longest2)),
                  glm::vec3(glm::cross(n, ab)),
                  float(1.0 / glm::dot(ab, ab)),
                  glm::vec3(glm::cross(n, bc)),
                  float(1.0 / glm::dot(bc, bc)),
                  glm::vec3(glm::cross(n, ca)),
                  float(1.0 / glm::dot(ca, ca))};
  }
  return refitNodes(poll);
}

bool TriangleBvh::refitNodes(LimitPoll& poll) {
  std::vector<uint32_t> triangles(nodes_.size());  // in each node's subtree
  // Children follow their parent, so one backward pass sees children before parents.
  for (size_t i = nodes_.size(); i-- > 0;) {
    if (poll.reached()) return false;
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
    triangles[i] = node.count > 0 ? node.count : triangles[node.first] + triangles[node.first + 1];
  }

  // Slabs, bottom-up in one more backward pass. A leaf measures its corners; an inner node
  // bounds each child's region (its box, and its ball and slab) along its own normal, so a refit
  // (updatePositions() of a deforming target) stays O(n).
  slabs_.assign(nodes_.size(), Slab{});
  std::vector<glm::dvec3> areaSum(nodes_.size());  // sum of the triangles' cross products
  std::vector<double> areaTotal(nodes_.size());    // sum of their lengths
  constexpr float kInf = std::numeric_limits<float>::infinity();
  for (size_t i = nodes_.size(); i-- > 0;) {
    if (poll.reached()) return false;
    const Node& node = nodes_[i];
    Slab& slab = slabs_[i];
    slab.lo = -kInf;
    slab.hi = kInf;
    slab.radius = kInf;
    glm::dvec3 sum(0.0);
    double area = 0.0;
    if (node.count > 0) {
      for (uint32_t s = node.first; s < node.first + node.count; ++s) {
        const glm::dvec3 a(corners_[s].a), b(corners_[s].b), c(corners_[s].c);
        const glm::dvec3 cr = glm::cross(b - a, c - a);
        sum += cr;
        area += glm::length(cr);
      }
    } else {
      sum = areaSum[node.first] + areaSum[node.first + 1];
      area = areaTotal[node.first] + areaTotal[node.first + 1];
    }
    areaSum[i] = sum;
    areaTotal[i] = area;
    if (triangles[i] > kSlabTriangles) continue;
    // The area-weighted mean normal: on a smooth patch the direction the patch is thinnest in.
    const double len = glm::length(sum);
    if (!(len > 0.5 * area) || !(len > 0.0)) continue;  // a fold or a crease: no useful plane
    // The bounds are measured from the single-precision normal and centre the query uses, so
    // only the query's own arithmetic can err.
    const glm::vec3 normalF(sum / len);
    const glm::vec3 centreF(0.5f * (node.min + node.max));
    const glm::dvec3 normal(normalF), centre(centreF);
    double lo = std::numeric_limits<double>::max(), hi = -lo, radius = 0.0;
    if (node.count > 0) {
      double radius2 = 0.0;
      for (uint32_t s = node.first; s < node.first + node.count; ++s) {
        for (const glm::vec3& v : {corners_[s].a, corners_[s].b, corners_[s].c}) {
          const glm::dvec3 d = glm::dvec3(v) - centre;
          const double h = glm::dot(normal, d);
          lo = std::min(lo, h);
          hi = std::max(hi, h);
          radius2 = std::max(radius2, glm::dot(d, d));
        }
      }
      radius = std::sqrt(radius2);
    } else {
      for (uint32_t k = node.first; k < node.first + 2; ++k) {
        const Node& child = nodes_[k];
        const Slab& cs = slabs_[k];
        // The child's box: centre +- half extents.
        const glm::dvec3 boxCentre = 0.5 * (glm::dvec3(child.min) + glm::dvec3(child.max));
        const glm::dvec3 half = 0.5 * (glm::dvec3(child.max) - glm::dvec3(child.min));
        const double boxAt = glm::dot(normal, boxCentre - centre);
        const double boxReach = glm::dot(glm::abs(normal), half);
        double cLo = boxAt - boxReach, cHi = boxAt + boxReach;
        double cRadius = glm::length(boxCentre - centre) + glm::length(half);
        if (cs.radius < kInf) {
          // Along the parent's normal n = alpha n_k + beta t (t across n_k): the child's slab
          // gives alpha [lo_k, hi_k], its ball beta [-R_k, R_k].
          const glm::dvec3 ck(cs.centre);
          const double alpha = glm::dot(normal, glm::dvec3(cs.normal));
          const double beta = std::sqrt(std::max(0.0, 1.0 - alpha * alpha));
          const double at = glm::dot(normal, ck - centre);
          const double a0 = alpha * double(cs.lo), a1 = alpha * double(cs.hi);
          cLo = std::max(cLo, at + std::min(a0, a1) - beta * double(cs.radius));
          cHi = std::min(cHi, at + std::max(a0, a1) + beta * double(cs.radius));
          cRadius = std::min(cRadius, glm::length(ck - centre) + double(cs.radius));
        }
        lo = std::min(lo, cLo);
        hi = std::max(hi, cHi);
        radius = std::max(radius, cRadius);
      }
      // Everything in the box is within half its diagonal of its centre.
      radius = std::min(radius, 0.5 * glm::length(glm::dvec3(node.max) - glm::dvec3(node.min)));
    }
    slab.normal = normalF;
    slab.centre = centreF;
    const double pad = 1e-6 * radius;  // rounds the float bounds outwards
    slab.lo = float(lo - pad);
    slab.hi = float(hi + pad);
    slab.radius = float(radius + pad);
  }
  return true;
}

// Inlined into closest(): it runs twice per inner node visited, over a hundred times a query.
[[gnu::always_inline]] inline float TriangleBvh::nodeDistanceSquared(const glm::vec3& p, uint32_t i,
                                                                     double best) const {
  const Node& node = nodes_[i];
  const float box = boxDistanceSquared(p, node.min, node.max);
  const Slab& slab = slabs_[i];
  // Already pruned by its box, or a node without a slab.
  if (double(box) >= best || !(slab.radius < std::numeric_limits<float>::infinity())) return box;
  // The triangles lie in the ball (centre, radius) and in the slab lo <= axial <= hi about the
  // centre, so any of them is at least the axial gap away along the normal and at least the
  // radial gap (distance from the normal's line through the centre, minus the radius) across
  // it: the squared distance is at least the sum of the two squares.
  const glm::vec3 d = p - slab.centre;
  const float axial = glm::dot(slab.normal, d);
  const glm::vec3 across = d - axial * slab.normal;
  const float radial2 = glm::dot(across, across);
  // Single-precision rounding of both grows with |d| (a few 1e-7 |d|); an allowance of 1e-5 |d|
  // is well above it and costs the bound only that fraction.
  const float slack = 1e-5f * (std::abs(axial) + std::abs(d.x) + std::abs(d.y) + std::abs(d.z));
  const float axialGap = std::max(std::max(slab.lo - axial, axial - slab.hi) - slack, 0.0f);
  float radialGap = 0.0f;
  if (radial2 > slab.radius * slab.radius) {
    radialGap = std::max(std::sqrt(radial2) - slab.radius - slack, 0.0f);
  }
  return std::max(box, axialGap * axialGap + radialGap * radialGap);
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
  if (prunable(nodeDistanceSquared(p, 0, best.distanceSquared))) return best;
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
      float nearD = nodeDistanceSquared(p, nearChild, best.distanceSquared);
      float farD = nodeDistanceSquared(p, farChild, best.distanceSquared);
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

namespace sdfg {

namespace {

// Four single-precision lanes (GCC/Clang vector extension: SSE on x86-64, NEON on ARM64, plain
// scalar code elsewhere). A packet of kPacketSize = 8 points is two of them.
typedef float F4 __attribute__((vector_size(16)));
typedef int32_t I4 __attribute__((vector_size(16)));
constexpr int kHalves = 2;

inline F4 splat(float v) {
  return F4{v, v, v, v};
}
inline F4 vmin(F4 a, F4 b) {
  return a < b ? a : b;
}
inline F4 vmax(F4 a, F4 b) {
  return a > b ? a : b;
}
// Bits 0..3 set where the lane of `c` is true (all ones).
inline uint32_t laneBits(I4 c) {
#if defined(__SSE2__)
  return uint32_t(_mm_movemask_ps(_mm_castsi128_ps(__m128i(c))));
#else
  return uint32_t(c[0] & 1) | uint32_t(c[1] & 2) | uint32_t(c[2] & 4) | uint32_t(c[3] & 8);
#endif
}
inline F4 vsqrt(F4 v) {
#if defined(__SSE2__)
  return F4(_mm_sqrt_ps(__m128(v)));
#else
  for (int q = 0; q < 4; ++q) v[q] = std::sqrt(v[q]);
  return v;
#endif
}

// Safety factor on single-precision rounding errors in the packet filter: 2^-16, far above the
// few dozen roundings of 2^-24 each that any of its quantities goes through.
constexpr float kFilterSlack = 1.0f / 65536.0f;

// The smallest float >= v (v >= 0), so float comparisons against it never prune what a double
// comparison against v would keep.
inline float floatAtLeast(double v) {
  const float f = float(v);
  return double(f) >= v ? f : std::nextafter(f, std::numeric_limits<float>::infinity());
}

}  // namespace

void TriangleBvh::closestPacket(std::span<const glm::vec3> points, std::span<Hit> hits) const {
  const size_t count = points.size();
  if (count == 0 || count != hits.size() || count > kPacketSize || nodes_.empty()) return;
  constexpr float kShrink = 1.0f - 1e-6f;  // as in closest()

  // A point nearer the surface than the group is wide searches a ball that the others' balls
  // barely overlap, so sharing the walk saves little and the eight-wide filter works for one
  // lane: such groups take one closest() per point (measured a little faster on the test meshes).
  {
    glm::vec3 lo = points[0], hi = points[0];
    double nearest2 = hits[0].distanceSquared;
    for (size_t l = 1; l < count; ++l) {
      lo = glm::min(lo, points[l]);
      hi = glm::max(hi, points[l]);
      nearest2 = std::min(nearest2, hits[l].distanceSquared);
    }
    const glm::dvec3 extent(hi - lo);
    if (nearest2 < glm::dot(extent, extent)) {
      for (size_t l = 0; l < count; ++l) hits[l] = closest(points[l], hits[l]);
      return;
    }
  }

  // Lanes past `count` repeat point 0 and are never active.
  alignas(16) float px[kPacketSize], py[kPacketSize], pz[kPacketSize];
  glm::vec3 centre(0.0f);
  for (size_t l = 0; l < kPacketSize; ++l) {
    const glm::vec3& p = points[l < count ? l : 0];
    px[l] = p.x;
    py[l] = p.y;
    pz[l] = p.z;
    if (l < count) centre += p;
  }
  centre /= float(count);
  F4 X[kHalves], Y[kHalves], Z[kHalves];
  for (int h = 0; h < kHalves; ++h) {
    std::memcpy(&X[h], px + 4 * h, sizeof(F4));
    std::memcpy(&Y[h], py + 4 * h, sizeof(F4));
    std::memcpy(&Z[h], pz + 4 * h, sizeof(F4));
  }

  // Per lane, float upper bounds of the best squared distance (for box pruning) and of the best
  // distance (for the triangle filter); infinity while nothing is known.
  alignas(16) float bound2[kPacketSize], bound[kPacketSize];
  const auto setBounds = [&](size_t l) {
    bound2[l] = floatAtLeast(hits[l].distanceSquared);
    bound[l] = floatAtLeast(std::sqrt(hits[l].distanceSquared));
  };
  for (size_t l = 0; l < kPacketSize; ++l) {
    if (l < count) {
      setBounds(l);
    } else {
      bound2[l] = bound[l] = 0.0f;  // nothing is nearer than 0: never active
    }
  }
  const auto load = [](const float* a, int h) {
    F4 v;
    std::memcpy(&v, a + 4 * h, sizeof(F4));
    return v;
  };

  // Lanes for which node `n`'s box is not ruled out by the lane's best so far (the same test as
  // closest(), done in float against bounds rounded up, so it keeps at least what it keeps).
  const auto liveLanes = [&](uint32_t index) {
    const Node& n = nodes_[index];
    const F4 mnx = splat(n.min.x), mny = splat(n.min.y), mnz = splat(n.min.z);
    const F4 mxx = splat(n.max.x), mxy = splat(n.max.y), mxz = splat(n.max.z);
    uint32_t bits = 0;
    for (int h = 0; h < kHalves; ++h) {
      const F4 dx = vmax(vmax(mnx - X[h], X[h] - mxx), splat(0.0f));
      const F4 dy = vmax(vmax(mny - Y[h], Y[h] - mxy), splat(0.0f));
      const F4 dz = vmax(vmax(mnz - Z[h], Z[h] - mxz), splat(0.0f));
      const F4 d2 = dx * dx + dy * dy + dz * dz;
      bits |= laneBits(d2 * splat(kShrink) < load(bound2, h)) << (4 * h);
    }
    // The slab bound of nodeDistanceSquared(), lane by lane, for the lanes the box kept.
    const Slab& slab = slabs_[index];
    if (bits == 0 || !(slab.radius < std::numeric_limits<float>::infinity())) return bits;
    uint32_t slabBits = 0;
    for (int h = 0; h < kHalves; ++h) {
      if (((bits >> (4 * h)) & 15u) == 0) continue;
      const F4 dx = X[h] - splat(slab.centre.x), dy = Y[h] - splat(slab.centre.y),
               dz = Z[h] - splat(slab.centre.z);
      const F4 axial = dx * slab.normal.x + dy * slab.normal.y + dz * slab.normal.z;
      const F4 ax = dx - axial * slab.normal.x, ay = dy - axial * slab.normal.y,
               az = dz - axial * slab.normal.z;
      const F4 radial = vsqrt(ax * ax + ay * ay + az * az);
      const F4 absAxial = vmax(axial, -axial);
      const F4 slack = splat(1e-5f) * (absAxial + vmax(dx, -dx) + vmax(dy, -dy) + vmax(dz, -dz));
      const F4 axialGap =
          vmax(vmax(splat(slab.lo) - axial, axial - splat(slab.hi)) - slack, splat(0.0f));
      const F4 radialGap = vmax(radial - splat(slab.radius) - slack, splat(0.0f));
      const F4 d2 = axialGap * axialGap + radialGap * radialGap;
      slabBits |= laneBits(d2 * splat(kShrink) < load(bound2, h)) << (4 * h);
    }
    return bits & slabBits;
  };

  const glm::dvec3 pd[kPacketSize] = {glm::dvec3(points[0]),
                                      glm::dvec3(points[std::min<size_t>(1, count - 1)]),
                                      glm::dvec3(points[std::min<size_t>(2, count - 1)]),
                                      glm::dvec3(points[std::min<size_t>(3, count - 1)]),
                                      glm::dvec3(points[std::min<size_t>(4, count - 1)]),
                                      glm::dvec3(points[std::min<size_t>(5, count - 1)]),
                                      glm::dvec3(points[std::min<size_t>(6, count - 1)]),
                                      glm::dvec3(points[std::min<size_t>(7, count - 1)])};

  // Every triangle of a leaf is measured for all live lanes in single precision; only lanes for
  // which it may beat the best so far get the exact double-precision distance.
  //
  // Why the filter never drops a triangle closer than a lane's best D (so the result is exact):
  // the float distance d_f is the plane distance when the point may project inside the triangle
  // and the least of the three edge-segment distances otherwise. Normals come from double
  // precision, so every quantity is a few dozen float roundings (2^-24 each, relative to
  // |p - a| + M, with M the longest edge) away from its exact value. "May project inside" is
  // decided with a tolerance larger than the rounding of the three edge tests, so a point that
  // projects inside is never taken for outside; the other mistake (outside taken for inside)
  // gives the plane distance, which never exceeds the true distance. Hence d_f <= d + err with
  // err < kFilterSlack * (|p - a| + M). A triangle closer than D has |p - a| < D + M, so
  // d_f < D + kFilterSlack * (D + 2M) =: T, and the filter keeps every triangle with d_f < T
  // (NaN included).
  const auto leaf = [&](const Node& node, uint32_t live) {
    for (uint32_t s = node.first; s < node.first + node.count; ++s) {
      const Corners& k = corners_[s];
      const FilterFrame& f = frames_[s];
      const glm::vec3 e0 = k.b - k.a, e1 = k.c - k.b, e2 = k.a - k.c;
      const float longest = f.longest;
      uint32_t candidates = 0;
      for (int h = 0; h < kHalves; ++h) {
        if (((live >> (4 * h)) & 15u) == 0) continue;
        const F4 ax = X[h] - splat(k.a.x), ay = Y[h] - splat(k.a.y), az = Z[h] - splat(k.a.z);
        const F4 bx = X[h] - splat(k.b.x), by = Y[h] - splat(k.b.y), bz = Z[h] - splat(k.b.z);
        const F4 cx = X[h] - splat(k.c.x), cy = Y[h] - splat(k.c.y), cz = Z[h] - splat(k.c.z);
        const F4 ap2 = ax * ax + ay * ay + az * az;
        // Edge test i is dot(p - v_i, inward_i), |p - v_i| |e_i| <= (|p - a| + M) M in size.
        const F4 apLength = vsqrt(ap2);
        const F4 tol = splat(-kFilterSlack * longest) * (apLength + splat(longest));
        const F4 s0 = ax * f.inward0.x + ay * f.inward0.y + az * f.inward0.z;
        const F4 s1 = bx * f.inward1.x + by * f.inward1.y + bz * f.inward1.z;
        const F4 s2 = cx * f.inward2.x + cy * f.inward2.y + cz * f.inward2.z;
        const I4 inside = (s0 >= tol) & (s1 >= tol) & (s2 >= tol);
        const F4 plane = ax * f.normal.x + ay * f.normal.y + az * f.normal.z;
        const auto segment = [](F4 vx, F4 vy, F4 vz, const glm::vec3& e, float inv) {
          const F4 t = vmin(vmax((vx * e.x + vy * e.y + vz * e.z) * inv, splat(0.0f)), splat(1.0f));
          const F4 rx = vx - t * e.x, ry = vy - t * e.y, rz = vz - t * e.z;
          return rx * rx + ry * ry + rz * rz;
        };
        const F4 edge2 =
            vmin(vmin(segment(ax, ay, az, e0, f.inverse0), segment(bx, by, bz, e1, f.inverse1)),
                 segment(cx, cy, cz, e2, f.inverse2));
        const F4 d2 = inside ? plane * plane : edge2;
        const F4 D = load(bound, h);
        const F4 T = D + splat(kFilterSlack) * (D + splat(2.0f * longest));
        candidates |= laneBits(~(d2 >= T * T)) << (4 * h);
      }
      candidates &= live;
      while (candidates != 0) {
        const int l = std::countr_zero(candidates);
        candidates &= candidates - 1;
        const TriangleClosest r =
            closestPointOnTriangle(pd[l], glm::dvec3(k.a), glm::dvec3(k.b), glm::dvec3(k.c));
        if (r.distanceSquared < hits[l].distanceSquared) {
          hits[l] = Hit{order_[s], r.distanceSquared, r.point, r.feature};
          setBounds(size_t(l));
        }
      }
    }
  };

  struct Entry {
    uint32_t node;
    uint32_t lanes;
  };
  std::array<Entry, kStackSize> stack;
  size_t top = 0;
  uint32_t current = 0;
  uint32_t live = liveLanes(0);
  if (live == 0) return;
  for (;;) {
    const Node& node = nodes_[current];
    if (node.count > 0) {
      leaf(node, live);
    } else {
      uint32_t nearChild = node.first, farChild = node.first + 1;
      uint32_t nearLive = live & liveLanes(nearChild);
      uint32_t farLive = live & liveLanes(farChild);
      // Nearer child first, as seen from the packet's centre.
      if (boxDistanceSquared(centre, nodes_[farChild].min, nodes_[farChild].max) <
          boxDistanceSquared(centre, nodes_[nearChild].min, nodes_[nearChild].max)) {
        std::swap(nearChild, farChild);
        std::swap(nearLive, farLive);
      }
      if (nearLive != 0) {
        if (farLive != 0) stack[top++] = Entry{farChild, farLive};
        current = nearChild;
        live = nearLive;
        continue;
      }
      if (farLive != 0) {
        current = farChild;
        live = farLive;
        continue;
      }
    }
    // Next subtree from the stack that some lane still needs (bests only shrink).
    bool next = false;
    while (top > 0) {
      const Entry e = stack[--top];
      const uint32_t lanes = e.lanes & liveLanes(e.node);
      if (lanes != 0) {
        current = e.node;
        live = lanes;
        next = true;
        break;
      }
    }
    if (!next) return;
  }
}

}  // namespace sdfg
