// Triangle meshes as the core takes them: positions and 32-bit indices, validated once.
//
// Every mesh that reaches the SDF builders or solvers went through makeMesh(), so they may
// assume finite positions, indices in range, and no degenerate triangles. Units are metres.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "base/pose.h"
#include "base/status.h"
#include "base/work_limit.h"

namespace sdfg {

struct TriangleMesh {
  std::vector<glm::vec3> positions;
  std::vector<uint32_t> indices;  // three per triangle, counter-clockwise seen from outside

  size_t vertexCount() const { return positions.size(); }
  size_t triangleCount() const { return indices.size() / 3; }
};

struct Aabb {
  glm::vec3 min{0.0f};
  glm::vec3 max{0.0f};
  glm::vec3 center() const { return (min + max) * 0.5f; }
  glm::vec3 extent() const { return max - min; }
};

// Checks arrays before anything is built. Returns the first problem found, naming the element:
// empty mesh, index count not a multiple of 3, NaN or infinite coordinate, index out of range,
// degenerate triangle (two equal indices, or zero area). Returns nothing when the mesh is valid.
// `limit` is polled every few thousand elements; once reached the check stops with an error of
// code timed_out (a mesh of 2^24 vertices takes a good fraction of a second).
std::optional<Error> validateMesh(std::span<const glm::vec3> positions,
                                  std::span<const uint32_t> indices,
                                  const WorkLimit& limit = WorkLimit::none());

// The degenerate-triangle part of validateMesh() alone, for new positions of a topology already
// validated (indices in range): the first triangle that repeats a vertex or has zero area.
std::optional<Error> findDegenerateTriangle(std::span<const glm::vec3> positions,
                                            std::span<const uint32_t> indices,
                                            const WorkLimit& limit = WorkLimit::none());

// Validates and copies the arrays into a mesh. Nothing is built when validation fails.
Result<TriangleMesh> makeMesh(std::span<const glm::vec3> positions,
                              std::span<const uint32_t> indices);

// Same, from interleaved float xyz triples (positions.size() must be a multiple of 3).
Result<TriangleMesh> makeMesh(std::span<const float> xyz, std::span<const uint32_t> indices);

Aabb computeBounds(std::span<const glm::vec3> positions);

// Applies parent = pose * (scale * p) to every vertex.
void transformMesh(TriangleMesh& mesh, const Pose& pose, float scale = 1.0f);

// Returns a copy scaled uniformly so the bounding-box diagonal equals `diagonal` metres and
// centred on the origin (the benchmark scales every object to hand size this way).
TriangleMesh normalizedToDiagonal(const TriangleMesh& mesh, float diagonal);
// Same, with the scale and centre taken from `box` instead of the mesh's own bounds (a variant of
// a mesh placed exactly as the original is).
TriangleMesh normalizedToDiagonal(const TriangleMesh& mesh, float diagonal, const Aabb& box);

}  // namespace sdfg
