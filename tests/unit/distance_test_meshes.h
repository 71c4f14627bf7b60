// Meshes and brute-force references shared by the distance and CPU SDF tests: small analytic
// meshes built here, the shared test meshes normalized to hand size (loaded once per process),
// and slow but obviously correct closest-point and inside/outside references.
#pragma once

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "mesh.h"
#include "test_support.h"
#include "triangle_bvh.h"

namespace sdfg::test {

// Axis-aligned cube of half-extent `h`, 12 outward counter-clockwise triangles.
inline TriangleMesh cubeMesh(float h) {
  TriangleMesh m;
  for (int i = 0; i < 8; ++i) {
    m.positions.emplace_back((i & 1) ? h : -h, (i & 2) ? h : -h, (i & 4) ? h : -h);
  }
  // Each face as a quad (a, b, c, d) counter-clockwise seen from outside.
  const uint32_t quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& q : quads) {
    m.indices.insert(m.indices.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
  }
  return m;
}

// Icosahedron subdivided `levels` times, vertices pushed onto the sphere of `radius`.
inline TriangleMesh icosphereMesh(float radius, int levels) {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  std::vector<glm::vec3> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                              {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                              {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<uint32_t> f = {0, 11, 5,  0, 5,  1, 0, 1, 7, 0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11,
                             4, 11, 10, 2, 10, 7, 6, 7, 1, 8, 3,  9,  4, 3,  4,  2, 3, 2, 6, 3,
                             6, 8,  3,  8, 9,  4, 9, 5, 2, 4, 11, 6,  2, 10, 8,  6, 7, 9, 8, 1};
  for (glm::vec3& p : v) p = glm::normalize(p);
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
    const auto midpoint = [&](uint32_t a, uint32_t b) {
      const auto key = std::minmax(a, b);
      const auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back(glm::normalize(v[a] + v[b]));
      return mid[key] = uint32_t(v.size() - 1);
    };
    std::vector<uint32_t> g;
    for (size_t i = 0; i < f.size(); i += 3) {
      const uint32_t a = f[i], b = f[i + 1], c = f[i + 2];
      const uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      g.insert(g.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
    }
    f = std::move(g);
  }
  TriangleMesh m;
  for (const glm::vec3& p : v) m.positions.push_back(p * radius);
  m.indices = std::move(f);
  return m;
}

// Minimal reader for the shared OBJ files (v and triangle f lines only), dropping zero-area
// triangles. Stands in for loadMesh() until the mesh I/O unit lands.
inline std::optional<TriangleMesh> readObj(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) return std::nullopt;
  TriangleMesh m;
  std::string line;
  while (std::getline(in, line)) {
    if (line.size() < 2) continue;
    if (line[0] == 'v' && line[1] == ' ') {
      std::istringstream s(line.substr(2));
      glm::vec3 p;
      s >> p.x >> p.y >> p.z;
      m.positions.push_back(p);
    } else if (line[0] == 'f' && line[1] == ' ') {
      std::istringstream s(line.substr(2));
      std::string token;
      std::vector<uint32_t> poly;
      while (s >> token) poly.push_back(uint32_t(std::stoul(token.substr(0, token.find('/'))) - 1));
      for (size_t k = 2; k < poly.size(); ++k) {
        const glm::dvec3 a(m.positions[poly[0]]), b(m.positions[poly[k - 1]]),
            c(m.positions[poly[k]]);
        const glm::dvec3 n = glm::cross(b - a, c - a);
        if (n.x == 0.0 && n.y == 0.0 && n.z == 0.0) continue;
        m.indices.insert(m.indices.end(), {poly[0], poly[k - 1], poly[k]});
      }
    }
  }
  return m;
}

// A shared mesh scaled to a 0.18 m bounding-box diagonal and centred, as the benchmark uses
// them; loaded once per process. Nothing when the shared meshes are absent.
inline const TriangleMesh* normalizedSharedMesh(const std::string& name) {
  static std::map<std::string, std::optional<TriangleMesh>> cache;
  auto it = cache.find(name);
  if (it == cache.end()) {
    std::optional<TriangleMesh> mesh;
    if (const auto path = sharedMesh(name)) {
      if (auto m = readObj(*path)) mesh = normalizedToDiagonal(*m, 0.18f);
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
