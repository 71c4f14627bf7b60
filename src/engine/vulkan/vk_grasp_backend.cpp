#include "vulkan/vk_grasp_backend.h"

#include <algorithm>
#include <iostream>
#include <utility>

namespace sdfg {

namespace {
constexpr uint64_t kDestroyWaitNs = 2'000'000'000ull;

// The gatherer of buffer targets' meshes. Its failure costs the readbacks only (buffer targets
// then take part through their grab-box field alone, as before readbacks): said once, not fatal.
std::unique_ptr<VkMeshReadback> makeReadback(const VulkanDevice& appQueue,
                                             const std::function<void(const std::string&)>& log) {
  auto made = VkMeshReadback::create(appQueue, log);
  if (made) return std::move(made.value());
  const std::string line = "sdfg: buffer targets' meshes cannot be read back (" +
                           made.error().message +
                           "): they take part in grasps through their grab-box field only";
  if (log)
    log(line);
  else
    std::cerr << line << std::endl;
  return nullptr;
}
}  // namespace

Result<std::unique_ptr<VkSdfBuilder>> VkGraspBackend::makeBuilder(const VulkanDevice& device) {
  VkSdfOptions options;
  // Every builder reports through the backend, which writes the session's one failure line.
  options.log = [this](const std::string& line) { logOnce(line); };
  return VkSdfBuilder::create(device, options);
}

Result<std::unique_ptr<VkGraspBackend>> VkGraspBackend::create(
    const VulkanDevice& appQueue, const VulkanDevice* ownQueue,
    const VkGraspBackendOptions& options) {
  std::unique_ptr<VkGraspBackend> b(new VkGraspBackend());
  b->options_ = options;
  b->appQueue_ = appQueue;
  b->ownQueue_ = ownQueue != nullptr;
  if (options.prepareInBackground) {
    b->prep_ = Prep::making;
    // With a queue of our own, builders for app-buffer targets (app's queue) are made now too,
    // so that no setDeviceMesh creates pipelines on the app's thread.
    b->preparer_ = std::thread(&VkGraspBackend::prepare, b.get(),
                               ownQueue != nullptr ? *ownQueue : appQueue, ownQueue != nullptr);
    return b;
  }
  for (Slot& slot : b->slots_) {
    auto builder = b->makeBuilder(ownQueue != nullptr ? *ownQueue : appQueue);
    if (!builder) return builder.error();
    slot.main.builder = std::move(builder.value());
    slot.main.shared = ownQueue == nullptr;
  }
  b->readback_ = makeReadback(appQueue, options.log);
  return b;
}

void VkGraspBackend::prepare(VulkanDevice mainQueue, bool appBuilders) {
  Prepared made;
  for (size_t i = 0; i < kSlots && !made.error && !cancelPrep_.load(); ++i) {
    auto main = makeBuilder(mainQueue);
    if (!main) {
      made.error = main.error();
      break;
    }
    made.main[i] = std::move(main.value());
    if (!appBuilders) continue;
    auto app = makeBuilder(appQueue_);
    if (!app) {
      made.error = app.error();
      break;
    }
    made.app[i] = std::move(app.value());
  }
  if (!made.error && !cancelPrep_.load()) made.readback = makeReadback(appQueue_, options_.log);
  {
    std::lock_guard lock(prepMutex_);
    made_ = std::move(made);
  }
  prepared_.store(true, std::memory_order_release);
}

void VkGraspBackend::adoptPrepared() {
  if (preparer_.joinable()) preparer_.join();  // it has finished: prepared_ was set
  Prepared made;
  {
    std::lock_guard lock(prepMutex_);
    made = std::move(made_);
  }
  if (made.error) {
    logOnce("sdfg: Vulkan SDF backend unavailable, falling back to the CPU: " +
            made.error->message);
    markFailed(made.error->code);
    return;
  }
  for (size_t i = 0; i < kSlots; ++i) {
    slots_[i].main.builder = std::move(made.main[i]);
    slots_[i].main.shared = !ownQueue_;
    slots_[i].main.warmups = 0;
    if (made.app[i]) {
      slots_[i].app.builder = std::move(made.app[i]);
      slots_[i].app.shared = true;
      slots_[i].app.warmups = 0;
    }
  }
  readback_ = std::move(made.readback);
  prep_ = Prep::warming;
}

Status VkGraspBackend::submitWarmups(bool sharedQueueFree) {
  // Small meshes in the middle of the default grab box (identity placement), so every pass has
  // triangles and nodes to work on.
  const GridBox box = [] {
    GridBox b = GridBox::referenceDefault();
    b.resolution = glm::uvec3(4u);
    return b;
  }();
  const glm::vec3 c = box.handFromBox.position;
  const float e = 0.02f;
  TriangleMesh meshes[kWarmups];
  meshes[0].positions = {c, c + glm::vec3(e, 0, 0), c + glm::vec3(0, e, 0)};
  meshes[0].indices = {0, 1, 2};
  meshes[1].positions = {c, c + glm::vec3(e, 0, 0), c + glm::vec3(0, e, 0), c + glm::vec3(0, 0, e)};
  meshes[1].indices = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
  for (Slot& slot : slots_) {
    for (Builder* b : {&slot.main, &slot.app}) {
      if (!b->builder || b->warmups >= kWarmups || (b->shared && !sharedQueueFree)) continue;
      const SdfPoll p = b->builder->poll();
      if (p == SdfPoll::pending) continue;  // the previous warm-up still runs
      if (p == SdfPoll::failed) return markFailed(Status::device_lost);
      Status st = b->builder->setMesh(meshes[b->warmups]);
      if (st == Status::ok) st = b->builder->submitBuild(box, Pose{}, {}, false);
      if (st != Status::ok) return markFailed(st);
      ++b->warmups;
    }
  }
  return Status::ok;
}

bool VkGraspBackend::ready() {
  if (failed_ || fault_ == VkGraspFault::neverReady) return false;
  if (prep_ == Prep::done) return true;
  if (prep_ == Prep::making) {
    if (!prepared_.load(std::memory_order_acquire)) return false;
    adoptPrepared();
    if (failed_) return false;
  }
  for (Slot& slot : slots_) {
    for (Builder* b : {&slot.main, &slot.app}) {
      if (!b->builder) continue;
      if (b->warmups < kWarmups) return false;
      const SdfPoll p = b->builder->poll();
      if (p == SdfPoll::pending) return false;
      if (p == SdfPoll::failed) {
        markFailed(Status::device_lost);
        return false;
      }
    }
  }
  prep_ = Prep::done;
  return true;
}

VkGraspBackend::~VkGraspBackend() {
  // The preparation thread stops after the builder it is making; builders it made and nobody
  // adopted are destroyed with made_.
  cancelPrep_.store(true);
  if (preparer_.joinable()) preparer_.join();
  readback_.reset();  // waits for its gather in flight
  // Each builder's destructor waits for its submission in flight before freeing anything.
  for (Slot& slot : slots_) {
    slot.main.builder.reset();
    slot.app.builder.reset();
  }
}

void VkGraspBackend::logOnce(const std::string& line) {
  std::lock_guard lock(logMutex_);
  if (logged_) return;
  logged_ = true;
  if (options_.log) {
    options_.log(line);
  } else {
    std::cerr << line << std::endl;
  }
}

Status VkGraspBackend::markFailed(Status status) {
  if (!failed_) {
    failed_ = true;
    // A builder has usually logged the cause already; this covers failures found here.
    logOnce(std::string("sdfg: Vulkan SDF backend disabled, falling back to the CPU (") +
            toString(status) + ")");
  }
  for (Slot& slot : slots_) slot.recorded = false;
  return status == Status::ok ? Status::device_lost : status;
}

Status VkGraspBackend::request(size_t slot, uint64_t id, uint64_t version, const TriangleMesh* mesh,
                               const Pose& objectFromHand, const GridBox& box) {
  if (failed_) return Status::device_lost;
  if (prep_ != Prep::done) return Status::unsupported;  // see ready()
  if (slot >= kSlots || box.validate()) return Status::invalid_argument;
  Slot& s = slots_[slot];
  if (s.recorded) return Status::unsupported;
  if (s.inFlight) {
    // A cancelled build may have finished: collect it before reusing the builder.
    const SdfPoll p = s.active->builder->poll();
    if (p == SdfPoll::pending) return Status::unsupported;
    s.inFlight = false;
    if (p == SdfPoll::failed) return markFailed(Status::device_lost);
  }
  if (mesh == nullptr) {
    auto it = deviceMeshes_.find(id);
    if (it == deviceMeshes_.end()) return Status::invalid_argument;
    Builder& b = s.app.builder ? s.app : s.main;
    if (!b.meshOnDevice || b.meshId != id || b.meshVersion != it->second.version) {
      const Status st = b.builder->setMesh(it->second.buffers);
      if (st == Status::invalid_argument) return st;
      if (st != Status::ok) return markFailed(st);
      b.meshId = id;
      b.meshVersion = it->second.version;
      b.meshOnDevice = true;
    }
    s.active = &b;
  } else {
    Builder& b = s.main;
    if (b.meshOnDevice || b.meshId != id || b.meshVersion != version) {
      // Copied now into the builder's staging; uploaded by the build that follows.
      const Status st = b.builder->setMesh(*mesh);
      if (st == Status::invalid_argument) return st;
      if (st != Status::ok) return markFailed(st);
      b.meshId = id;
      b.meshVersion = version;
      b.meshOnDevice = false;
    }
    s.active = &b;
  }
  s.box = box;
  s.objectFromHand = objectFromHand;
  s.recorded = true;
  s.discard = false;
  return Status::ok;
}

bool VkGraspBackend::needsSubmit(bool sharedQueueFree) const {
  if (failed_) return false;
  if (prep_ == Prep::making) return prepared_.load(std::memory_order_acquire);
  if (!readbackWanted_.empty() && readback_ != nullptr && sharedQueueFree) return true;
  if (prep_ == Prep::warming) {
    for (const Slot& s : slots_) {
      for (const Builder* b : {&s.main, &s.app}) {
        if (b->builder && b->warmups < kWarmups && (sharedQueueFree || !b->shared)) return true;
      }
    }
    return false;
  }
  for (const Slot& s : slots_) {
    if (s.recorded && (sharedQueueFree || !s.active->shared)) return true;
  }
  return false;
}

Status VkGraspBackend::submit(bool sharedQueueFree) {
  if (failed_) return Status::device_lost;
  if (prep_ == Prep::making) {
    if (!prepared_.load(std::memory_order_acquire)) return Status::ok;
    adoptPrepared();
    if (failed_) return Status::device_lost;
  }
  pumpReadbacks(sharedQueueFree);
  if (prep_ == Prep::warming) return submitWarmups(sharedQueueFree);
  for (Slot& s : slots_) {
    if (!s.recorded || (s.active->shared && !sharedQueueFree)) continue;
    VkSdfBuilder& builder = *s.active->builder;
    if (fault_ == VkGraspFault::lostAtSubmit) builder.simulateDeviceLostForTesting();
    // No sample points: the solver reads the whole grid, which comes back with the fence.
    const Status st = builder.submitBuild(s.box, s.objectFromHand, {}, true);
    if (st == Status::unsupported) continue;  // still busy; next time
    s.recorded = false;
    if (st != Status::ok) return markFailed(st);
    s.inFlight = true;
    if (fault_ == VkGraspFault::lostAtPoll) builder.simulateDeviceLostForTesting();
  }
  return Status::ok;
}

BuildPoll VkGraspBackend::poll(size_t slot, SdfGrid& out) {
  if (failed_) return BuildPoll::failed;
  if (slot >= kSlots) return BuildPoll::idle;
  Slot& s = slots_[slot];
  if (s.recorded) return BuildPoll::pending;
  if (!s.inFlight) return BuildPoll::idle;
  const SdfPoll p = s.active->builder->poll();
  if (p == SdfPoll::pending) return BuildPoll::pending;
  s.inFlight = false;
  if (p == SdfPoll::failed) {
    markFailed(Status::device_lost);
    return BuildPoll::failed;
  }
  if (s.discard) {
    s.discard = false;
    return BuildPoll::idle;
  }
  const SdfGrid* grid = s.active->builder->grid();
  if (grid == nullptr) {
    markFailed(Status::internal);
    return BuildPoll::failed;
  }
  out = *grid;
  return BuildPoll::ready;
}

void VkGraspBackend::cancel(size_t slot) {
  if (slot >= kSlots) return;
  Slot& s = slots_[slot];
  s.recorded = false;
  if (s.inFlight) s.discard = true;
}

Status VkGraspBackend::setDeviceMesh(uint64_t id, const VkMeshBuffers& buffers) {
  if (failed_) return Status::device_lost;
  // The builder's checks, made here too so that a bad description fails at registration.
  if (!validMeshBuffers(buffers)) return Status::invalid_argument;
  if (ownQueue_ && !options_.prepareInBackground) {
    // App buffers are read on the app's queue (see the header): builders there, made once (by
    // the preparation thread when there is one).
    for (Slot& slot : slots_) {
      if (slot.app.builder) continue;
      auto builder = makeBuilder(appQueue_);
      if (!builder) return builder.error().code;
      slot.app.builder = std::move(builder.value());
      slot.app.shared = true;
    }
  }
  auto [it, inserted] = deviceMeshes_.try_emplace(id);
  if (!inserted) {
    ++it->second.version;
    const VkMeshBuffers& was = it->second.buffers;
    // Other index buffers (a new description, not new vertices): a readback brings them again.
    if (was.indices != buffers.indices || was.indexOffset != buffers.indexOffset ||
        was.indexType != buffers.indexType || was.indexCount != buffers.indexCount)
      it->second.indicesRead = false;
  }
  it->second.buffers = buffers;
  return Status::ok;
}

Status VkGraspBackend::requestReadback(uint64_t id, uint64_t generation) {
  if (failed_) return Status::device_lost;
  if (deviceMeshes_.count(id) == 0) return Status::invalid_argument;
  // Null once prepared: it could not be made (logged). While the preparation runs, requests are
  // kept until it has made the gatherer.
  if (prep_ != Prep::making && (readback_ == nullptr || readback_->failed()))
    return Status::unsupported;
  auto [it, inserted] = readbackWanted_.try_emplace(id, generation);
  if (inserted)
    readbackOrder_.push_back(id);
  else
    it->second = std::max(it->second, generation);
  return Status::ok;
}

void VkGraspBackend::collectReadback() {
  if (readback_ == nullptr || !readback_->busy()) return;
  std::optional<MeshReadback> done = readback_->poll();
  if (!done) return;
  auto it = deviceMeshes_.find(done->id);
  if (it == deviceMeshes_.end()) return;  // removed meanwhile
  if (!done->indices.empty()) it->second.indicesRead = true;
  readbacksDone_.push_back(std::move(*done));
}

void VkGraspBackend::pumpReadbacks(bool sharedQueueFree) {
  if (readback_ == nullptr) return;
  collectReadback();
  // The app's queue only: its writes to the buffers are ordered before the gather by submission
  // order there.
  while (sharedQueueFree && !readback_->busy() && !readback_->failed() && !readbackOrder_.empty()) {
    const uint64_t id = readbackOrder_.front();
    readbackOrder_.pop_front();
    auto wanted = readbackWanted_.find(id);
    auto mesh = deviceMeshes_.find(id);
    if (wanted == readbackWanted_.end()) continue;
    const uint64_t generation = wanted->second;
    readbackWanted_.erase(wanted);
    if (mesh == deviceMeshes_.end()) continue;
    // A description the gather refuses is refused at registration already; a device failure
    // leaves readback_ failed and is said by its one log line.
    (void)readback_->submit(id, generation, mesh->second.buffers, !mesh->second.indicesRead);
  }
}

std::vector<MeshReadback> VkGraspBackend::takeReadbacks() {
  collectReadback();
  if (prep_ != Prep::making && (readback_ == nullptr || readback_->failed())) {
    // No gatherer now (it could not be made, or the device failed it): the requests kept for it
    // are refused, as empty readbacks, so that no owner waits for them.
    for (const uint64_t id : readbackOrder_) {
      auto wanted = readbackWanted_.find(id);
      if (wanted != readbackWanted_.end())
        readbacksDone_.push_back(MeshReadback{id, wanted->second, {}, {}});
      readbackWanted_.erase(id);
    }
    readbackOrder_.clear();
  }
  return std::exchange(readbacksDone_, {});
}

bool VkGraspBackend::removeDeviceMesh(uint64_t id) {
  if (fault_ == VkGraspFault::stuckReadsOnce && deviceMeshes_.count(id) != 0) {
    fault_ = VkGraspFault::none;
    return false;
  }
  // The reads in flight end first: the app may destroy its buffers once this returns true.
  for (Slot& s : slots_) {
    Builder* b = s.active;
    if (!s.inFlight || b == nullptr || !b->builder || !b->meshOnDevice || b->meshId != id) continue;
    const SdfPoll p = b->builder->wait(kDestroyWaitNs);
    if (p == SdfPoll::pending) return false;
    s.inFlight = false;  // its result is dropped: the owner asks again
    if (p == SdfPoll::failed) markFailed(Status::device_lost);
  }
  for (Slot& s : slots_) {
    for (Builder* b : {&s.main, &s.app}) {
      if (!b->builder || !b->meshOnDevice || b->meshId != id) continue;
      if (s.active == b) s.recorded = false;  // recorded, not submitted: it never reads them
      b->meshId = 0;
      b->meshOnDevice = false;
    }
  }
  // A gather of its buffers in flight ends first too; its result is dropped.
  if (readback_ != nullptr && readback_->busyWith() == id) {
    (void)readback_->wait(kDestroyWaitNs);
    if (readback_->busy() && !readback_->failed()) return false;
  }
  std::erase_if(readbacksDone_, [&](const MeshReadback& r) { return r.id == id; });
  readbackWanted_.erase(id);
  deviceMeshes_.erase(id);
  return true;
}

}  // namespace sdfg
