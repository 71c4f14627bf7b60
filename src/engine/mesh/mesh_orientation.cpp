// Orientation of triangle meshes: consistent winding per connected part, then outward by signed
// volume (closed parts) or by the generalized winding number (open parts). See the header.
#include "mesh/mesh_orientation.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <deque>
#include <numbers>
#include <optional>

#include <glm/geometric.hpp>

#include "base/polled_sort.h"

namespace sdfg {
namespace {

// One triangle's use of an undirected edge: +1 when it runs from the smaller vertex id to the
// larger, -1 the other way.
struct EdgeUse {
  uint32_t triangle;
  int direction;
};

uint64_t edgeKey(uint32_t a, uint32_t b) {
  return (uint64_t(std::min(a, b)) << 32) | std::max(a, b);
}

glm::dvec3 at(std::span<const glm::vec3> positions, uint32_t i) {
  return glm::dvec3(positions[i]);
}

// Vertex k (0..2) of triangle t as currently oriented (a flipped triangle swaps its last two).
uint32_t corner(const std::vector<uint32_t>& indices, const std::vector<char>& flip, uint32_t t,
                int k) {
  if (flip[t] && k > 0) k = 3 - k;
  return indices[3 * size_t(t) + size_t(k)];
}

// windingNumberAt() that gives up (nothing) once `poll` says the limit is reached.
std::optional<double> windingNumberPolled(std::span<const glm::vec3> positions,
                                          std::span<const uint32_t> indices, const glm::dvec3& p,
                                          LimitPoll& poll) {
  // Solid angle of each triangle (Van Oosterom & Strackee 1983), summed and divided by 4 pi.
  double sum = 0.0;
  for (size_t i = 0; i + 2 < indices.size(); i += 3) {
    if (poll.reached()) return std::nullopt;
    const glm::dvec3 a = at(positions, indices[i]) - p;
    const glm::dvec3 b = at(positions, indices[i + 1]) - p;
    const glm::dvec3 c = at(positions, indices[i + 2]) - p;
    const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
    const double num = glm::dot(a, glm::cross(b, c));
    const double den =
        la * lb * lc + glm::dot(a, b) * lc + glm::dot(b, c) * la + glm::dot(c, a) * lb;
    sum += 2.0 * std::atan2(num, den);
  }
  return sum / (4.0 * std::numbers::pi);
}

}  // namespace

double windingNumberAt(std::span<const glm::vec3> positions, std::span<const uint32_t> indices,
                       const glm::dvec3& p) {
  const WorkLimit none;
  LimitPoll poll(none);
  return *windingNumberPolled(positions, indices, p, poll);
}

const char* MeshOrientation::describe() const {
  if (inconsistent > 0) return "mixed";
  if (invertedComponents > 0) return "clockwise (inside-out)";
  return "counter-clockwise (outward)";
}

MeshOrientation orientOutward(std::span<const glm::vec3> positions, std::vector<uint32_t>& indices,
                              const WorkLimit& limit) {
  assert(indices.size() % 3 == 0);
  const uint32_t triangles = uint32_t(indices.size() / 3);
  MeshOrientation out;
  if (triangles == 0) return out;
  // Every loop below polls, so the time between two looks at the limit stays bounded whatever
  // the mesh; nothing is written to `indices` before the last loop.
  LimitPoll poll(limit);
  const auto stop = [&out] {
    out = MeshOrientation{};
    out.stopped = true;
    return out;
  };

  // Each corner's edge (slot 3t + k runs from corner k to corner k + 1), grouped by undirected
  // edge: sorted by (edge, slot), so an edge's uses come in triangle order. A flat array rather
  // than a hash map of lists: sorted with the limit in view, and freed at once when the work
  // stops (freeing a million small lists took a tenth of a second).
  struct HalfEdge {
    uint64_t key;
    uint32_t slot;
  };
  std::vector<HalfEdge> sorted(3 * size_t(triangles));
  for (uint32_t t = 0; t < triangles; ++t) {
    if (poll.reached()) return stop();
    for (uint32_t k = 0; k < 3; ++k) {
      const uint32_t a = indices[3 * size_t(t) + k], b = indices[3 * size_t(t) + (k + 1) % 3];
      assert(a < positions.size() && b < positions.size());
      sorted[3 * size_t(t) + k] = {edgeKey(a, b), 3 * t + k};
    }
  }
  const auto bySlot = [](const HalfEdge& x, const HalfEdge& y) {
    return x.key < y.key || (x.key == y.key && x.slot < y.slot);
  };
  if (!polledSort(sorted, bySlot, limit)) return stop();
  // Per slot: where its edge's uses start in `sorted`, and how many there are.
  std::vector<uint32_t> groupStart(sorted.size()), groupSize(sorted.size());
  for (size_t i = 0; i < sorted.size();) {
    if (poll.reached()) return stop();
    size_t j = i;
    while (j < sorted.size() && sorted[j].key == sorted[i].key) ++j;
    for (size_t m = i; m < j; ++m) {
      groupStart[sorted[m].slot] = uint32_t(i);
      groupSize[sorted[m].slot] = uint32_t(j - i);
    }
    i = j;
  }
  const auto useAt = [&](size_t position) {
    const uint32_t slot = sorted[position].slot, t = slot / 3, k = slot % 3;
    const uint32_t a = indices[slot], b = indices[3 * size_t(t) + (k + 1) % 3];
    return EdgeUse{t, a < b ? 1 : -1};
  };

  // Breadth-first over each connected part through manifold edges (two triangles): a neighbour
  // agrees when it runs the shared edge the other way. The first assignment wins on a
  // non-orientable part (a Moebius strip), which has no consistent answer.
  std::vector<char> flip(triangles, 0);
  std::vector<uint32_t> part(triangles, UINT32_MAX);
  std::vector<std::vector<uint32_t>> parts;
  std::deque<uint32_t> queue;
  for (uint32_t seed = 0; seed < triangles; ++seed) {
    if (part[seed] != UINT32_MAX) continue;
    const uint32_t id = uint32_t(parts.size());
    parts.emplace_back();
    part[seed] = id;
    queue.push_back(seed);
    while (!queue.empty()) {
      if (poll.reached()) return stop();
      const uint32_t t = queue.front();
      queue.pop_front();
      parts[id].push_back(t);
      for (uint32_t k = 0; k < 3; ++k) {
        const uint32_t slot = 3 * t + k;
        if (groupSize[slot] != 2) continue;
        const EdgeUse uses[2] = {useAt(groupStart[slot]), useAt(groupStart[slot] + 1)};
        const EdgeUse& self = uses[0].triangle == t ? uses[0] : uses[1];
        const EdgeUse& other = uses[0].triangle == t ? uses[1] : uses[0];
        if (other.triangle == t || part[other.triangle] != UINT32_MAX) continue;
        part[other.triangle] = id;
        flip[other.triangle] = char((other.direction == self.direction) != bool(flip[t]));
        queue.push_back(other.triangle);
      }
    }
  }

  double diagonal = 0.0;
  {
    glm::dvec3 lo(positions.empty() ? glm::dvec3(0.0) : at(positions, 0)), hi = lo;
    for (const glm::vec3& p : positions) {
      lo = glm::min(lo, glm::dvec3(p));
      hi = glm::max(hi, glm::dvec3(p));
    }
    diagonal = glm::length(hi - lo);
  }

  out.components = uint32_t(parts.size());
  for (const auto& tris : parts) {
    if (poll.reached()) return stop();
    // The walk's seed is arbitrary: the triangles it disagrees with are the minority.
    uint32_t disagree = 0;
    for (uint32_t t : tris) disagree += flip[t] ? 1 : 0;
    if (2 * disagree > tris.size()) {
      for (uint32_t t : tris) flip[t] = char(!flip[t]);
      disagree = uint32_t(tris.size()) - disagree;
    }
    out.inconsistent += disagree;

    bool closed = true;
    for (uint32_t t : tris) {
      if (poll.reached()) return stop();
      for (uint32_t k = 0; k < 3 && closed; ++k) closed = groupSize[3 * size_t(t) + k] == 2;
    }
    double vote = 0.0;
    if (closed) {
      ++out.closedComponents;
      // Six times the signed volume: positive when the triangles face outward.
      for (uint32_t t : tris) {
        if (poll.reached()) return stop();
        const glm::dvec3 a = at(positions, corner(indices, flip, t, 0));
        const glm::dvec3 b = at(positions, corner(indices, flip, t, 1));
        const glm::dvec3 c = at(positions, corner(indices, flip, t, 2));
        vote += glm::dot(a, glm::cross(b, c));
      }
    } else {
      // The winding number of the whole mesh as oriented so far, just in front of and behind
      // sampled triangles: their mean is positive when this part is seen from its inner side.
      std::vector<uint32_t> current(indices.size());
      for (uint32_t t = 0; t < triangles; ++t) {
        if (poll.reached()) return stop();
        for (int k = 0; k < 3; ++k) current[3 * size_t(t) + k] = corner(indices, flip, t, k);
      }
      const size_t samples = std::min<size_t>(16, tris.size());
      const double step = 1e-3 * diagonal;
      for (size_t i = 0; i < samples; ++i) {
        const uint32_t t = tris[i * tris.size() / samples];
        const glm::dvec3 a = at(positions, current[3 * size_t(t)]);
        const glm::dvec3 b = at(positions, current[3 * size_t(t) + 1]);
        const glm::dvec3 c = at(positions, current[3 * size_t(t) + 2]);
        const glm::dvec3 n = glm::cross(b - a, c - a);
        const double len = glm::length(n);
        if (!(len > 0.0)) continue;
        const glm::dvec3 centre = (a + b + c) / 3.0;
        const glm::dvec3 offset = n / len * step;
        const std::optional<double> front =
            windingNumberPolled(positions, current, centre + offset, poll);
        const std::optional<double> back =
            windingNumberPolled(positions, current, centre - offset, poll);
        if (!front || !back) return stop();
        vote += *front + *back;
      }
    }
    if (vote < 0.0) {
      ++out.invertedComponents;
      for (uint32_t t : tris) flip[t] = char(!flip[t]);
    }
  }

  for (uint32_t t = 0; t < triangles; ++t) {
    if (!flip[t]) continue;
    std::swap(indices[3 * size_t(t) + 1], indices[3 * size_t(t) + 2]);
    ++out.flipped;
  }
  return out;
}

}  // namespace sdfg
