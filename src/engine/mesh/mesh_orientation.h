// Which way a triangle mesh is wound, and the fix that makes it outward.
//
// The SDF's sign (negative inside) and every solver take a triangle's counter-clockwise side,
// seen from outside, as its outside. Meshes from games are wound either way, or both: an
// inside-out mesh would be "grasped" with the hand open (the whole world outside the object reads
// as inside). orientOutward() finds each connected part's orientation and flips the triangles of
// the parts that face inwards, so the core always gets outward triangles:
// - neighbouring triangles are first made consistent across every edge that exactly two of them
//   share (a breadth-first walk per connected part), which repairs mixed winding;
// - a closed part (every edge shared by two triangles) then faces outward when its signed volume
//   is positive;
// - an open part (a bowl, a sheet) has no volume: it faces outward when the generalized winding
//   number (Jacobson et al. 2013) of the whole mesh, averaged at sample points just in front of
//   and just behind its triangles, is positive (about +1/2 when outward, -1/2 when inside-out).
// A part whose vote is zero (a flat sheet, whose two sides are alike) is left as given.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "base/work_limit.h"

namespace sdfg {

struct MeshOrientation {
  uint32_t components = 0;  // connected parts (triangles linked through shared edges)
  uint32_t closedComponents = 0;
  uint32_t inconsistent = 0;        // triangles flipped to agree with their part's neighbours
  uint32_t invertedComponents = 0;  // parts that faced inwards and were flipped whole
  uint32_t flipped = 0;             // triangles flipped in all
  // The WorkLimit was reached before the end: `indices` were left as given, the counts are
  // incomplete.
  bool stopped = false;
  // What the app gave, in words: "counter-clockwise (outward)", "clockwise (inside-out)" or
  // "mixed".
  const char* describe() const;
};

// Rewrites `indices` (three per triangle, into `positions`) so every part faces outward, and says
// what it found. Cost: O(triangles) for the walk and the volumes, plus O(samples x triangles)
// for each open part (at most 16 samples per part). `indices` must be a valid triangle list
// (size a multiple of 3, every index < positions.size(); as after validateMesh()). `limit` is
// polled every few thousand triangles (an open part's vote alone reads every triangle 32 times).
MeshOrientation orientOutward(std::span<const glm::vec3> positions, std::vector<uint32_t>& indices,
                              const WorkLimit& limit = WorkLimit::none());

// The generalized winding number of the triangles at `p` (sum of their solid angles / 4 pi):
// ~1 inside a closed outward mesh, ~0 outside, ~-1 inside an inside-out one.
double windingNumberAt(std::span<const glm::vec3> positions, std::span<const uint32_t> indices,
                       const glm::dvec3& p);

}  // namespace sdfg
