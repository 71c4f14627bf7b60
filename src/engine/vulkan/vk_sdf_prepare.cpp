// The CPU side of a Vulkan SDF build (vk_sdf_builder_detail.h): a mesh's pseudo-normals and
// Morton keys, the winding-number hierarchy's plan, and the jump-flooding steps.
#include <cmath>

#include <glm/gtc/quaternion.hpp>

#include "mesh/mesh_weld.h"
#include "vulkan/vk_sdf_builder_detail.h"

namespace sdfg::vk_sdf_detail {

FloodTestHooks floodTestHooks;

// Spreads the low 10 bits of v to every third bit (Morton order of triangle centroids, so that
// consecutive triangles, the hierarchy's clusters, are close in space).
uint32_t spreadBits(uint32_t v) {
  v &= 0x3ffu;
  v = (v | (v << 16)) & 0x030000ffu;
  v = (v | (v << 8)) & 0x0300f00fu;
  v = (v | (v << 4)) & 0x030c30c3u;
  v = (v | (v << 2)) & 0x09249249u;
  return v;
}

// Pseudo-normals of every triangle's edges and corners when the mesh is closed (every edge has
// two triangles), consistently oriented (they traverse it in opposite directions) and its closed
// parts do not overlap, in the mesh's triangle order; nothing otherwise (those meshes are signed
// by the winding number, as MeshDistance signs them). The caller gives the mesh welded
// (mesh/mesh_weld.h) where its vertices may be split: split vertices read as open edges here.
std::optional<std::vector<L::TrianglePseudoNormals>> pseudoNormals(const TriangleMesh& mesh) {
  const size_t triangles = mesh.triangleCount();
  struct HalfEdge {
    uint64_t key;
    uint32_t slot;  // 3 * triangle + edge
  };
  std::vector<HalfEdge> half(3 * triangles);
  for (size_t t = 0; t < triangles; ++t) {
    for (uint32_t e = 0; e < 3; ++e) {
      const uint32_t u = mesh.indices[3 * t + e], v = mesh.indices[3 * t + (e + 1) % 3];
      half[3 * t + e] = {(uint64_t(std::min(u, v)) << 32) | std::max(u, v), uint32_t(3 * t + e)};
    }
  }
  std::sort(half.begin(), half.end(),
            [](const HalfEdge& x, const HalfEdge& y) { return x.key < y.key; });
  std::vector<glm::dvec3> face(triangles), vertex(mesh.vertexCount(), glm::dvec3(0.0));
  for (size_t t = 0; t < triangles; ++t) {
    const glm::dvec3 p[3] = {glm::dvec3(mesh.positions[mesh.indices[3 * t]]),
                             glm::dvec3(mesh.positions[mesh.indices[3 * t + 1]]),
                             glm::dvec3(mesh.positions[mesh.indices[3 * t + 2]])};
    face[t] = glm::normalize(glm::cross(p[1] - p[0], p[2] - p[0]));
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3 e1 = glm::normalize(p[(k + 1) % 3] - p[k]);
      const glm::dvec3 e2 = glm::normalize(p[(k + 2) % 3] - p[k]);
      vertex[mesh.indices[3 * t + k]] +=
          std::acos(std::clamp(glm::dot(e1, e2), -1.0, 1.0)) * face[t];
    }
  }
  std::vector<L::TrianglePseudoNormals> out(triangles);
  for (size_t i = 0; i < half.size(); i += 2) {
    if (i + 1 >= half.size() || half[i].key != half[i + 1].key ||
        (i + 2 < half.size() && half[i + 2].key == half[i].key)) {
      return std::nullopt;  // a boundary or non-manifold edge
    }
    const uint32_t s0 = half[i].slot, s1 = half[i + 1].slot;
    if (mesh.indices[s0] == mesh.indices[s1]) return std::nullopt;  // neighbours disagree
    const glm::vec4 n(glm::vec3(face[s0 / 3] + face[s1 / 3]), 0.0f);
    out[s0 / 3].edge[s0 % 3] = n;
    out[s1 / 3].edge[s1 % 3] = n;
  }
  if (partsOverlap(mesh.positions, mesh.indices)) return std::nullopt;
  for (size_t t = 0; t < triangles; ++t) {
    for (int k = 0; k < 3; ++k) {
      out[t].corner[k] = glm::vec4(glm::vec3(vertex[mesh.indices[3 * t + k]]), 0.0f);
    }
  }
  return out;
}

glm::mat4 poseMatrix(const Pose& pose) {
  glm::mat4 m = glm::mat4_cast(pose.orientation);
  m[3] = glm::vec4(pose.position, 1.0f);
  return m;
}

bool finitePose(const Pose& p) {
  const glm::quat& q = p.orientation;
  return std::isfinite(q.w) && std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) &&
         std::isfinite(p.position.x) && std::isfinite(p.position.y) &&
         std::isfinite(p.position.z) && std::abs(glm::length(q) - 1.0f) < 1e-3f;
}

Hierarchy planHierarchy(uint32_t triangles) {
  Hierarchy h;
  uint32_t n = ceilDiv(triangles, L::kFanOut);
  while (true) {
    h.offset[h.levels] = h.total;
    h.count[h.levels] = n;
    h.total += n;
    ++h.levels;
    if (n <= L::kFanOut || h.levels == L::kMaxLevels) break;
    n = ceilDiv(n, L::kFanOut);
  }
  return h;
}

// The jump steps for a grid whose longest axis has `n` nodes: the largest power of two below n,
// halving to 1, then 2 and 1 again (JFA+2: cleans up most of the flood's misses).
std::vector<uint32_t> jumpSteps(uint32_t n) {
  std::vector<uint32_t> steps;
  uint32_t s = 1;
  while (s * 2 < n) s *= 2;
  for (; s >= 1; s /= 2) steps.push_back(s);
  if (n > 2) {
    steps.push_back(2);
    steps.push_back(1);
  }
  return steps;
}

}  // namespace sdfg::vk_sdf_detail
