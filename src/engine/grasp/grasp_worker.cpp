// GraspWorker's thread: the queue of set-ups, jobs, outer-hand jobs and depth frames, the order it
// takes them in, and the hand-over of what it finished. The work itself: grasp_worker_targets.cpp
// (set-ups and refits), grasp_worker_solve.cpp (fields, solves, the choice),
// grasp_worker_outer.cpp, grasp_worker_depth.cpp.
#include "grasp/grasp_worker.h"

#include "grasp/scene_exact_source.h"
#include "grasp/target_choice.h"
#include "scene/scene_field.h"

#include <algorithm>
#include <limits>
#include <new>
#include <utility>

#ifdef __linux__
#include <pthread.h>
#include <sched.h>
#endif

namespace sdfg {

GraspWorker::GraspWorker(std::unique_ptr<SdfBackend> backend) : backend_(std::move(backend)) {
  thread_ = std::thread([this] { run(); });
}

GraspWorker::~GraspWorker() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
    for (auto& flag : stopBuild_) flag.store(true, std::memory_order_relaxed);
    for (auto& [id, target] : targets_) target->stop.store(true, std::memory_order_relaxed);
  }
  wake_.notify_all();
  thread_.join();
}

void GraspWorker::request(size_t slot, Job job) {
  {
    std::lock_guard lock(mutex_);
    slots_[slot].queued = std::move(job);
  }
  wake_.notify_all();
}

void GraspWorker::cancel(size_t slot) {
  std::lock_guard lock(mutex_);
  Slot& s = slots_[slot];
  s.queued.reset();
  s.done.reset();
  if (s.running) {
    s.cancelledBelow = s.runningTicket + 1;
    stopBuild_[slot].store(true, std::memory_order_relaxed);
  }
}

std::optional<GraspWorker::Done> GraspWorker::take(size_t slot) {
  // Polled every frame from the app's thread: never wait for the worker (which may have been
  // preempted while holding the lock); the result is taken at the next poll instead.
  std::unique_lock lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock()) return std::nullopt;
  std::optional<Done> out = std::move(slots_[slot].done);
  slots_[slot].done.reset();
  return out;
}

void GraspWorker::hold(bool held) {
  {
    std::lock_guard lock(mutex_);
    held_ = held;
  }
  wake_.notify_all();
}

bool GraspWorker::waitIdle(std::chrono::milliseconds timeout) const {
  std::unique_lock lock(mutex_);
  return idle_.wait_for(lock, timeout, [&] { return !busy_ && !anyQueued(); });
}

uint64_t GraspWorker::setupsDone() const {
  std::lock_guard lock(mutex_);
  return setupsDone_;
}

uint64_t GraspWorker::jobsDone() const {
  std::lock_guard lock(mutex_);
  return jobsDone_;
}

void GraspWorker::run() {
#ifdef __linux__
  // SCHED_BATCH: the kernel does not let this thread preempt the one that woke it, so handing a
  // job over never costs the app's thread the rest of its time slice (measured: a 0.7 ms stall
  // in xrSyncActions on a busy 2-core machine without it). Same nice value, same share of CPU.
  // Best effort: the default policy is kept where it is refused.
  sched_param param{};
  param.sched_priority = 0;
  (void)pthread_setschedparam(pthread_self(), SCHED_BATCH, &param);
#endif
  std::unique_lock lock(mutex_);
  for (;;) {
    wake_.wait(lock, [&] { return stop_ || (!held_ && anyQueued()); });
    if (stop_) break;
    busy_ = true;
    const bool otherWork =
        !setups_.empty() || slots_[0].queued || slots_[1].queued || depth_.queued.has_value();
    if ((outer_[0].queued || outer_[1].queued) && !(lastRanOuter_ && otherWork)) {
      // The outer hand first: one frame's short solve, which the hand shows at once, before a
      // set-up or a build of a grab (milliseconds, up to seconds for a big mesh) that the hand
      // waits frames for anyway. Outer jobs come every frame: after one, a queued set-up or grab
      // runs before the next, so a worker slower than the frames starves neither. An outer job
      // waits at most for the job in progress and the other hand's outer job.
      size_t slot = nextOuter_;
      if (!outer_[slot].queued) slot = 1 - slot;
      nextOuter_ = 1 - slot;
      lastRanOuter_ = true;
      OuterJob job = std::move(*outer_[slot].queued);
      outer_[slot].queued.reset();
      runOuter(lock, slot, std::move(job));
    } else if (!setups_.empty()) {
      // Set-ups before grabs: a target must be ready before any hand can grab it.
      lastRanOuter_ = false;
      const uint64_t id = setups_.front();
      setups_.pop_front();
      auto it = targets_.find(id);
      if (it != targets_.end() && it->second->setupMesh) runSetup(lock, id, it->second);
    } else if (slots_[0].queued || slots_[1].queued) {
      // The slots take turns, so one hand's stream of re-solves cannot starve the other's grab.
      size_t slot = nextSlot_;
      if (!slots_[slot].queued) slot = 1 - slot;
      nextSlot_ = 1 - slot;
      lastRanOuter_ = false;
      Job job = std::move(*slots_[slot].queued);
      slots_[slot].queued.reset();
      runJob(lock, slot, std::move(job));
    } else {
      // The depth scene last: a grab or an outer-hand job is what a hand waits for this frame;
      // a frame of depth left for later is replaced by a newer one.
      lastRanOuter_ = false;
      DepthJob job = std::move(*depth_.queued);
      depth_.queued.reset();
      runDepth(lock, std::move(job));
    }
    busy_ = false;
    if (!anyQueued()) idle_.notify_all();
  }
  busy_ = false;
  idle_.notify_all();
}

bool GraspWorker::anyQueued() const {
  return !setups_.empty() || slots_[0].queued || slots_[1].queued || outer_[0].queued ||
         outer_[1].queued || depth_.queued;
}

}  // namespace sdfg
