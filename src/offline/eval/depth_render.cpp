#include "depth_render.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>

namespace sdfg {

DepthView depthLookAt(const glm::vec3& eye, const glm::vec3& target, float nearZ, float farZ,
                      uint32_t size) {
  const glm::vec3 f = glm::normalize(target - eye);
  const glm::vec3 r = glm::normalize(glm::cross(f, glm::vec3(0, 1, 0)));
  const glm::vec3 u = glm::cross(r, f);
  DepthView v;
  v.worldFromView = Pose{glm::normalize(glm::quat_cast(glm::mat3(r, u, -f))), eye};
  const float half = 0.25f * 3.14159265f;
  v.fov = DepthFov{-half, half, half, -half};
  v.width = v.height = size;
  v.nearZ = nearZ;
  v.farZ = farZ;
  return v;
}

std::vector<float> renderDepthDistances(const DepthView& view,
                                        std::span<const DepthPlaced> objects) {
  std::vector<float> z(size_t(view.width) * view.height, std::numeric_limits<float>::infinity());
  const Pose viewFromWorld = view.worldFromView.inverse();
  const float tl = std::tan(view.fov.left), tr = std::tan(view.fov.right);
  const float tu = std::tan(view.fov.up), td = std::tan(view.fov.down);
  const float sx = float(view.width) / (tr - tl), sy = float(view.height) / (tu - td);
  const auto edge = [](const glm::vec2& a, const glm::vec2& b, const glm::vec2& p) {
    return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
  };
  for (const DepthPlaced& o : objects) {
    const TriangleMesh& m = *o.mesh;
    for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
      glm::vec2 s[3];
      float zs[3];
      bool ok = true;
      for (int c = 0; c < 3; ++c) {
        const glm::vec3 v = viewFromWorld.transformPoint(
            o.worldFromObject.transformPoint(m.positions[m.indices[t + size_t(c)]]));
        zs[c] = -v.z;
        ok = ok && zs[c] > 0.01f;  // no clipping: a triangle reaching behind the eye is dropped
        s[c] = glm::vec2((v.x / zs[c] - tl) * sx, (tu - v.y / zs[c]) * sy);
      }
      if (!ok) continue;
      const float area = edge(s[0], s[1], s[2]);
      if (std::abs(area) < 1e-12f) continue;
      const glm::vec2 lo = glm::min(s[0], glm::min(s[1], s[2]));
      const glm::vec2 hi = glm::max(s[0], glm::max(s[1], s[2]));
      const int x0 = std::max(0, int(std::floor(lo.x))), y0 = std::max(0, int(std::floor(lo.y)));
      const int x1 = std::min(int(view.width) - 1, int(std::ceil(hi.x)));
      const int y1 = std::min(int(view.height) - 1, int(std::ceil(hi.y)));
      for (int y = y0; y <= y1; ++y) {
        for (int x = x0; x <= x1; ++x) {
          const glm::vec2 p(float(x) + 0.5f, float(y) + 0.5f);
          const float w0 = edge(s[1], s[2], p) / area, w1 = edge(s[2], s[0], p) / area;
          const float w2 = 1.0f - w0 - w1;
          if (w0 < 0.0f || w1 < 0.0f || w2 < 0.0f) continue;
          // 1 / z is affine in screen space.
          const float d = 1.0f / (w0 / zs[0] + w1 / zs[1] + w2 / zs[2]);
          float& out = z[size_t(y) * view.width + size_t(x)];
          out = std::min(out, d);
        }
      }
    }
  }
  return z;
}

std::vector<float> storedDepthValues(const DepthView& view, const std::vector<float>& z,
                                     DepthStored format) {
  std::vector<float> d(z.size());
  for (size_t i = 0; i < z.size(); ++i) {
    float v = view.storedAt(z[i]);
    if (format == DepthStored::d16) v = std::round(v * 65535.0f) / 65535.0f;
    if (format == DepthStored::d24) v = float(std::round(double(v) * 16777215.0) / 16777215.0);
    d[i] = v;
  }
  return d;
}

}  // namespace sdfg
