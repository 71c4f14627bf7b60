#include "depth/depth_view.h"

#include <algorithm>
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

std::optional<DepthPixelRect> DepthView::cover(const glm::vec3& lo, const glm::vec3& hi) const {
  const Pose viewFromWorld = worldFromView.inverse();
  const float tl = std::tan(fov.left), tr = std::tan(fov.right);
  const float tu = std::tan(fov.up), td = std::tan(fov.down);
  float x0 = std::numeric_limits<float>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
  int behind = 0;
  for (int c = 0; c < 8; ++c) {
    const glm::vec3 corner((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z);
    const glm::vec3 v = viewFromWorld.transformPoint(corner);
    const float z = -v.z;
    if (!(z > 1e-3f)) {
      ++behind;
      continue;
    }
    const float px = (v.x / z - tl) / (tr - tl) * float(width);
    const float py = (tu - v.y / z) / (tu - td) * float(height);
    x0 = std::min(x0, px);
    x1 = std::max(x1, px);
    y0 = std::min(y0, py);
    y1 = std::max(y1, py);
  }
  if (behind == 8) return std::nullopt;
  if (behind > 0) return DepthPixelRect{0, 0, width, height};
  // A box is convex: its projection lies within its corners' projections.
  const float left = std::max(std::floor(x0), 0.0f), top = std::max(std::floor(y0), 0.0f);
  const float right = std::min(std::ceil(x1), float(width));
  const float bottom = std::min(std::ceil(y1), float(height));
  if (!(left < right && top < bottom)) return std::nullopt;
  return DepthPixelRect{uint32_t(left), uint32_t(top), uint32_t(right - left),
                        uint32_t(bottom - top)};
}

DepthView DepthView::crop(const DepthPixelRect& rect) const {
  const float tl = std::tan(fov.left), tr = std::tan(fov.right);
  const float tu = std::tan(fov.up), td = std::tan(fov.down);
  DepthView out = *this;
  out.fov.left = std::atan(tl + float(rect.x) / float(width) * (tr - tl));
  out.fov.right = std::atan(tl + float(rect.x + rect.width) / float(width) * (tr - tl));
  out.fov.up = std::atan(tu - float(rect.y) / float(height) * (tu - td));
  out.fov.down = std::atan(tu - float(rect.y + rect.height) / float(height) * (tu - td));
  out.width = rect.width;
  out.height = rect.height;
  return out;
}

}  // namespace sdfg
