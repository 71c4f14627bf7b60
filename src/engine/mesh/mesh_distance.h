// Exact point-to-mesh distance with a robust inside/outside sign, for one mesh.
//
// Built once per mesh (a bounding volume hierarchy over its triangles plus per-feature
// pseudo-normals) and refit, not rebuilt, when the vertices move. The distance is exact (the
// closest point on the closest triangle). The sign comes from the angle-weighted pseudo-normal of
// the closest feature (face, edge or vertex; Baerentzen & Aanaes 2005) on closed meshes, and from
// the generalized winding number (Jacobson et al. 2013) where the mesh is open or its closed parts
// overlap. The topology is the surface's, not the indices': split vertices are welded and repeated
// triangles dropped first (mesh_weld.h), so a triangle soup is signed like the indexed mesh.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <span>

#include <glm/vec3.hpp>

#include "base/status.h"
#include "base/work_limit.h"
#include "mesh/mesh.h"

namespace sdfg {

struct ClosestPoint {
  float distance = std::numeric_limits<float>::infinity();  // unsigned, metres
  glm::vec3 point{0.0f};                                    // on the mesh
  uint32_t triangle = 0;
};

class MeshDistance {
 public:
  // Takes its own copy of the mesh. Fails on an invalid mesh (see validateMesh), and with
  // timed_out once `limit` is reached: every step (the check, the hierarchy, the sort of the
  // edges, the normals, the winding-number clusters) looks at it every few thousand elements, so
  // a set-up of a million triangles (about a second) stops within milliseconds of being asked.
  static Result<std::unique_ptr<MeshDistance>> create(const TriangleMesh& mesh,
                                                      const WorkLimit& limit = WorkLimit::none());
  ~MeshDistance();
  MeshDistance(const MeshDistance&) = delete;
  MeshDistance& operator=(const MeshDistance&) = delete;

  // New vertex positions, same count and topology (animated or skinned meshes). Refits the
  // hierarchy's bounds and recomputes pseudo-normals in O(n); no rebuild. A refused update
  // (invalid_argument) changes nothing. Once `limit` is reached it returns timed_out: during the
  // check nothing has changed yet, later the object is left half updated and must not be used
  // again (the worker passes a limit only to stop work whose target is being dropped).
  Status updatePositions(std::span<const glm::vec3> positions,
                         const WorkLimit& limit = WorkLimit::none());

  // The mesh as welded (mesh_weld.h): the given positions, indices that share the vertices the
  // given ones split, without repeated triangles. Triangle ids of the queries index this mesh.
  const TriangleMesh& mesh() const;
  // True when every edge of the welded mesh has exactly two triangles (no boundary, no
  // non-manifold edge).
  bool isClosed() const;

  ClosestPoint closest(const glm::vec3& p) const;
  // Skips subtrees farther than `maxDistance`; returns infinity when nothing is that close.
  ClosestPoint closestWithin(const glm::vec3& p, float maxDistance) const;
  float signedDistance(const glm::vec3& p) const;
  // closestWithin() with a local sign, for checks near the surface that must stay cheap: the
  // sign is the side of the closest feature's angle-weighted pseudo-normal, on every mesh. On
  // closed meshes that is signedDistance()'s sign; on open ones (where signedDistance() pays for
  // a winding number) it is the side of the nearest sheet, which differs only near holes and
  // where open parts overlap. Returns +infinity when no triangle is within `maxDistance` (the
  // sign is then unknown); writes the closest point to *closestPoint when one was found and the
  // pointer is not null.
  float localSignedDistanceWithin(const glm::vec3& p, float maxDistance,
                                  glm::vec3* closestPoint = nullptr) const;
  // localSignedDistanceWithin() seeded with a triangle likely to be near `p` (the previous
  // closest triangle of a point that moved a little): when it is within `maxDistance` its exact
  // distance bounds the search from the start, so fewer subtrees are walked.
  // Same result as localSignedDistanceWithin() whatever the hint (a hint out of range or
  // farther than `maxDistance` is ignored). Writes the closest triangle to *closestTriangle when
  // one was found and the pointer is not null.
  float localSignedDistanceNear(const glm::vec3& p, float maxDistance, uint32_t hintTriangle,
                                glm::vec3* closestPoint = nullptr,
                                uint32_t* closestTriangle = nullptr) const;
  // signedDistance(p) seeded with a triangle likely to be near `p` (in a sweep over grid nodes,
  // the previous node's closest triangle): its exact distance bounds the search, so far less of
  // the hierarchy is visited. Same distance as signedDistance(p) whatever the hint (the sign too,
  // except where two features are exactly equally close); a hint out of
  // range is ignored. Writes the closest triangle to *closestTriangle when it is not null.
  float signedDistanceNear(const glm::vec3& p, uint32_t hintTriangle,
                           uint32_t* closestTriangle = nullptr) const;
  // Points signedDistances() takes in one group.
  static constexpr size_t kGroupSize = 8;

  // signedDistanceNear() for many points: points[i] gets distances[i], with triangles[i] its hint
  // on entry and its closest triangle on return. Consecutive groups of kGroupSize points share one
  // walk of the hierarchy, so each group should lie close together (a 2x2x2 block of grid nodes);
  // any order gives the same values, only slower. The three spans must have the same size, else
  // invalid_argument and nothing is written.
  Status signedDistances(std::span<const glm::vec3> points, std::span<uint32_t> triangles,
                         std::span<float> distances) const;
  // Generalized winding number: ~1 inside, ~0 outside, fractional near holes.
  float windingNumber(const glm::vec3& p) const;
  // Whether the distance queries take their sign from the winding number (open, non-manifold or
  // inconsistently oriented meshes) rather than from pseudo-normals.
  bool signsByWinding() const;
  // -1 where the winding number exceeds 1/2, else +1: on a mesh signsByWinding(), exactly the sign
  // the distance queries give at `p` (the same double-precision comparison), without the search.
  float windingSign(const glm::vec3& p) const;

 private:
  struct Impl;
  explicit MeshDistance(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace sdfg
