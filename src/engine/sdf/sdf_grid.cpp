#include "sdf/sdf_grid.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace sdfg {

GridBox GridBox::referenceDefault() {
  GridBox box;
  // Hand space is the wrist frame: -Z toward the fingers, -Y toward the palm side.
  box.handFromBox.position = glm::vec3(0.0f, -0.075f, -0.081f);
  box.size = glm::vec3(0.2133f);
  box.resolution = glm::uvec3(16u);
  return box;
}

std::optional<Error> GridBox::validate() const {
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(size[a]) || size[a] <= 0.0f) {
      return makeError(Status::invalid_argument, "grid box: size[" + std::to_string(a) +
                                                     "] = " + std::to_string(size[a]) +
                                                     " must be finite and positive");
    }
    if (resolution[a] < kMinGridResolution || resolution[a] > kMaxGridResolution) {
      return makeError(Status::invalid_argument, "grid box: resolution[" + std::to_string(a) +
                                                     "] = " + std::to_string(resolution[a]) +
                                                     " is outside [" +
                                                     std::to_string(kMinGridResolution) + ", " +
                                                     std::to_string(kMaxGridResolution) + "]");
    }
  }
  const glm::quat& q = handFromBox.orientation;
  const float norm = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  if (!std::isfinite(norm) || std::abs(norm - 1.0f) > 1e-3f) {
    return makeError(Status::invalid_argument, "grid box: orientation is not a unit quaternion");
  }
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(handFromBox.position[a])) {
      return makeError(Status::invalid_argument, "grid box: position is not finite");
    }
  }
  return std::nullopt;
}

float GridBox::maxSpacing() const {
  const glm::vec3 s = spacing();
  return std::max({s.x, s.y, s.z});
}

namespace {

// Splits a normalized coordinate into the lower node index and the fraction toward the next,
// clamping to the grid so points outside the box read the nearest face.
inline void locate(float u, uint32_t n, uint32_t& i0, float& t) {
  const float x = std::clamp(u, 0.0f, 1.0f) * float(n - 1);
  const float fl = std::min(std::floor(x), float(n - 2));
  i0 = uint32_t(fl);
  t = x - fl;
}

}  // namespace

float SdfGrid::sampleNormalized(const glm::vec3& uvw) const {
  const glm::uvec3& n = box_.resolution;
  uint32_t i, j, k;
  float tx, ty, tz;
  locate(uvw.x, n.x, i, tx);
  locate(uvw.y, n.y, j, ty);
  locate(uvw.z, n.z, k, tz);
  const size_t sx = 1, sy = n.x, sz = size_t(n.x) * n.y;
  const float* v = values_.data() + index(i, j, k);
  const float c00 = v[0] + (v[sx] - v[0]) * tx;
  const float c10 = v[sy] + (v[sy + sx] - v[sy]) * tx;
  const float c01 = v[sz] + (v[sz + sx] - v[sz]) * tx;
  const float c11 = v[sz + sy] + (v[sz + sy + sx] - v[sz + sy]) * tx;
  const float c0 = c00 + (c10 - c00) * ty;
  const float c1 = c01 + (c11 - c01) * ty;
  return c0 + (c1 - c0) * tz;
}

glm::vec3 SdfGrid::gradient(const glm::vec3& pHand) const {
  const glm::uvec3& n = box_.resolution;
  const glm::vec3 uvw = box_.handToNormalized(pHand);
  uint32_t i, j, k;
  float tx, ty, tz;
  locate(uvw.x, n.x, i, tx);
  locate(uvw.y, n.y, j, ty);
  locate(uvw.z, n.z, k, tz);
  auto v = [&](uint32_t di, uint32_t dj, uint32_t dk) { return at(i + di, j + dj, k + dk); };
  // Partial derivatives of the trilinear interpolant within the cell, per node spacing.
  const float dx = (1 - ty) * (1 - tz) * (v(1, 0, 0) - v(0, 0, 0)) +
                   ty * (1 - tz) * (v(1, 1, 0) - v(0, 1, 0)) +
                   (1 - ty) * tz * (v(1, 0, 1) - v(0, 0, 1)) + ty * tz * (v(1, 1, 1) - v(0, 1, 1));
  const float dy = (1 - tx) * (1 - tz) * (v(0, 1, 0) - v(0, 0, 0)) +
                   tx * (1 - tz) * (v(1, 1, 0) - v(1, 0, 0)) +
                   (1 - tx) * tz * (v(0, 1, 1) - v(0, 0, 1)) + tx * tz * (v(1, 1, 1) - v(1, 0, 1));
  const float dz = (1 - tx) * (1 - ty) * (v(0, 0, 1) - v(0, 0, 0)) +
                   tx * (1 - ty) * (v(1, 0, 1) - v(1, 0, 0)) +
                   (1 - tx) * ty * (v(0, 1, 1) - v(0, 1, 0)) + tx * ty * (v(1, 1, 1) - v(1, 1, 0));
  const glm::vec3 boxGradient = glm::vec3(dx, dy, dz) / box_.spacing();
  return box_.handFromBox.transformVector(boxGradient);
}

}  // namespace sdfg
