#include "sdf/sdf_cpu.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <functional>
#include <limits>
#include <mutex>
#include <thread>
#include <vector>

#include <glm/geometric.hpp>

namespace sdfg {

// Workers sleep on `wake` until a new generation of work is posted; the calling thread works
// too, so a builder with one thread starts none.
struct CpuSdfBuilder::Pool {
  explicit Pool(unsigned threads) {
    for (unsigned i = 1; i < threads; ++i) workers.emplace_back([this] { loop(); });
  }
  ~Pool() {
    {
      std::lock_guard lock(mutex);
      stopping = true;
    }
    wake.notify_all();
    for (std::thread& t : workers) t.join();
  }

  // Runs `job` on every worker and on the caller; returns when all have finished it.
  void run(const std::function<void()>& fn) {
    {
      std::lock_guard lock(mutex);
      job = &fn;
      busy = unsigned(workers.size());
      ++generation;
    }
    wake.notify_all();
    fn();
    std::unique_lock lock(mutex);
    done.wait(lock, [this] { return busy == 0; });
    job = nullptr;
  }

  void loop() {
    uint64_t seen = 0;
    for (;;) {
      const std::function<void()>* fn;
      {
        std::unique_lock lock(mutex);
        wake.wait(lock, [&] { return stopping || generation != seen; });
        if (stopping) return;
        seen = generation;
        fn = job;
      }
      (*fn)();
      {
        std::lock_guard lock(mutex);
        --busy;
      }
      done.notify_one();
    }
  }

