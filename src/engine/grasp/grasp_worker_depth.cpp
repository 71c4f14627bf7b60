// GraspWorker's depth scene: each frame of the app's depth fused into one volume per hand, which
// the session's grabs and outer hand read as a target like any other (its volume, through
// sceneMember()).
#include "grasp/grasp_worker.h"

#include <utility>

namespace sdfg {

Status GraspWorker::enableDepth(const std::array<uint64_t, kSlots>& ids,
                                const DepthFusionOptions& options) {
  std::array<std::optional<DepthFusion>, kSlots> made;
  for (size_t slot = 0; slot < kSlots; ++slot) {
    Result<DepthFusion> f = DepthFusion::create(options);
    if (!f.ok()) return f.error().code;
    made[slot].emplace(std::move(*f));
  }
  std::lock_guard lock(mutex_);
  if (depth_.enabled) return Status::invalid_argument;
  for (uint64_t id : ids)
    if (targets_.count(id) != 0) return Status::invalid_argument;
  for (size_t slot = 0; slot < kSlots; ++slot) {
    auto t = std::make_shared<Target>();
    t->setup = TargetSetup::ready;
    targets_[ids[slot]] = std::move(t);
  }
  depth_.enabled = true;
  depth_.ids = ids;
  depth_.fusion = std::move(made);
  return Status::ok;
}

void GraspWorker::requestDepth(DepthJob job) {
  {
    std::lock_guard lock(mutex_);
    if (!depth_.enabled) return;
    depth_.queued = std::move(job);
  }
  wake_.notify_all();
}

std::optional<std::array<GraspWorker::DepthDone, GraspWorker::kSlots>> GraspWorker::takeDepth() {
  std::unique_lock lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock() || !depth_.fresh) return std::nullopt;
  depth_.fresh = false;
  return depth_.done;
}

void GraspWorker::runDepth(std::unique_lock<std::mutex>& lock, DepthJob job) {
  // The fusions and their volumes are this thread's: a job that reads a volume runs before or
  // after this one, never during it.
  lock.unlock();
  std::array<DepthDone, kSlots> done{};
  for (size_t slot = 0; slot < kSlots; ++slot) {
    if (!job.centres[slot]) continue;
    DepthFusion& f = *depth_.fusion[slot];
    f.recentre(*job.centres[slot]);
    for (size_t v = 0; v < job.views.size() && v < job.depth.size(); ++v) {
      if (f.integrate(job.views[v], job.depth[v], job.hands, job.time) != Status::ok)
        ++done[slot].refusedViews;
    }
    f.finishFrame(job.time);
    done[slot].valid = true;
    done[slot].observed = f.observedVoxels();
    done[slot].bounds = f.volume().bounds();
  }
  job = DepthJob{};  // the frame's pixels go before the lock
  lock.lock();
  for (size_t slot = 0; slot < kSlots; ++slot) {
    if (!done[slot].valid) continue;
    auto it = targets_.find(depth_.ids[slot]);
    if (it == targets_.end()) continue;
    Target& t = *it->second;
    t.volume = &depth_.fusion[slot]->volume();
    t.bounds = done[slot].bounds;
    done[slot].version = ++t.appliedVersion;
    depth_.done[slot] = done[slot];
    depth_.fresh = true;
  }
}

}  // namespace sdfg
