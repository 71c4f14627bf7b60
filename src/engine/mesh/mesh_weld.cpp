// Welding by position and the overlap of connected parts. See the header.
#include "mesh/mesh_weld.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <numeric>
#include <unordered_map>
#include <unordered_set>

#include <glm/geometric.hpp>

#include "mesh/mesh.h"

namespace sdfg {
namespace {

constexpr uint32_t kNone = UINT32_MAX;

// A grid cell's key: three 21-bit cell coordinates. Coordinates are taken from the mesh's
// bounding-box corner in cells of the tolerance, so they stay below 2^21 for any tolerance of
// 1e-5 of the diagonal or more (up to 1e5 cells along the diagonal).
uint64_t cellKey(const glm::ivec3& c) {
  constexpr uint64_t kMask = (uint64_t(1) << 21) - 1;
  return (uint64_t(c.x) & kMask) | ((uint64_t(c.y) & kMask) << 21) |
         ((uint64_t(c.z) & kMask) << 42);
}

struct TriangleKeyHash {
  size_t operator()(const std::array<uint32_t, 3>& k) const {
    uint64_t h = k[0];
    h = h * 0x9e3779b97f4a7c15ull ^ k[1];
    h = h * 0x9e3779b97f4a7c15ull ^ k[2];
    return size_t(h ^ (h >> 29));
  }
};

uint32_t findRoot(std::vector<uint32_t>& parent, uint32_t v) {
  while (parent[v] != v) {
    parent[v] = parent[parent[v]];
    v = parent[v];
  }
  return v;
}

}  // namespace

std::string WeldReport::describe() const {
  std::string out;
  if (weldedVertices != vertices) {
    out =
        std::to_string(vertices) + " split vertices welded into " + std::to_string(weldedVertices);
    if (nearWelded > 0) out += " (" + std::to_string(nearWelded) + " within the tolerance)";
  } else {
    out = "no split vertices";
  }
  if (duplicateTriangles > 0)
    out += ", " + std::to_string(duplicateTriangles) + " duplicate triangles dropped";
  if (collapsedTriangles > 0)
    out += ", " + std::to_string(collapsedTriangles) + " triangles collapsed by the weld dropped";
  return out;
}

WeldReport weldByPosition(std::span<const glm::vec3> positions, std::vector<uint32_t>& indices,
                          const WorkLimit& limit) {
  assert(indices.size() % 3 == 0);
  WeldReport out;
  LimitPoll poll(limit);
  const auto stop = [] {
    WeldReport r;
    r.stopped = true;
    return r;
  };
  if (indices.empty()) return out;

  // The bounds of the referenced vertices set the tolerance and the grid's origin.
  glm::vec3 lo(positions[indices[0]]), hi = lo;
  for (uint32_t i : indices) {
    if (poll.reached()) return stop();
    lo = glm::min(lo, positions[i]);
    hi = glm::max(hi, positions[i]);
  }
  const float tolerance = kWeldRelativeTolerance * glm::length(hi - lo);
  const float cell = tolerance > 0.0f ? tolerance : 1.0f;
  const auto cellOf = [&](const glm::vec3& p) { return glm::ivec3(glm::floor((p - lo) / cell)); };

  // Each vertex, in the order the triangles first use it, is either a representative (the first
  // vertex at its position) or welded to the nearest representative within the tolerance. A
  // representative is never itself welded later, so no chain grows: every welded vertex is within
  // the tolerance of the position that replaces it.
  std::vector<uint32_t> weldTo(positions.size(), kNone);
  std::unordered_map<uint64_t, uint32_t> cellHead;  // first representative in a cell
  std::vector<uint32_t> nextInCell;                 // per representative, by representative rank
  std::vector<uint32_t> representatives;
  cellHead.reserve(indices.size() / 2);
  for (uint32_t v : indices) {
    if (poll.reached()) return stop();
    if (weldTo[v] != kNone) continue;
    ++out.vertices;
    const glm::vec3 p = positions[v];
    const glm::ivec3 c = cellOf(p);
    uint32_t best = kNone;
    float bestDistance = tolerance;
    for (int dz = -1; dz <= 1 && bestDistance > 0.0f; ++dz)
      for (int dy = -1; dy <= 1 && bestDistance > 0.0f; ++dy)
        for (int dx = -1; dx <= 1 && bestDistance > 0.0f; ++dx) {
          const auto it = cellHead.find(cellKey(c + glm::ivec3(dx, dy, dz)));
          if (it == cellHead.end()) continue;
          for (uint32_t r = it->second; r != kNone; r = nextInCell[r]) {
            const uint32_t rep = representatives[r];
            const float d = glm::length(positions[rep] - p);
            if (d <= bestDistance && (best == kNone || d < bestDistance)) {
              best = rep;
              bestDistance = d;
            }
          }
        }
    if (best != kNone) {
      weldTo[v] = best;
      if (positions[best] != p) ++out.nearWelded;
      continue;
    }
    weldTo[v] = v;
    const uint32_t rank = uint32_t(representatives.size());
    representatives.push_back(v);
    auto [it, inserted] = cellHead.try_emplace(cellKey(c), rank);
    nextInCell.push_back(inserted ? kNone : it->second);
    if (!inserted) it->second = rank;
  }
  out.weldedVertices = uint32_t(representatives.size());

  // Triangles on the welded vertices, dropping collapsed ones and repeats of an earlier
  // triangle's three corners in any order (a double-sided face is one face; the winding repair
  // decides which way it faces).
  std::vector<uint32_t> welded;
  welded.reserve(indices.size());
  std::unordered_set<std::array<uint32_t, 3>, TriangleKeyHash> seen;
  seen.reserve(indices.size() / 3);
  for (size_t t = 0; t < indices.size(); t += 3) {
    if (poll.reached()) return stop();
    const std::array<uint32_t, 3> corner = {weldTo[indices[t]], weldTo[indices[t + 1]],
                                            weldTo[indices[t + 2]]};
    if (corner[0] == corner[1] || corner[1] == corner[2] || corner[2] == corner[0]) {
      ++out.collapsedTriangles;
      continue;
    }
    std::array<uint32_t, 3> key = corner;
    std::sort(key.begin(), key.end());
    if (!seen.insert(key).second) {
      ++out.duplicateTriangles;
      continue;
    }
    welded.insert(welded.end(), corner.begin(), corner.end());
  }
  // A welded corner moves by up to the tolerance: a sliver thinner than that could be left with no
  // area, which no sign or normal can use. Such a mesh (or one below the tolerance in every
  // triangle) is kept as given.
  std::optional<Error> degenerate;
  if (!welded.empty() && out.weldedVertices != out.vertices)
    degenerate = findDegenerateTriangle(positions, welded, limit);
  if (degenerate && degenerate->code == Status::timed_out) return stop();
  if (welded.empty() || degenerate) {
    WeldReport unchanged;
    unchanged.vertices = unchanged.weldedVertices = out.vertices;
    return unchanged;
  }
  indices = std::move(welded);
  return out;
}

bool partsOverlap(std::span<const glm::vec3> positions, std::span<const uint32_t> indices) {
  // Parts through shared vertices (a union-find over the triangles' corners): on a welded mesh
  // that is the parts through shared edges, except parts that touch at a single vertex, which
  // then count as one (and cannot overlap as two).
  std::vector<uint32_t> parent(positions.size());
  std::iota(parent.begin(), parent.end(), 0u);
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    const uint32_t a = findRoot(parent, indices[t]);
    const uint32_t b = findRoot(parent, indices[t + 1]);
    const uint32_t c = findRoot(parent, indices[t + 2]);
    parent[b] = a;
    parent[c] = a;
  }
  std::unordered_map<uint32_t, Aabb> parts;
  for (uint32_t i : indices) {
    const uint32_t root = findRoot(parent, i);
    auto [it, inserted] = parts.try_emplace(root, Aabb{positions[i], positions[i]});
    if (!inserted) {
      it->second.min = glm::min(it->second.min, positions[i]);
      it->second.max = glm::max(it->second.max, positions[i]);
    }
  }
  if (parts.size() < 2) return false;
  // Sweep along x: each box is compared with the boxes whose x range is still open.
  std::vector<Aabb> boxes;
  boxes.reserve(parts.size());
  for (const auto& [root, box] : parts) boxes.push_back(box);
  std::sort(boxes.begin(), boxes.end(),
            [](const Aabb& a, const Aabb& b) { return a.min.x < b.min.x; });
  for (size_t i = 0; i < boxes.size(); ++i) {
    for (size_t j = i + 1; j < boxes.size() && boxes[j].min.x <= boxes[i].max.x; ++j) {
      const Aabb& a = boxes[i];
      const Aabb& b = boxes[j];
      if (a.min.y <= b.max.y && b.min.y <= a.max.y && a.min.z <= b.max.z && b.min.z <= a.max.z)
        return true;
    }
  }
  return false;
}

}  // namespace sdfg