  std::vector<std::thread> workers;
  std::mutex mutex;
  std::condition_variable wake, done;
  const std::function<void()>* job = nullptr;
  unsigned busy = 0;
  uint64_t generation = 0;
  bool stopping = false;
};

CpuSdfBuilder::CpuSdfBuilder(unsigned threads) {
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  pool_ = std::make_unique<Pool>(threads);
}

CpuSdfBuilder::~CpuSdfBuilder() = default;

Status CpuSdfBuilder::build(const MeshDistance& target, const Pose& objectFromHand,
                            const GridBox& box, SdfGrid& out, const CpuSdfOptions& options,
                            const WorkLimit& limit) {
  if (!(options.exactBand >= 0.0f) || !std::isfinite(options.exactBand)) {
    return Status::invalid_argument;
  }
  if (options.exactBand == 0.0f) return buildExact(target, objectFromHand, box, out, limit);
  return buildFar(target, objectFromHand, box, options.exactBand, out, limit);
}

Status CpuSdfBuilder::build(const MeshDistance& target, const Pose& objectFromHand,
                            const GridBox& box, SdfGrid& out) {
  return buildExact(target, objectFromHand, box, out, WorkLimit::none());
}

Status CpuSdfBuilder::buildExact(const MeshDistance& target, const Pose& objectFromHand,
                                 const GridBox& box, SdfGrid& out, const WorkLimit& limit) {
  if (box.validate()) return Status::invalid_argument;
  SdfGrid grid(box);
  const Pose objectFromBox = objectFromHand * box.handFromBox;
  const glm::uvec3 n = box.resolution;
  // Work is handed out by rows of 2x2x2 blocks of nodes along x. A block's nodes share one walk of
  // the triangle hierarchy (MeshDistance::signedDistances), and each node is seeded with the
  // closest triangle of the nearest node of the previous block along x, whose distance bounds the
  // search. Rows start unseeded and never depend on one another, so
  // the grid is the same whatever the thread count.
  const glm::uvec3 blocks = (n + 1u) / 2u;
  const uint32_t rows = blocks.y * blocks.z;
  std::span<float> values = grid.values();
  std::atomic<uint32_t> nextRow{0};
  std::atomic<bool> stopped{false};

  const std::function<void()> work = [&] {
    constexpr size_t kGroup = MeshDistance::kGroupSize;
    static_assert(kGroup == 8, "a group is one 2x2x2 block");
    for (;;) {
      const uint32_t row = nextRow.fetch_add(1, std::memory_order_relaxed);
      if (row >= rows) return;
      // A row is at most kMaxGridResolution / 2 block queries: the bound is overrun by one row.
      if (stopped.load(std::memory_order_relaxed) || limit.reached()) {
        stopped.store(true, std::memory_order_relaxed);
        return;
      }
      const uint32_t j0 = 2 * (row % blocks.y), k0 = 2 * (row / blocks.y);
      // hint[c]: closest triangle last found at corner c = dx + 2 dy + 4 dz of a block.
      std::array<uint32_t, kGroup> hint;
      hint.fill(std::numeric_limits<uint32_t>::max());
      std::array<glm::vec3, kGroup> points;
      std::array<uint32_t, kGroup> triangles, corner;
      std::array<float, kGroup> distances;
      std::array<size_t, kGroup> slot;
      for (uint32_t i0 = 0; i0 < n.x; i0 += 2) {
        size_t count = 0;
        for (uint32_t c = 0; c < kGroup; ++c) {
          const uint32_t i = i0 + (c & 1), j = j0 + ((c >> 1) & 1), k = k0 + (c >> 2);
          if (i >= n.x || j >= n.y || k >= n.z) continue;  // odd resolution: a partial block
          points[count] = objectFromBox.transformPoint(box.nodeLocal(i, j, k));
          triangles[count] = hint[c];
          corner[count] = c;
          slot[count] = grid.index(i, j, k);
          ++count;
        }
        target.signedDistances(std::span(points.data(), count), std::span(triangles.data(), count),
                               std::span(distances.data(), count));
        // The next block's near face (dx = 0) is one step from this block's far face (dx = 1),
        // its far face two steps: both start from the far face's triangles (corners ascend, so
        // the far face's write comes last).
        for (size_t l = 0; l < count; ++l) {
          values[slot[l]] = distances[l];
          hint[corner[l] & ~1u] = hint[corner[l] | 1u] = triangles[l];
        }
      }
    }
  };
  pool_->run(work);
  if (stopped.load()) return Status::timed_out;
  out = std::move(grid);
  lastExactNodes_ = box.nodeCount();
  return Status::ok;
}

// Far-field mode. Nodes are visited coarse to fine over nested lattices: stride 4 (every 4th
// node per axis plus the last one), then 2, then 1. Every node of the coarsest lattice is queried
// exactly. A node first met at stride s takes as sources the nodes of the stride-2s lattice that
// bracket it on each axis (up to 8, all already known). From a source q known to lie at least
// m(q) from the surface, the triangle inequality gives |d(p)| >= m(q) - |p - q|. When the best
// such bound b reaches the band, p is not queried and gets b:
//  - b <= |d(p)| by the inequality above (the unsigned distance is 1-Lipschitz whatever the sign),
//    so every node closer than the band is queried exactly;
//  - the sign: on a mesh signed by pseudo-normals (closed and consistently oriented), the open
//    ball of radius m(q) > |p - q| about q holds no surface point and contains p, so p and q lie
//    in the same component of space minus the surface, where (for a mesh without self-
//    intersections, the case the pseudo-normal sign is exact for: Baerentzen & Aanaes) the sign
//    is constant; sources that disagree (a self-intersecting mesh) send p to the exact query.
//    On a mesh signed by winding number, a hole lets the winding number cross 1/2 without
//    crossing the surface, so no ball argument holds: each bounded node takes the sign from
//    MeshDistance::windingSign, the very comparison the exact query makes (no closest-point
//    search, the expensive part far away).
// A bounded source gives a valid bound too (m(q) is itself a lower bound), so bounds chain.
//
// Rounding: a stored float distance is within half an ulp of the true distance of the stored
// (float) node position, and |p - q| is taken in double between those positions; m(q) is scaled
// by (1 - 1e-6) before the subtraction, which more than covers both roundings, so the float
// bound never exceeds the float exact value (rounding is monotonic).
//
// Finally the bounds are raised to the max-plus closure over grid edges, b(p) >= m(q) - h_axis
// for each neighbour q (two raster passes, exact for this separable metric): still lower bounds
// (each step is the triangle inequality along one edge), and it makes every axis difference of
// the node values at most the spacing, as for exact distances, so the trilinear interpolant
// keeps the sqrt(3) slope bound the solvers rely on (solver_ours.cpp, kInterpolantLipschitz).
// Against exact values: an exact neighbour q of a bounded p has |d(q)| <= |d(p)| + h, and
// b(p) >= |d(q)| - h by the closure. Results do not depend on the thread count: hints come
// from coarser levels or from earlier nodes of the same row, never from another row.
namespace {
constexpr uint32_t kCoarsestStride = 4;
constexpr uint32_t kNoTriangle = std::numeric_limits<uint32_t>::max();
enum : uint8_t { kUnset = 0, kExact = 1, kBounded = 2 };

// Node indices along an axis of n nodes on the lattice of stride s: multiples of s and the last.
std::vector<uint32_t> latticeIndices(uint32_t n, uint32_t s) {
  std::vector<uint32_t> out;
  for (uint32_t i = 0; i < n; i += s) out.push_back(i);
  if (out.back() != n - 1) out.push_back(n - 1);
  return out;
}

// The nodes of the stride-2s lattice bracketing index i (itself when on it).
uint32_t bracket(uint32_t i, uint32_t n, uint32_t s2, std::array<uint32_t, 2>& out) {
  if (i % s2 == 0 || i == n - 1) {
    out[0] = i;
    return 1;
  }
  out[0] = i / s2 * s2;
  out[1] = std::min(out[0] + s2, n - 1);
  return 2;
}

}  // namespace

Status CpuSdfBuilder::buildFar(const MeshDistance& target, const Pose& objectFromHand,
                               const GridBox& box, float band, SdfGrid& out,
                               const WorkLimit& limit) {
  if (box.validate()) return Status::invalid_argument;
  SdfGrid grid(box);
  const Pose objectFromBox = objectFromHand * box.handFromBox;
  const glm::uvec3 n = box.resolution;
  const size_t count = box.nodeCount();
  std::vector<glm::vec3> points(count);
  for (uint32_t k = 0; k < n.z; ++k) {
    for (uint32_t j = 0; j < n.y; ++j) {
      for (uint32_t i = 0; i < n.x; ++i) {
        // Same expression as build(), so exact nodes get the same float positions and values.
        points[grid.index(i, j, k)] = objectFromBox.transformPoint(box.nodeLocal(i, j, k));
      }
    }
  }
  std::span<float> values = grid.values();
  std::vector<float> magnitude(count, 0.0f), sign(count, 1.0f);
  std::vector<uint8_t> state(count, kUnset);
  std::vector<uint32_t> hint(count, kNoTriangle);
  std::vector<uint32_t> needSign;  // bounded nodes of a winding-signed mesh
  const bool windingSigns = target.signsByWinding();
  const double band64 = band;
  size_t exactCount = 0;

  // Queued exact queries of one level, by rows of 2x2x2 blocks of its lattice.
  std::vector<uint32_t> queue;
  std::vector<uint8_t> queueCorner;
  std::vector<uint32_t> groupEnd;  // one group per 2x2x2 block of the lattice with queued nodes
  std::vector<uint32_t> rowStart;  // first group of each row
  for (uint32_t s = kCoarsestStride; s >= 1; s /= 2) {
    const std::array<std::vector<uint32_t>, 3> lattice = {
        latticeIndices(n.x, s), latticeIndices(n.y, s), latticeIndices(n.z, s)};
    const uint32_t s2 = 2 * s;
    queue.clear();
    queueCorner.clear();
    rowStart.clear();
    groupEnd.clear();
    auto tryBound = [&](uint32_t i, uint32_t j, uint32_t k, size_t p) {
      std::array<uint32_t, 2> bi, bj, bk;
      const uint32_t ci = bracket(i, n.x, s2, bi), cj = bracket(j, n.y, s2, bj),
                     ck = bracket(k, n.z, s2, bk);
      const glm::dvec3 at(points[p]);
      double best = -1.0, nearest = std::numeric_limits<double>::infinity();
      float bestSign = 0.0f;
      bool agree = true;
      for (uint32_t c = 0; c < ck; ++c) {
        for (uint32_t b = 0; b < cj; ++b) {
          for (uint32_t a = 0; a < ci; ++a) {
            const size_t q = grid.index(bi[a], bj[b], bk[c]);
            const double gap = glm::distance(at, glm::dvec3(points[q]));
            if (gap < nearest) {
              nearest = gap;
              hint[p] = hint[q];
            }
            const double bound = double(magnitude[q]) * (1.0 - 1e-6) - gap;
            if (bound < band64) continue;
            if (bestSign == 0.0f) bestSign = sign[q];
            agree = agree && sign[q] == bestSign;
            best = std::max(best, bound);
          }
        }
      }
      if (best < band64 || !(agree || windingSigns)) return false;
      magnitude[p] = float(best);  // >= band: band is a float and rounding is monotonic
      sign[p] = bestSign;
      state[p] = kBounded;
      if (windingSigns) needSign.push_back(uint32_t(p));
      return true;
    };
    const std::array<uint32_t, 3> size = {uint32_t(lattice[0].size()), uint32_t(lattice[1].size()),
                                          uint32_t(lattice[2].size())};
    for (uint32_t c0 = 0; c0 < size[2]; c0 += 2) {
      for (uint32_t b0 = 0; b0 < size[1]; b0 += 2) {
        rowStart.push_back(uint32_t(groupEnd.size()));
        for (uint32_t a0 = 0; a0 < size[0]; a0 += 2) {
          const size_t before = queue.size();
          for (uint32_t corner = 0; corner < 8; ++corner) {
            const uint32_t a = a0 + (corner & 1), b = b0 + ((corner >> 1) & 1),
                           c = c0 + (corner >> 2);
            if (a >= size[0] || b >= size[1] || c >= size[2]) continue;
            const uint32_t i = lattice[0][a], j = lattice[1][b], k = lattice[2][c];
            const size_t p = grid.index(i, j, k);
            if (state[p] != kUnset) continue;  // on a coarser lattice
            if (s < kCoarsestStride && tryBound(i, j, k, p)) continue;
            queue.push_back(uint32_t(p));
            queueCorner.push_back(uint8_t(corner));
          }
          if (queue.size() > before) groupEnd.push_back(uint32_t(queue.size()));
        }
      }
    }
    rowStart.push_back(uint32_t(groupEnd.size()));
    exactCount += queue.size();

    // Rows run in parallel; within a row the queued nodes go block by block, each seeded with
    // its nearest source's closest triangle, else (the coarsest level) with the closest
    // triangle last found at the same block corner in the row, as build() does.
    const uint32_t rows = uint32_t(rowStart.size() - 1);
    std::atomic<uint32_t> nextRow{0};
    std::atomic<bool> stopped{false};
    const std::function<void()> work = [&] {
      constexpr size_t kGroup = MeshDistance::kGroupSize;
      for (;;) {
        const uint32_t row = nextRow.fetch_add(1, std::memory_order_relaxed);
        if (row >= rows) return;
        if (stopped.load(std::memory_order_relaxed) || limit.reached()) {
          stopped.store(true, std::memory_order_relaxed);
          return;
        }
        std::array<uint32_t, 8> chain;
        chain.fill(kNoTriangle);
        std::array<glm::vec3, kGroup> pts;
        std::array<uint32_t, kGroup> tris;
        std::array<float, kGroup> dist;
        for (uint32_t g = rowStart[row]; g < rowStart[row + 1]; ++g) {
          const uint32_t first = g == 0 ? 0 : groupEnd[g - 1];
          const size_t m = groupEnd[g] - first;
          for (size_t l = 0; l < m; ++l) {
            const uint32_t p = queue[first + l];
            pts[l] = points[p];
            tris[l] = hint[p] != kNoTriangle ? hint[p] : chain[queueCorner[first + l]];
          }
          // One query per node: the queued nodes are sparse (a band around the surface, or a
          // coarse lattice), and there a packet walk costs more than its nodes' own walks
          // (measured: 1.3x slower on the 100k armadillo at a band of 2 spacings).
          for (size_t l = 0; l < m; ++l) {
            dist[l] = target.signedDistanceNear(pts[l], tris[l], &tris[l]);
          }
          for (size_t l = 0; l < m; ++l) {
            const uint32_t p = queue[first + l];
            const uint32_t corner = queueCorner[first + l];
            values[p] = dist[l];
            magnitude[p] = std::abs(dist[l]);
            sign[p] = dist[l] < 0.0f ? -1.0f : 1.0f;
            hint[p] = tris[l];
            state[p] = kExact;
            chain[corner & ~1u] = chain[corner | 1u] = tris[l];
          }
        }
      }
    };
    pool_->run(work);
    if (stopped.load()) return Status::timed_out;
  }

  if (!needSign.empty()) {
    std::atomic<size_t> next{0};
    std::atomic<bool> stopped{false};
    const std::function<void()> work = [&] {
      constexpr size_t kChunk = 16;
      for (;;) {
        const size_t first = next.fetch_add(kChunk, std::memory_order_relaxed);
        if (first >= needSign.size()) return;
        if (stopped.load(std::memory_order_relaxed) || limit.reached()) {
          stopped.store(true, std::memory_order_relaxed);
          return;
        }
        const size_t last = std::min(first + kChunk, needSign.size());
        for (size_t l = first; l < last; ++l) {
          sign[needSign[l]] = target.windingSign(points[needSign[l]]);
        }
      }
    };
    pool_->run(work);
    if (stopped.load()) return Status::timed_out;
  }

  // Max-plus closure over grid edges (see above). The edge length in object space is the box
  // spacing (the pose is rigid), padded for the float node positions; results round down.
  const glm::dvec3 edge = glm::dvec3(box.spacing()) * (1.0 + 1e-5);
  auto relax = [&](size_t p, size_t q, double h) {
    const double bound = double(magnitude[q]) - h;
    if (bound <= double(magnitude[p])) return;
    float f = float(bound);
    if (double(f) > bound) f = std::nextafter(f, 0.0f);
    magnitude[p] = std::max(magnitude[p], f);
  };
  for (uint32_t k = 0; k < n.z; ++k) {
    for (uint32_t j = 0; j < n.y; ++j) {
      for (uint32_t i = 0; i < n.x; ++i) {
        const size_t p = grid.index(i, j, k);
        if (state[p] != kBounded) continue;
        if (i > 0) relax(p, p - 1, edge.x);
        if (j > 0) relax(p, p - n.x, edge.y);
        if (k > 0) relax(p, p - size_t(n.x) * n.y, edge.z);
      }
    }
  }
  for (uint32_t k = n.z; k-- > 0;) {
    for (uint32_t j = n.y; j-- > 0;) {
      for (uint32_t i = n.x; i-- > 0;) {
        const size_t p = grid.index(i, j, k);
        if (state[p] != kBounded) continue;
        if (i + 1 < n.x) relax(p, p + 1, edge.x);
        if (j + 1 < n.y) relax(p, p + n.x, edge.y);
        if (k + 1 < n.z) relax(p, p + size_t(n.x) * n.y, edge.z);
      }
    }
  }
  for (size_t p = 0; p < count; ++p) {
    if (state[p] == kBounded) values[p] = sign[p] * magnitude[p];
  }
  grid.setExactBand(band);
  out = std::move(grid);
  lastExactNodes_ = exactCount;
  return Status::ok;
}

}  // namespace sdfg
