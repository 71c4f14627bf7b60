// Simple solids a target can be instead of a triangle mesh: a box (a table top, a shelf, a wall
// of some thickness) or a plane (a floor, a wall seen from one side). Scene geometry is often no
// more than that, and an app should not have to triangulate a floor to keep fingers out of it.
//
// A shape lives in its target's frame: a box is centred on the origin with its edges along the
// axes; a plane is the frame's y = 0 plane, solid below it (its outward normal is +Y). Distances
// are exact and signed (negative inside), as MeshDistance's are for meshes.
#pragma once

#include <optional>

#include <glm/vec3.hpp>

#include "base/status.h"
#include "mesh/mesh.h"

namespace sdfg {

enum class ShapeKind : uint8_t { box, plane };

struct AnalyticShape {
  ShapeKind kind = ShapeKind::box;
  glm::vec3 halfExtents{0.0f};  // box: half the edge lengths, metres; plane: unused (zero)

  // Box: every half extent finite and in (0, kMaxHalfExtent]; plane: half extents all zero.
  // The first problem, named, or nothing.
  std::optional<Error> validate() const;
  // Whether the shape has finite bounds (a plane has none).
  bool bounded() const { return kind == ShapeKind::box; }
  // The shape's bounds in its frame (boxes only; a plane gives an empty box at the origin).
  Aabb bounds() const;

  // Signed distance of `p` (target frame), negative inside.
  float signedDistance(const glm::vec3& p) const;
  // The closest point of the surface to `p` and its signed distance, in one call.
  float closest(const glm::vec3& p, glm::vec3& surfacePoint) const;

  static constexpr float kMaxHalfExtent = 1000.0f;  // metres: a room, with margin
};

}  // namespace sdfg
