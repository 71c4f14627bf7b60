#include "io/mesh_variants.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace sdfg {

namespace {

constexpr std::array<std::string_view, 3> kNames = {"soup", "flat", "seams"};

// Unnormalised face normal, in double: a sliver's normal still has a sign and a dominant axis.
glm::dvec3 faceNormal(const TriangleMesh& mesh, size_t t) {
  const glm::dvec3 a(mesh.positions[mesh.indices[3 * t]]);
  const glm::dvec3 b(mesh.positions[mesh.indices[3 * t + 1]]);
  const glm::dvec3 c(mesh.positions[mesh.indices[3 * t + 2]]);
  return glm::cross(b - a, c - a);
}

// The mesh whose corners use one vertex per (original vertex, group of the corner's triangle)
// pair: corners share an index exactly when they shared one before and their triangles are in
// the same group. New vertices in the order of first use.
TriangleMesh splitByGroup(const TriangleMesh& mesh, const std::vector<uint32_t>& groupOfTriangle) {
  TriangleMesh out;
  out.indices.resize(mesh.indices.size());
  std::unordered_map<uint64_t, uint32_t> copies;  // vertex << 32 | group -> new index
  copies.reserve(mesh.positions.size() * 2);
  for (size_t c = 0; c < mesh.indices.size(); ++c) {
    const uint32_t v = mesh.indices[c];
    const uint64_t key = (uint64_t(v) << 32) | groupOfTriangle[c / 3];
    const auto [it, added] = copies.try_emplace(key, uint32_t(out.positions.size()));
    if (added) out.positions.push_back(mesh.positions[v]);
    out.indices[c] = it->second;
  }
  return out;
}

// Union-find over triangles (path halving; the smaller index becomes the root, so the groups do
// not depend on anything but the order of the unions, which is fixed).
struct Regions {
  std::vector<uint32_t> parent;
  explicit Regions(size_t n) : parent(n) {
    for (size_t i = 0; i < n; ++i) parent[i] = uint32_t(i);
  }
  uint32_t find(uint32_t x) {
    while (parent[x] != x) {
      parent[x] = parent[parent[x]];
      x = parent[x];
    }
    return x;
  }
  void join(uint32_t a, uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

}  // namespace

TriangleMesh soupVariant(const TriangleMesh& mesh) {
  TriangleMesh out;
  out.positions.reserve(mesh.indices.size());
  out.indices.resize(mesh.indices.size());
  for (size_t c = 0; c < mesh.indices.size(); ++c) {
    out.positions.push_back(mesh.positions[mesh.indices[c]]);
    out.indices[c] = uint32_t(c);
  }
  return out;
}

TriangleMesh flatVariant(const TriangleMesh& mesh, float splitAngleDegrees) {
  const size_t triangles = mesh.triangleCount();
  std::vector<glm::dvec3> normals(triangles);
  for (size_t t = 0; t < triangles; ++t) {
    const glm::dvec3 n = faceNormal(mesh, t);
    const double length = glm::length(n);
    normals[t] = length > 0.0 ? n / length : glm::dvec3(0.0);
  }
  // Every edge use, sorted so the triangles sharing an undirected edge are adjacent.
  struct EdgeUse {
    uint64_t edge;  // min vertex << 32 | max vertex
    uint32_t triangle;
    bool operator<(const EdgeUse& o) const {
      return edge != o.edge ? edge < o.edge : triangle < o.triangle;
    }
  };
  std::vector<EdgeUse> uses;
  uses.reserve(mesh.indices.size());
  for (size_t t = 0; t < triangles; ++t) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = mesh.indices[3 * t + size_t(k)];
      const uint32_t b = mesh.indices[3 * t + size_t((k + 1) % 3)];
      uses.push_back({(uint64_t(std::min(a, b)) << 32) | std::max(a, b), uint32_t(t)});
    }
  }
  std::sort(uses.begin(), uses.end());
  const double cosLimit = std::cos(double(splitAngleDegrees) * 3.14159265358979323846 / 180.0);
  Regions regions(triangles);
  for (size_t i = 0; i < uses.size();) {
    size_t j = i + 1;
    while (j < uses.size() && uses[j].edge == uses[i].edge) ++j;
    // A boundary or non-manifold edge is hard: no exporter smooths across it either.
    if (j - i == 2) {
      const uint32_t s = uses[i].triangle, t = uses[i + 1].triangle;
      if (glm::dot(normals[s], normals[t]) >= cosLimit) regions.join(s, t);
    }
    i = j;
  }
  std::vector<uint32_t> group(triangles);
  for (size_t t = 0; t < triangles; ++t) group[t] = regions.find(uint32_t(t));
  return splitByGroup(mesh, group);
}

TriangleMesh seamsVariant(const TriangleMesh& mesh) {
  const size_t triangles = mesh.triangleCount();
  std::vector<uint32_t> chart(triangles);
  for (size_t t = 0; t < triangles; ++t) {
    const glm::dvec3 n = faceNormal(mesh, t);
    int axis = 0;
    for (int k = 1; k < 3; ++k) {
      if (std::abs(n[k]) > std::abs(n[axis])) axis = k;
    }
    chart[t] = uint32_t(2 * axis + (n[axis] < 0.0 ? 1 : 0));
  }
  return splitByGroup(mesh, chart);
}

std::span<const std::string_view> meshVariantNames() {
  return kNames;
}

Result<TriangleMesh> makeMeshVariant(std::string_view name, const TriangleMesh& mesh) {
  if (auto error = validateMesh(mesh.positions, mesh.indices)) {
    return makeError(error->code, error->message);
  }
  if (name == "soup") return soupVariant(mesh);
  if (name == "flat") return flatVariant(mesh);
  if (name == "seams") return seamsVariant(mesh);
  return makeError(Status::invalid_argument,
                   "unknown mesh variant \"" + std::string(name) + "\" (soup, flat or seams)");
}

}  // namespace sdfg
