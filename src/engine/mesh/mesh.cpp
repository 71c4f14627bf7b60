#include "mesh/mesh.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/geometric.hpp>

namespace sdfg {
namespace {

Error stopped() {
  return makeError(Status::timed_out, "mesh: the check was stopped");
}

}  // namespace

std::optional<Error> findDegenerateTriangle(std::span<const glm::vec3> positions,
                                            std::span<const uint32_t> indices,
                                            const WorkLimit& limit) {
  LimitPoll poll(limit);
  for (size_t t = 0; t < indices.size() / 3; ++t) {
    if (poll.reached()) return stopped();
    const uint32_t a = indices[3 * t], b = indices[3 * t + 1], c = indices[3 * t + 2];
    if (a == b || b == c || a == c) {
      return makeError(Status::invalid_argument, "mesh: triangle " + std::to_string(t) +
                                                     " repeats a vertex (" + std::to_string(a) +
                                                     ", " + std::to_string(b) + ", " +
                                                     std::to_string(c) + ")");
    }
    // Zero area in double precision: the three corners are collinear (or coincide).
    const glm::dvec3 pa(positions[a]), pb(positions[b]), pc(positions[c]);
    const glm::dvec3 n = glm::cross(pb - pa, pc - pa);
    if (n.x == 0.0 && n.y == 0.0 && n.z == 0.0) {
      return makeError(Status::invalid_argument,
                       "mesh: triangle " + std::to_string(t) + " has zero area");
    }
  }
  return std::nullopt;
}

std::optional<Error> validateMesh(std::span<const glm::vec3> positions,
                                  std::span<const uint32_t> indices, const WorkLimit& limit) {
  LimitPoll poll(limit);
  if (positions.empty() || indices.empty()) {
    return makeError(Status::invalid_argument, "mesh: empty (" + std::to_string(positions.size()) +
                                                   " vertices, " + std::to_string(indices.size()) +
                                                   " indices)");
  }
  if (indices.size() % 3 != 0) {
    return makeError(
        Status::invalid_argument,
        "mesh: index count " + std::to_string(indices.size()) + " is not a multiple of 3");
  }
  for (size_t v = 0; v < positions.size(); ++v) {
    if (poll.reached()) return stopped();
    const glm::vec3& p = positions[v];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      return makeError(Status::invalid_argument,
                       "mesh: vertex " + std::to_string(v) + " has a NaN or infinite coordinate");
    }
  }
  for (size_t i = 0; i < indices.size(); ++i) {
    if (poll.reached()) return stopped();
    if (indices[i] >= positions.size()) {
      return makeError(Status::invalid_argument,
                       "mesh: index " + std::to_string(i) + " (triangle " + std::to_string(i / 3) +
                           ") is " + std::to_string(indices[i]) + ", but the mesh has " +
                           std::to_string(positions.size()) + " vertices");
    }
  }
  return findDegenerateTriangle(positions, indices, limit);
}

Result<TriangleMesh> makeMesh(std::span<const glm::vec3> positions,
                              std::span<const uint32_t> indices) {
  if (auto error = validateMesh(positions, indices)) return *error;
  TriangleMesh mesh;
  mesh.positions.assign(positions.begin(), positions.end());
  mesh.indices.assign(indices.begin(), indices.end());
  return mesh;
}

Result<TriangleMesh> makeMesh(std::span<const float> xyz, std::span<const uint32_t> indices) {
  if (xyz.size() % 3 != 0) {
    return makeError(
        Status::invalid_argument,
        "mesh: position array has " + std::to_string(xyz.size()) + " floats, not a multiple of 3");
  }
  std::vector<glm::vec3> positions(xyz.size() / 3);
  for (size_t v = 0; v < positions.size(); ++v) {
    positions[v] = glm::vec3(xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]);
  }
  return makeMesh(std::span<const glm::vec3>(positions), indices);
}

Aabb computeBounds(std::span<const glm::vec3> positions) {
  Aabb box;
  if (positions.empty()) return box;
  box.min = box.max = positions[0];
  for (const glm::vec3& p : positions) {
    box.min = glm::min(box.min, p);
    box.max = glm::max(box.max, p);
  }
  return box;
}

void transformMesh(TriangleMesh& mesh, const Pose& pose, float scale) {
  for (glm::vec3& p : mesh.positions) p = pose.transformPoint(p * scale);
}

TriangleMesh normalizedToDiagonal(const TriangleMesh& mesh, float diagonal) {
  return normalizedToDiagonal(mesh, diagonal, computeBounds(mesh.positions));
}

TriangleMesh normalizedToDiagonal(const TriangleMesh& mesh, float diagonal, const Aabb& box) {
  TriangleMesh out = mesh;
  const float current = glm::length(box.extent());
  const float scale = current > 0.0f ? diagonal / current : 1.0f;
  const glm::vec3 centre = box.center();
  for (glm::vec3& p : out.positions) p = (p - centre) * scale;
  return out;
}

}  // namespace sdfg
