#include "sdf/deferred_mailbox.h"

#include <utility>

namespace sdfg {

class DeferredMailbox::OwnerSide final : public DeferredSdfBackend {
 public:
  explicit OwnerSide(std::shared_ptr<DeferredMailbox> mailbox) : mailbox_(std::move(mailbox)) {}
  std::string_view name() const override { return "mailbox"; }
  Status request(size_t slot, uint64_t id, uint64_t version, const TriangleMesh* mesh,
                 const Pose& objectFromHand, const GridBox& box) override {
    return mailbox_->request(slot, id, version, mesh, objectFromHand, box);
  }
  bool hasDeviceMesh(uint64_t id) const override { return mailbox_->hasDeviceMesh(id); }
  bool needsSubmit(bool) const override { return mailbox_->needsSubmit(); }
  Status submit(bool) override { return failed() ? Status::device_lost : Status::ok; }
  BuildPoll poll(size_t slot, SdfGrid& out) override { return mailbox_->poll(slot, out); }
  void cancel(size_t slot) override { mailbox_->cancel(slot); }
  bool failed() const override { return mailbox_->failed(); }
  bool ready() override { return mailbox_->ready(); }

 private:
  std::shared_ptr<DeferredMailbox> mailbox_;
};

DeferredMailbox::DeferredMailbox(std::unique_ptr<DeferredSdfBackend> device)
    : device_(std::move(device)) {}

DeferredMailbox::~DeferredMailbox() {
  shutdown();
}

std::unique_ptr<DeferredSdfBackend> DeferredMailbox::ownerSide(
    std::shared_ptr<DeferredMailbox> mailbox) {
  return std::make_unique<OwnerSide>(std::move(mailbox));
}

Status DeferredMailbox::request(size_t slot, uint64_t id, uint64_t version,
                                const TriangleMesh* mesh, const Pose& objectFromHand,
                                const GridBox& box) {
  if (slot >= kSlots || box.validate()) return Status::invalid_argument;
  std::lock_guard lock(mutex_);
  if (failed_) return Status::device_lost;
  Slot& s = slots_[slot];
  // A build still on the device (a cancelled one) or waiting: ask again at the next update.
  if (s.queued || s.onDevice) return Status::unsupported;
  Request r;
  r.id = id;
  r.version = version;
  r.objectFromHand = objectFromHand;
  r.box = box;
  if (mesh != nullptr) {
    // The pump reads the mesh on another thread while the owner may change its own copy: the
    // request carries one of its own, made again only for new vertices or another target.
    MeshCopy& copy = meshes_[slot];
    if (copy.mesh == nullptr || copy.id != id || copy.version != version) {
      copy.mesh = std::make_shared<const TriangleMesh>(*mesh);
      copy.id = id;
      copy.version = version;
    }
    r.mesh = copy.mesh;
  }
  r.generation = ++s.generation;
  s.result.reset();
  s.queued = std::move(r);
  return Status::ok;
}

BuildPoll DeferredMailbox::poll(size_t slot, SdfGrid& out) {
  if (slot >= kSlots) return BuildPoll::idle;
  std::lock_guard lock(mutex_);
  if (failed_) return BuildPoll::failed;
  Slot& s = slots_[slot];
  if (s.result) {
    out = std::move(*s.result);
    s.result.reset();
    return BuildPoll::ready;
  }
  if (s.queued || (s.onDevice && s.deviceGeneration == s.generation)) return BuildPoll::pending;
  return BuildPoll::idle;  // refused or lost by the device (or never asked): the owner redoes it
}

void DeferredMailbox::cancel(size_t slot) {
  if (slot >= kSlots) return;
  std::lock_guard lock(mutex_);
  Slot& s = slots_[slot];
  ++s.generation;
  s.queued.reset();
  s.result.reset();
  if (s.onDevice) s.cancel = true;
}

bool DeferredMailbox::hasDeviceMesh(uint64_t id) const {
  std::lock_guard lock(mutex_);
  return deviceMeshes_.count(id) != 0;
}

bool DeferredMailbox::needsSubmit() const {
  std::lock_guard lock(mutex_);
  if (failed_) return false;
  if (deviceNeedsSubmit_) return true;
  for (const Slot& s : slots_)
    if (s.queued) return true;
  return false;
}

bool DeferredMailbox::failed() const {
  std::lock_guard lock(mutex_);
  return failed_;
}

bool DeferredMailbox::ready() const {
  std::lock_guard lock(mutex_);
  return ready_ && !failed_;
}

void DeferredMailbox::noteDeviceMesh(uint64_t id, bool present) {
  std::lock_guard lock(mutex_);
  if (present)
    deviceMeshes_.insert(id);
  else
    deviceMeshes_.erase(id);
}

void DeferredMailbox::post(std::function<void(DeferredSdfBackend&)> call) {
  std::lock_guard lock(mutex_);
  posted_.push_back(std::move(call));
}

bool DeferredMailbox::claim(std::unique_lock<std::mutex>& lock) {
  released_.wait(lock, [&] { return !claimed_; });
  if (device_ == nullptr) return false;
  claimed_ = true;
  return true;
}

void DeferredMailbox::release(std::unique_lock<std::mutex>& lock) {
  if (!lock.owns_lock()) lock.lock();
  claimed_ = false;
  lock.unlock();
  released_.notify_all();
}

void DeferredMailbox::exclusive(const std::function<void(DeferredSdfBackend&)>& call) {
  std::unique_lock lock(mutex_);
  if (!claim(lock)) return;
  std::vector<std::function<void(DeferredSdfBackend&)>> posted = std::move(posted_);
  posted_.clear();
  lock.unlock();
  for (auto& f : posted) f(*device_);
  call(*device_);
  const bool failed = device_->failed();
  lock.lock();
  failed_ = failed_ || failed;
  release(lock);
}

void DeferredMailbox::shutdown() {
  std::unique_ptr<DeferredSdfBackend> device;
  {
    std::unique_lock lock(mutex_);
    released_.wait(lock, [&] { return !claimed_; });
    device = std::move(device_);
    posted_.clear();
    failed_ = true;
  }
  device.reset();  // waits for its work in flight, with no lock held
}

bool DeferredMailbox::pump(bool sharedQueueFree) {
  std::array<Seen, kSlots> seen;  // a refused request is simply not started: poll() says idle
  std::array<bool, kSlots> cancels{};
  std::array<bool, kSlots> inFlight{};
  std::vector<std::function<void(DeferredSdfBackend&)>> posted;
  std::unique_lock lock(mutex_);
  // Never wait for another thread's device calls: it does this work, or the next pump will.
  if (claimed_ || device_ == nullptr) return false;
  claimed_ = true;
  posted = std::move(posted_);
  posted_.clear();
  for (size_t i = 0; i < kSlots; ++i) {
    Slot& s = slots_[i];
    cancels[i] = std::exchange(s.cancel, false);
    seen[i].request = std::move(s.queued);
    s.queued.reset();
    inFlight[i] = s.onDevice;
  }
  lock.unlock();

  DeferredSdfBackend& device = *device_;
  for (auto& f : posted) f(device);
  for (size_t i = 0; i < kSlots; ++i)
    if (cancels[i]) device.cancel(i);
  const bool ready = device.ready();
  for (size_t i = 0; i < kSlots; ++i) {
    Seen& v = seen[i];
    if (!v.request) continue;
    const Request& r = *v.request;
    const Status st = device.request(i, r.id, r.version, r.mesh.get(), r.objectFromHand, r.box);
    v.started = st == Status::ok;
    v.busy = st == Status::unsupported;
  }
  if (device.needsSubmit(sharedQueueFree)) (void)device.submit(sharedQueueFree);
  for (size_t i = 0; i < kSlots; ++i) {
    Seen& v = seen[i];
    if (!inFlight[i] && !v.started) continue;
    v.polled = true;
    v.poll = device.poll(i, v.grid);
  }
  const bool failed = device.failed();
  const bool needsSubmit = device.needsSubmit(true);

  lock.lock();
  for (size_t i = 0; i < kSlots; ++i) {
    Slot& s = slots_[i];
    Seen& v = seen[i];
    if (v.started) {
      s.onDevice = true;
      s.deviceGeneration = v.request->generation;
    }
    if (v.polled && v.poll != BuildPoll::pending) {
      const bool current = s.onDevice && s.deviceGeneration == s.generation;
      s.onDevice = false;
      if (current && v.poll == BuildPoll::ready) s.result = std::move(v.grid);
    }
    if (v.busy && !s.queued && v.request->generation == s.generation)
      s.queued = std::move(v.request);
  }
  failed_ = failed_ || failed;
  ready_ = ready;
  deviceNeedsSubmit_ = needsSubmit;
  release(lock);
  return true;
}

}  // namespace sdfg
