// How long a piece of worker-thread work (a grab-box SDF build, a target's set-up or refit) may
// run, and whether its owner wants it stopped: a deadline and an optional stop flag, polled at
// coarse steps.
//
// The layer's worker builds on a thread the app never waits for, but work that never ends still
// leaves the hand open for good and holds up the session's destruction, which joins the worker.
// Work that takes a WorkLimit polls reached() between steps of bounded size (a row of nodes, a
// few thousand triangles), gives up with Status::timed_out at the first step that finds it
// reached, and says what it left behind (a build leaves its output untouched). A
// default-constructed limit never stops anything.
#pragma once

#include <atomic>
#include <chrono>

namespace sdfg {

struct WorkLimit {
  using Clock = std::chrono::steady_clock;

  Clock::time_point deadline = Clock::time_point::max();
  // Owned by the caller; set from another thread to stop the work early (nullptr: none).
  const std::atomic<bool>* stop = nullptr;

  static WorkLimit none() { return {}; }
  static WorkLimit after(Clock::duration budget, const std::atomic<bool>* stop = nullptr) {
    return {Clock::now() + budget, stop};
  }

  bool reached() const {
    if (stop != nullptr && stop->load(std::memory_order_relaxed)) return true;
    return deadline != Clock::time_point::max() && Clock::now() >= deadline;
  }
};

// A WorkLimit polled from inside a loop: reached() looks at the limit only every `every` calls,
// so a loop whose steps take nanoseconds pays one clock read per batch, and the time between two
// looks stays bounded by `every` steps. Once reached, it stays reached.
class LimitPoll {
 public:
  explicit LimitPoll(const WorkLimit& limit, uint32_t every = 4096)
      : limit_(limit), every_(every) {}
  bool reached() {
    if (stopped_) return true;
    if (++count_ < every_) return false;
    count_ = 0;
    stopped_ = limit_.reached();
    return stopped_;
  }
  bool stopped() const { return stopped_; }

 private:
  const WorkLimit& limit_;
  uint32_t every_;
  uint32_t count_ = 0;
  bool stopped_ = false;
};

}  // namespace sdfg
