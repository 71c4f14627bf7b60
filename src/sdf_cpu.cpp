#include "sdf_cpu.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <condition_variable>
#include <functional>
#include <limits>
#include <mutex>
#include <thread>
#include <vector>

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
                            const GridBox& box, SdfGrid& out) {
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

  const std::function<void()> work = [&] {
    constexpr size_t kGroup = MeshDistance::kGroupSize;
    static_assert(kGroup == 8, "a group is one 2x2x2 block");
    for (;;) {
      const uint32_t row = nextRow.fetch_add(1, std::memory_order_relaxed);
      if (row >= rows) return;
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
  out = std::move(grid);
  return Status::ok;
}

}  // namespace sdfg
