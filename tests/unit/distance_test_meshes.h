// Meshes and brute-force references shared by the distance and CPU SDF tests: small analytic
// meshes built here, the shared test meshes normalized to hand size (loaded once per process),
// and slow but obviously correct closest-point and inside/outside references.
#pragma once

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "io/mesh_io.h"
#include "io/shapes.h"
#include "mesh/mesh.h"
#include "mesh/triangle_bvh.h"
#include "test_support.h"

namespace sdfg::test {

// Axis-aligned cube of half-extent `h`, 12 outward counter-clockwise triangles.
inline TriangleMesh cubeMesh(float h) {
  return makeBox(glm::vec3(2.0f * h));
}

// Icosahedron subdivided `levels` times, vertices on the sphere of `radius`.
inline TriangleMesh icosphereMesh(float radius, int levels) {
  return makeSphere(radius, levels);
}

// A shared mesh scaled to a 0.18 m bounding-box diagonal and centred, as the benchmark uses
// them; loaded once per process. Nothing when the shared meshes are absent.
inline const TriangleMesh* normalizedSharedMesh(const std::string& name) {
  static std::map<std::string, std::optional<TriangleMesh>> cache;
  auto it = cache.find(name);
  if (it == cache.end()) {
    std::optional<TriangleMesh> mesh;
    if (const auto path = sharedMesh(name)) {
      if (auto loaded = loadMesh(*path)) mesh = normalizedToDiagonal(loaded->mesh, 0.18f);
    }
    it = cache.emplace(name, std::move(mesh)).first;
  }
  return it->second ? &*it->second : nullptr;
}

// Exact distance by testing every triangle.
inline double bruteForceDistance(const TriangleMesh& m, const glm::vec3& p) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t t = 0; t < m.triangleCount(); ++t) {
    const auto c = closestPointOnTriangle(glm::dvec3(p), glm::dvec3(m.positions[m.indices[3 * t]]),
                                          glm::dvec3(m.positions[m.indices[3 * t + 1]]),
                                          glm::dvec3(m.positions[m.indices[3 * t + 2]]));
    best = std::min(best, c.distanceSquared);
  }
  return std::sqrt(best);
}

// Number of triangles a ray from `o` along `d` crosses (Moller-Trumbore, double precision).
inline int rayCrossings(const TriangleMesh& m, const glm::dvec3& o, const glm::dvec3& d) {
  int hits = 0;
  for (size_t t = 0; t < m.triangleCount(); ++t) {
    const glm::dvec3 a(m.positions[m.indices[3 * t]]), b(m.positions[m.indices[3 * t + 1]]),
        c(m.positions[m.indices[3 * t + 2]]);
    const glm::dvec3 e1 = b - a, e2 = c - a, q = glm::cross(d, e2);
    const double det = glm::dot(e1, q);
    if (std::abs(det) < 1e-300) continue;
    const double inv = 1.0 / det;
    const glm::dvec3 s = o - a;
    const double u = glm::dot(s, q) * inv;
    if (u < 0.0 || u > 1.0) continue;
    const glm::dvec3 r = glm::cross(s, e1);
    const double v = glm::dot(d, r) * inv;
    if (v < 0.0 || u + v > 1.0) continue;
    if (glm::dot(e2, r) * inv > 0.0) ++hits;
  }
  return hits;
}

// Reference inside/outside by ray parity along `rays` random directions. Returns +1 when every
// ray says inside, -1 when every ray says outside, 0 when they disagree (a point near a hole or
// a grazing ray): callers only judge the unanimous points.
inline int rayParityVote(const TriangleMesh& m, const glm::vec3& p, std::mt19937& rng,
                         int rays = 5) {
  std::normal_distribution<double> g;
  int inside = 0;
  for (int r = 0; r < rays; ++r) {
    const glm::dvec3 d = glm::normalize(glm::dvec3(g(rng), g(rng), g(rng)));
    inside += rayCrossings(m, glm::dvec3(p), d) % 2;
  }
  return inside == rays ? 1 : inside == 0 ? -1 : 0;
}

}  // namespace sdfg::test
