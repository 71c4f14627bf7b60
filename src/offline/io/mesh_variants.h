// The same surface with its vertices split as game exporters split them, for tests and the
// benchmark to check that a grasp does not depend on how a mesh shares its vertices.
//
// Game meshes duplicate a vertex wherever an attribute other than the position changes: at UV
// seams and at hard edges (flat shading). Each variant keeps every triangle, in order, with its
// winding, and every corner at a bit-identical position; only which corners share an index
// changes. New vertices come in the order of their first use (triangle by triangle, corner by
// corner), so a variant is a pure function of the mesh. Vertices no triangle uses are dropped.
// The functions below take a valid mesh (validateMesh()); makeMeshVariant() checks it.
#pragma once

#include <span>
#include <string_view>

#include "base/status.h"
#include "mesh/mesh.h"

namespace sdfg {

// Angle between two faces' normals above which an edge is hard (split): Blender's auto-smooth
// default, and the usual import smoothing angle of game engines.
inline constexpr float kFlatSplitAngleDegrees = 30.0f;

// A triangle soup: every triangle gets three vertices of its own (3 x triangles vertices).
TriangleMesh soupVariant(const TriangleMesh& mesh);

// Flat-shaded / hard-edge split: triangles are grouped into smoothing regions through the edges
// shared by exactly two triangles whose normals differ by at most `splitAngleDegrees`; every
// other edge is hard. A vertex gets one copy per region among the triangles using it. A cube
// becomes 24 vertices (each face a region), a finely tessellated smooth mesh stays as it is.
TriangleMesh flatVariant(const TriangleMesh& mesh,
                         float splitAngleDegrees = kFlatSplitAngleDegrees);

// UV seams of box-projection (cube) mapping: each triangle goes to one of 6 charts, by the
// dominant axis of its normal and that component's sign (ties to the lower axis: x, then y, z);
// a vertex gets one copy per chart among the triangles using it.
TriangleMesh seamsVariant(const TriangleMesh& mesh);

// The variants' names, in the order tests and the benchmark run them: soup, flat, seams.
std::span<const std::string_view> meshVariantNames();

// The variant called `name` (flat at kFlatSplitAngleDegrees). Errors (invalid_argument): an
// unknown name.
Result<TriangleMesh> makeMeshVariant(std::string_view name, const TriangleMesh& mesh);

}  // namespace sdfg
