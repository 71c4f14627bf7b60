#include "scene/analytic_shape.h"

#include <algorithm>
#include <cmath>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

namespace sdfg {

std::optional<Error> AnalyticShape::validate() const {
  switch (kind) {
    case ShapeKind::box:
      for (int a = 0; a < 3; ++a) {
        if (!std::isfinite(halfExtents[a]) || !(halfExtents[a] > 0.0f) ||
            halfExtents[a] > kMaxHalfExtent)
          return makeError(Status::invalid_argument,
                           "box shape: every half extent must be finite and in (0, 1000] m");
      }
      return std::nullopt;
    case ShapeKind::plane:
      if (halfExtents != glm::vec3(0.0f))
        return makeError(Status::invalid_argument, "plane shape: half extents must be zero");
      return std::nullopt;
  }
  return makeError(Status::invalid_argument, "shape: unknown kind");
}

Aabb AnalyticShape::bounds() const {
  if (kind != ShapeKind::box) return Aabb{};
  return Aabb{-halfExtents, halfExtents};
}

float AnalyticShape::signedDistance(const glm::vec3& p) const {
  glm::vec3 unused;
  return closest(p, unused);
}

float AnalyticShape::closest(const glm::vec3& p, glm::vec3& surfacePoint) const {
  if (kind == ShapeKind::plane) {
    surfacePoint = glm::vec3(p.x, 0.0f, p.z);
    return p.y;
  }
  const glm::vec3 q = glm::abs(p) - halfExtents;
  const bool inside = q.x <= 0.0f && q.y <= 0.0f && q.z <= 0.0f;
  if (!inside) {
    // Outside: clamping each coordinate into the box gives the closest point.
    surfacePoint = glm::clamp(p, -halfExtents, halfExtents);
    return glm::length(glm::max(q, glm::vec3(0.0f)));
  }
  // Inside: the nearest face is the one with the largest (least negative) q.
  int axis = 0;
  if (q.y > q[axis]) axis = 1;
  if (q.z > q[axis]) axis = 2;
  surfacePoint = p;
  surfacePoint[axis] = p[axis] < 0.0f ? -halfExtents[axis] : halfExtents[axis];
  return q[axis];
}

}  // namespace sdfg
