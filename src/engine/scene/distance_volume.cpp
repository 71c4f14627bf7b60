#include "scene/distance_volume.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

namespace sdfg {

DistanceVolume::DistanceVolume(const glm::vec3& origin, float voxel, const glm::uvec3& dims,
                               float truncation)
    : origin_(origin),
      voxel_(voxel),
      dims_(dims),
      truncation_(truncation),
      values_(size_t(dims.x) * dims.y * dims.z, truncation) {}

Aabb DistanceVolume::bounds() const {
  return Aabb{origin_, origin_ + voxel_ * glm::vec3(glm::max(dims_, glm::uvec3(1u)) - 1u)};
}

float DistanceVolume::signedDistance(const glm::vec3& p) const {
  if (values_.empty()) return truncation_;
  const glm::vec3 g = (p - origin_) / voxel_;
  const glm::vec3 last = glm::vec3(dims_ - 1u);
  if (!(g.x >= 0.0f && g.y >= 0.0f && g.z >= 0.0f && g.x <= last.x && g.y <= last.y &&
        g.z <= last.z))
    return truncation_;
  const glm::uvec3 lo = glm::min(glm::uvec3(g), dims_ - 2u);
  const glm::vec3 t = g - glm::vec3(lo);
  float c[2][2][2];
  for (uint32_t dz = 0; dz < 2; ++dz)
    for (uint32_t dy = 0; dy < 2; ++dy)
      for (uint32_t dx = 0; dx < 2; ++dx)
        c[dz][dy][dx] = values_[index(lo.x + dx, lo.y + dy, lo.z + dz)];
  auto lerp = [](float a, float b, float s) { return a + (b - a) * s; };
  const float y0 = lerp(lerp(c[0][0][0], c[0][0][1], t.x), lerp(c[0][1][0], c[0][1][1], t.x), t.y);
  const float y1 = lerp(lerp(c[1][0][0], c[1][0][1], t.x), lerp(c[1][1][0], c[1][1][1], t.x), t.y);
  return lerp(y0, y1, t.z);
}

float DistanceVolume::closest(const glm::vec3& p, glm::vec3& closest) const {
  const float d = signedDistance(p);
  closest = p;
  if (!(std::abs(d) < truncation_)) return d;
  // Central differences half a voxel apart: the gradient of the trilinear field, which is the
  // surface normal near a surface.
  const float h = 0.5f * voxel_;
  const glm::vec3 grad(
      signedDistance(p + glm::vec3(h, 0, 0)) - signedDistance(p - glm::vec3(h, 0, 0)),
      signedDistance(p + glm::vec3(0, h, 0)) - signedDistance(p - glm::vec3(0, h, 0)),
      signedDistance(p + glm::vec3(0, 0, h)) - signedDistance(p - glm::vec3(0, 0, h)));
  const float l = glm::length(grad);
  if (l > 1e-12f) closest = p - d * grad / l;
  return d;
}

}  // namespace sdfg
