#include "depth/depth_view.h"

#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include <glm/geometric.hpp>

namespace sdfg {

namespace {

bool finitePose(const Pose& p) {
  const glm::quat& q = p.orientation;
  const float n = q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z;
  return std::isfinite(p.position.x) && std::isfinite(p.position.y) &&
         std::isfinite(p.position.z) && std::isfinite(n) && std::abs(n - 1.0f) < 1e-3f;
}

bool validPlane(float z) {
  return !std::isnan(z) && z > 0.0f;  // +infinity allowed
}

}  // namespace

std::optional<Error> DepthView::validate() const {
  if (!finitePose(worldFromView))
    return makeError(Status::invalid_argument, "depth view: the pose is not finite and unit");
  const float half = 0.5f * std::numbers::pi_v<float> - 1e-3f;
  const float angles[] = {fov.left, fov.right, fov.up, fov.down};
  for (float a : angles) {
    if (!std::isfinite(a) || std::abs(a) > half)
      return makeError(Status::invalid_argument,
                       "depth view: a field-of-view angle is not finite or not within 90 degrees");
  }
  if (!(fov.left < fov.right) || !(fov.down < fov.up))
    return makeError(Status::invalid_argument,
                     "depth view: the field of view is empty (left >= right or down >= up)");
  if (width == 0 || height == 0)
    return makeError(Status::invalid_argument, "depth view: the sub-image rect is empty");
  if (!(minDepth >= 0.0f && minDepth < maxDepth && maxDepth <= 1.0f))
    return makeError(Status::invalid_argument,
                     "depth view: minDepth and maxDepth must satisfy 0 <= min < max <= 1");
  if (!validPlane(nearZ) || !validPlane(farZ))
    return makeError(Status::invalid_argument, "depth view: nearZ and farZ must be positive");
  if (nearZ == farZ)
    return makeError(Status::invalid_argument,
                     "depth view: nearZ == farZ (" + std::to_string(nearZ) + ")");
  return std::nullopt;
}

float DepthView::distance(float depth) const {
  if (!(depth >= minDepth && depth <= maxDepth)) return std::numeric_limits<float>::quiet_NaN();
  const float t = (depth - minDepth) / (maxDepth - minDepth);
  const float inverse = (1.0f - t) / nearZ + t / farZ;  // 1 / inf == 0
  return inverse > 0.0f ? 1.0f / inverse : std::numeric_limits<float>::infinity();
}

float DepthView::storedAt(float z) const {
  const float a = 1.0f / nearZ, b = 1.0f / farZ;
  float t = (1.0f / z - a) / (b - a);
  if (!(t >= 0.0f)) t = 0.0f;
  if (t > 1.0f) t = 1.0f;
  return minDepth + t * (maxDepth - minDepth);
}

glm::vec3 DepthView::ray(const glm::vec2& pixel) const {
  const float tl = std::tan(fov.left), tr = std::tan(fov.right);
  const float tu = std::tan(fov.up), td = std::tan(fov.down);
  const float x = tl + pixel.x / float(width) * (tr - tl);
  const float y = tu - pixel.y / float(height) * (tu - td);
  return glm::vec3(x, y, -1.0f);
}

bool DepthView::project(const glm::vec3& p, glm::vec2& pixel, float& z) const {
  const glm::vec3 v = worldFromView.inverse().transformPoint(p);
  z = -v.z;
  if (!(z > 0.0f)) return false;
  const float tl = std::tan(fov.left), tr = std::tan(fov.right);
  const float tu = std::tan(fov.up), td = std::tan(fov.down);
  pixel.x = (v.x / z - tl) / (tr - tl) * float(width);
  pixel.y = (tu - v.y / z) / (tu - td) * float(height);
  return true;
}

}  // namespace sdfg
