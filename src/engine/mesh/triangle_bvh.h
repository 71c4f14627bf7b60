// A bounding volume hierarchy over the triangles of one mesh, for exact closest-point queries.
//
// Built once per mesh (binned surface-area heuristic, leaves of a few triangles, one flat node
// array) and refit in O(n) when the vertices move with the same topology. The closest-point
// query walks the nearer child first and prunes every subtree farther than the best distance
// found so far; it can be seeded with a known bound (a triangle near the previous query point),
// which is what makes sweeps over grid nodes cheap. Nodes of up to kSlabTriangles triangles are
// also bounded by a ball and a slab about their box's centre (the range of the triangles along
// the patch's mean normal): a box only says how far a point is from the patch along the axes, so
// from a point a few millimetres off a dense surface every leaf whose box the search ball touches
// is opened; the ball and slab say how far it is across and along the normal, so only the leaves
// near the foot of the perpendicular are (a third of the triangles on the 270k-triangle test mesh).
// Point-triangle distances are computed in double precision and report which feature of the
// triangle (face, edge, vertex) is closest, so callers can pick the matching pseudo-normal for
// the sign.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "base/work_limit.h"

namespace sdfg {

// Which part of a triangle (a, b, c) holds the closest point. Edge i joins vertex i and vertex
// (i + 1) % 3: edge0 = ab, edge1 = bc, edge2 = ca.
enum class TriangleFeature : uint8_t { face, edge0, edge1, edge2, vertex0, vertex1, vertex2 };

struct TriangleClosest {
  glm::dvec3 point{0.0};
  double distanceSquared = 0.0;
  TriangleFeature feature = TriangleFeature::face;
};

// Exact closest point of `p` on triangle (a, b, c) (Ericson, Real-Time Collision Detection,
// 5.1.5: Voronoi regions of the vertices, then the edges, then the face). The triangle must not
// be degenerate.
TriangleClosest closestPointOnTriangle(const glm::dvec3& p, const glm::dvec3& a,
                                       const glm::dvec3& b, const glm::dvec3& c);

// Result of a closest-triangle query.
struct TriangleHit {
  uint32_t triangle = std::numeric_limits<uint32_t>::max();  // max(): none found
  double distanceSquared = std::numeric_limits<double>::infinity();
  glm::dvec3 point{0.0};
  TriangleFeature feature = TriangleFeature::face;
  bool found() const { return triangle != std::numeric_limits<uint32_t>::max(); }
};

class TriangleBvh {
 public:
  // count > 0: a leaf holding triangles order()[first, first + count).
  // count == 0: an inner node whose children are nodes[first] and nodes[first + 1].
  // Children always come after their parent in the array.
  struct Node {
    glm::vec3 min{0.0f};
    uint32_t first = 0;
    glm::vec3 max{0.0f};
    uint32_t count = 0;
  };

  using Hit = TriangleHit;

  // Builds over `indices` (three per triangle) into `positions`. The arrays must describe a
  // valid mesh (validateMesh); they are not kept, only copied per triangle in leaf order.
  // `limit` is polled every few thousand triangles; once it is reached the build stops, returns
  // false and leaves an empty tree (a million triangles take about a second to build).
  bool build(std::span<const glm::vec3> positions, std::span<const uint32_t> indices,
             uint32_t maxLeafSize = 4, const WorkLimit& limit = WorkLimit::none());

  // New positions for the same triangles (same indices as build()): recomputes the node bounds
  // bottom-up, O(n). The tree shape stays, so queries stay exact but may slow down after large
  // deformations. Stopped by `limit` (false), the tree is left half refit: not to be queried
  // again (its owner is dropping it).
  bool refit(std::span<const glm::vec3> positions, std::span<const uint32_t> indices,
             const WorkLimit& limit = WorkLimit::none());

  // Closest triangle to `p` among those nearer than sqrt(seed.distanceSquared); returns `seed`
  // unchanged when none is. A default seed searches everything. A seed carrying a triangle must
  // carry that triangle's exact distance (see evaluate()); ties keep the seed.
  Hit closest(const glm::vec3& p, Hit seed = Hit{}) const;

  // Most points closestPacket() takes at once.
  static constexpr size_t kPacketSize = 8;

  // closest() for up to kPacketSize points at once: hits[i] is point i's seed on entry (same
  // contract as closest()'s seed) and its result on return; points.size() must equal
  // hits.size() and be at most kPacketSize (otherwise nothing is done). Meant for points close
  // together (a 2x2x2 block of grid nodes): one walk of the hierarchy serves them all, and each
  // triangle is first measured for all of them at once in single precision with a bound on its
  // rounding error, so the exact double-precision distance is computed only where the triangle
  // may be the closest. Every result is the same as closest() would give: the exact distance of
  // the closest triangle (which triangle may differ only between exactly equal distances).
  void closestPacket(std::span<const glm::vec3> points, std::span<Hit> hits) const;

  // The exact hit record of `p` against one triangle (original index).
  Hit evaluate(const glm::vec3& p, uint32_t triangle) const;

  std::span<const Node> nodes() const { return nodes_; }
  // Nodes with at most this many triangles get a slab bound (see the file comment).
  static constexpr uint32_t kSlabTriangles = 64;
  // Original triangle index of each leaf slot.
  std::span<const uint32_t> order() const { return order_; }
  struct Corners {
    glm::vec3 a, b, c;
  };
  // Corner positions of each leaf slot (the triangle order()[slot]).
  std::span<const Corners> corners() const { return corners_; }
  size_t triangleCount() const { return order_.size(); }

 private:
  bool refitNodes(LimitPoll& poll);
  void clear();
  // Lower bound on the squared distance from `p` to node i's triangles: its box, and its slab
  // unless the box alone reaches `best` (then the node is pruned anyway).
  float nodeDistanceSquared(const glm::vec3& p, uint32_t i, double best) const;

  std::vector<Node> nodes_;
  std::vector<uint32_t> order_;   // leaf slot -> original triangle
  std::vector<uint32_t> slotOf_;  // original triangle -> leaf slot
  std::vector<Corners> corners_;  // per leaf slot, so a leaf reads one contiguous run
  // Per leaf slot, what closestPacket()'s single-precision filter needs, rounded from double
  // precision: unit normal, longest edge, and per edge i (from corner i to corner i + 1) the
  // in-plane normal pointing into the triangle (length |edge|) and 1 / |edge|^2.
  struct FilterFrame {
    glm::vec3 normal;
    float longest;
    glm::vec3 inward0;
    float inverse0;
    glm::vec3 inward1;
    float inverse1;
    glm::vec3 inward2;
    float inverse2;
  };
  std::vector<FilterFrame> frames_;
  // Per node: its triangles lie within `radius` of `centre` (the box's centre) and in
  // lo <= dot(normal, x - centre) <= hi (all rounded outwards). Nodes with more than
  // kSlabTriangles triangles, or no dominant direction (a fold), have infinite bounds (the box
  // alone then bounds them). refit() measures a leaf's corners and bounds an inner node by its
  // children's boxes, balls and slabs, so it stays O(n).
  struct Slab {
    glm::vec3 normal{0.0f};
    float lo = 0.0f;
    glm::vec3 centre{0.0f};
    float hi = 0.0f;
    float radius = 0.0f;
  };
  std::vector<Slab> slabs_;
};

}  // namespace sdfg
