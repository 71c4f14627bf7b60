// Welding by position: the topology of a mesh as its surface has it, not as its indices do.
//
// Game meshes rarely give one vertex per position: exporters split vertices wherever a UV seam,
// a hard edge or a flat-shaded face runs, so two triangles that meet on the surface often share
// no index, and a triangle soup shares none at all. Everything that reads topology (which edges
// are shared, which parts are closed, the pseudo-normals of edges and corners, the orientation
// of connected parts) would take such a mesh for a heap of open slivers. weldByPosition() gives
// the topology back without touching the app's vertex array: it rewrites a copy of the indices so
// that vertices at the same position (within a tolerance of about a micrometre on a hand-sized
// object, to absorb float noise) share one index, the first such vertex's, and drops triangles
// that repeat another's corners (duplicated or double-sided faces) or collapse to two corners.
// The positions keep their count and order, so new vertices from the app (skinned meshes:
// xrUpdateGraspTargetVerticesSDFG) still apply one for one; vertices that were welded away are
// simply no longer referenced. Split vertices are expected to move together, as they do under
// skinning (one position, one set of weights).
//
// Not a library's: meshoptimizer's shadow index buffer (meshopt_generateShadowIndexBuffer) does
// the bit-exact part, but Debian ships it only as a shared library (every app's machine would
// need it) and not for the MinGW build of the Windows layer, and the tolerance is needed anyway.
// The tolerance is deliberately tiny: cracks between parts (a millimetre between two pieces of a
// model) are not closed by welding, which would move real vertices; they are signed by the
// generalized winding number instead, which needs no topology (mesh_distance.h).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "base/work_limit.h"

namespace sdfg {

// Positions closer than this fraction of the mesh's bounding-box diagonal are one vertex:
// 1.8 um on the benchmark's 18 cm objects, 20 um on a 2 m character; far below any edge a real
// mesh has, far above the rounding of a float transform or a six-decimal file format.
inline constexpr float kWeldRelativeTolerance = 1e-5f;

struct WeldReport {
  uint32_t vertices = 0;            // distinct indices the triangles used, as given
  uint32_t weldedVertices = 0;      // distinct positions they were welded into
  uint32_t nearWelded = 0;          // of the welded-away vertices, those not bit-equal to theirs
  uint32_t duplicateTriangles = 0;  // dropped: the same three corners as an earlier triangle
  uint32_t collapsedTriangles = 0;  // dropped: two corners welded into one
  // The WorkLimit was reached before the end: `indices` were left as given.
  bool stopped = false;

  bool changed() const {
    return weldedVertices != vertices || duplicateTriangles > 0 || collapsedTriangles > 0;
  }
  // What was found, in words a user acts on: "12000 split vertices welded into 4100, 24
  // duplicate triangles dropped", or "no split vertices".
  std::string describe() const;
};

// Rewrites `indices` (three per triangle into `positions`, valid as after validateMesh()) as
// described above; the result is again a valid triangle list over the same positions, with at
// least one triangle and none of zero area (a weld that would leave one, or no triangle at all,
// changes nothing, and the report then says so: weldedVertices == vertices, nothing dropped).
// O(vertices + triangles)
// expected time, with `limit` polled every few thousand elements.
WeldReport weldByPosition(std::span<const glm::vec3> positions, std::vector<uint32_t>& indices,
                          const WorkLimit& limit = WorkLimit::none());

// Whether two connected parts of the mesh (triangles linked through shared edges, after welding)
// have overlapping bounding boxes. Closed parts that intersect (a character built from closed
// pieces) make the pseudo-normal sign wrong in their overlap: a point inside one part but nearest
// to the other part's surface reads as outside. Callers that would sign by pseudo-normals sign by
// the winding number instead when this is true. O(triangles log triangles).
bool partsOverlap(std::span<const glm::vec3> positions, std::span<const uint32_t> indices);

}  // namespace sdfg
