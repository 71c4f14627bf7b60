// How long a piece of worker-thread work (a grab-box SDF build) may run, and whether its owner
// wants it stopped: a deadline and an optional stop flag, polled at coarse steps.
//
// The layer's worker builds on a thread the app never waits for, but a build that never ends
// still leaves the hand open for good and holds up the session's destruction, which joins the
// worker. Work that takes a WorkLimit polls reached() between steps of bounded size (a row of
// nodes), gives up with Status::timed_out at the first step that finds it reached, and leaves
// its output untouched. A default-constructed limit never stops anything.
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

}  // namespace sdfg
