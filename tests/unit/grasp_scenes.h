// Analytic grasp scenes for the solver tests: SDF grids filled from closed-form distances, the
// true contact curl of a finger found from the same distances, and box meshes for colliders.
// Nothing here uses the SDF builders, so solver tests do not depend on them.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "hand/hand_model.h"
#include "mesh/mesh.h"
#include "sdf/sdf_grid.h"

namespace sdfg::test {

// Sets every node of `grid` to distance(node position in hand space).
template <class Distance>
void fillGrid(SdfGrid& grid, Distance distance) {
  const GridBox& box = grid.box();
  for (uint32_t k = 0; k < box.resolution.z; ++k) {
    for (uint32_t j = 0; j < box.resolution.y; ++j) {
      for (uint32_t i = 0; i < box.resolution.x; ++i) {
        const glm::vec3 p = box.handFromBox.transformPoint(box.nodeLocal(i, j, k));
        grid.values()[grid.index(i, j, k)] = distance(p);
      }
    }
  }
}

// The smallest curl in [0, 1] at which distance(tip) < radius: a scan by 1e-3, then bisection
// down to 1e-6. Nothing when the tip never comes that close.
template <class Distance>
std::optional<float> firstContactCurl(const HandModel& hand, Finger finger, Distance distance,
                                      float radius) {
  auto touches = [&](float a) { return distance(hand.tipPosition(finger, a)) < radius; };
  if (touches(0.0f)) return 0.0f;
  constexpr int kSteps = 1000;
  for (int s = 1; s <= kSteps; ++s) {
    float hi = float(s) / kSteps;
    if (!touches(hi)) continue;
    float lo = float(s - 1) / kSteps;
    while (hi - lo > 1e-6f) {
      const float mid = 0.5f * (lo + hi);
      (touches(mid) ? hi : lo) = mid;
    }
    return hi;
  }
  return std::nullopt;
}

// Signed distance to an axis-aligned box: exact outside, the usual max-of-planes inside.
inline float boxDistance(const glm::vec3& p, const glm::vec3& lo, const glm::vec3& hi) {
  const glm::vec3 centre = 0.5f * (lo + hi), half = 0.5f * (hi - lo);
  const glm::vec3 q = glm::abs(p - centre) - half;
  const float outside = glm::length(glm::max(q, glm::vec3(0.0f)));
  const float inside = std::min(std::max(q.x, std::max(q.y, q.z)), 0.0f);
  return outside + inside;
}

// Appends a closed box (12 triangles, counter-clockwise seen from outside) to `mesh`.
inline void appendBox(TriangleMesh& mesh, const glm::vec3& lo, const glm::vec3& hi) {
  const uint32_t base = uint32_t(mesh.positions.size());
  for (int c = 0; c < 8; ++c) {
    mesh.positions.emplace_back((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y,
                                (c & 4) ? hi.z : lo.z);
  }
  // Corners of each face, around its boundary; the winding is fixed below from the normal.
  constexpr std::array<std::array<uint32_t, 4>, 6> kFaces = {
      {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}}};
  const glm::vec3 centre = 0.5f * (lo + hi);
  for (const auto& face : kFaces) {
    const glm::vec3 a = mesh.positions[base + face[0]], b = mesh.positions[base + face[1]],
                    c = mesh.positions[base + face[2]];
    const bool outward = glm::dot(glm::cross(b - a, c - a), a - centre) > 0.0f;
    const std::array<uint32_t, 6> tri = outward ? std::array<uint32_t, 6>{0, 1, 2, 0, 2, 3}
                                                : std::array<uint32_t, 6>{0, 2, 1, 0, 3, 2};
    for (uint32_t t : tri) mesh.indices.push_back(base + face[t]);
  }
}

}  // namespace sdfg::test
