#include "sdf_cpu.h"

#include <algorithm>
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
  const uint32_t rows = n.y * n.z;
  std::span<float> values = grid.values();
  std::atomic<uint32_t> nextRow{0};

  // Work is handed out by rows along x. Each row starts unseeded and seeds every later node
  // with the previous node's closest triangle, whose distance at the new node is within one
  // spacing of the answer and prunes most of the hierarchy. Rows never depend on one another,
  // so the grid is the same whatever the thread count.
  const std::function<void()> work = [&] {
    for (;;) {
      const uint32_t row = nextRow.fetch_add(1, std::memory_order_relaxed);
      if (row >= rows) return;
      const uint32_t j = row % n.y, k = row / n.y;
      uint32_t hint = std::numeric_limits<uint32_t>::max();
      float* dst = &values[grid.index(0, j, k)];
      for (uint32_t i = 0; i < n.x; ++i) {
        const glm::vec3 p = objectFromBox.transformPoint(box.nodeLocal(i, j, k));
        dst[i] = target.signedDistanceNear(p, hint, &hint);
      }
    }
  };
  pool_->run(work);
  out = std::move(grid);
  return Status::ok;
}

}  // namespace sdfg
