#include "sdf/deferred_mailbox.h"

#include <algorithm>
#include <exception>
#include <utility>

namespace sdfg {

class DeferredMailbox::OwnerSide final : public DeferredSdfBackend {
 public:
  explicit OwnerSide(std::shared_ptr<DeferredMailbox> mailbox) : mailbox_(std::move(mailbox)) {}
  std::string_view name() const override { return "mailbox"; }
  // Lent arrays must outlive the call, so they are copied (here, under no lock of the mailbox's);
  // an owner that holds a lock shares its arrays through requestShared instead.
  Status request(size_t slot, uint64_t id, uint64_t version, const TriangleMesh* mesh,
                 const Pose& objectFromHand, const GridBox& box) override {
    SharedMesh shared;
    if (mesh != nullptr) {
      shared.positions = std::make_shared<const std::vector<glm::vec3>>(mesh->positions);
      shared.indices = std::make_shared<const std::vector<uint32_t>>(mesh->indices);
    }
    return mailbox_->request(slot, id, version, std::move(shared), objectFromHand, box);
  }
  Status requestShared(size_t slot, uint64_t id, uint64_t version, const SharedMesh& mesh,
                       const Pose& objectFromHand, const GridBox& box) override {
    if (mesh.positions == nullptr || mesh.indices == nullptr) return Status::invalid_argument;
    return mailbox_->request(slot, id, version, mesh, objectFromHand, box);
  }
  bool hasDeviceMesh(uint64_t id) const override { return mailbox_->hasDeviceMesh(id); }
  bool needsSubmit(bool) const override { return mailbox_->needsSubmit(); }
  Status submit(bool) override { return failed() ? Status::device_lost : Status::ok; }
  BuildPoll poll(size_t slot, SdfGrid& out) override { return mailbox_->poll(slot, out); }
  void cancel(size_t slot) override { mailbox_->cancel(slot); }
  bool failed() const override { return mailbox_->failed(); }
  bool ready() override { return mailbox_->ready(); }
  Status requestReadback(uint64_t id, uint64_t generation) override {
    return mailbox_->requestReadback(id, generation);
  }
  std::vector<MeshReadback> takeReadbacks() override { return mailbox_->takeReadbacks(); }

 private:
  std::shared_ptr<DeferredMailbox> mailbox_;
};

// The device for one thread, from construction (the taker holds mutex_ and found it free) to
// destruction, which gives it back and wakes the threads waiting for it, also while an exception
// from a device call unwinds. It takes mutex_ itself: a Claim is declared before the
// unique_lock of its scope, so that unwinding unlocks first.
class DeferredMailbox::Claim {
 public:
  explicit Claim(DeferredMailbox& mailbox) : mailbox_(mailbox) { mailbox_.claimed_ = true; }
  ~Claim() {
    {
      std::lock_guard lock(mailbox_.mutex_);
      mailbox_.claimed_ = false;
    }
    mailbox_.released_.notify_all();
  }
  Claim(const Claim&) = delete;
  Claim& operator=(const Claim&) = delete;

 private:
  DeferredMailbox& mailbox_;
};

DeferredMailbox::DeferredMailbox(std::unique_ptr<DeferredSdfBackend> device,
                                 std::chrono::milliseconds claimWait)
    : claimWait_(claimWait), device_(std::move(device)) {}

DeferredMailbox::~DeferredMailbox() {
  (void)shutdown();
}

std::unique_ptr<DeferredSdfBackend> DeferredMailbox::ownerSide(
    std::shared_ptr<DeferredMailbox> mailbox) {
  return std::make_unique<OwnerSide>(std::move(mailbox));
}

Status DeferredMailbox::request(size_t slot, uint64_t id, uint64_t version, SharedMesh mesh,
                                const Pose& objectFromHand, const GridBox& box) {
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
  // Shared, never copied here: the owner calls this under its session lock.
  r.mesh = std::move(mesh);
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
  if (deviceNeedsSubmit_ || !readbackRequests_.empty()) return true;
  for (const Slot& s : slots_)
    if (s.queued) return true;
  return false;
}

Status DeferredMailbox::requestReadback(uint64_t id, uint64_t generation) {
  std::lock_guard lock(mutex_);
  if (failed_) return Status::device_lost;
  if (deviceMeshes_.count(id) == 0) return Status::invalid_argument;
  if (readbackUnsupported_) return Status::unsupported;
  uint64_t& wanted = readbackRequests_[id];
  wanted = std::max(wanted, generation);
  return Status::ok;
}

std::vector<MeshReadback> DeferredMailbox::takeReadbacks() {
  std::lock_guard lock(mutex_);
  return std::exchange(readbacks_, {});
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

DeferredMailbox::Access DeferredMailbox::waitToClaim(std::unique_lock<std::mutex>& lock,
                                                     std::optional<Claim>& claim) {
  const bool free = released_.wait_for(lock, claimWait_, [&] { return !claimed_ || closed_; });
  if (closed_ || device_ == nullptr) return Access::shut_down;
  if (!free) return Access::timed_out;
  claim.emplace(*this);
  return Access::done;
}

void DeferredMailbox::requeue(std::vector<std::function<void(DeferredSdfBackend&)>>& posted,
                              size_t from) {
  if (from >= posted.size()) return;
  // In front of what was posted meanwhile: posted calls run in the order posted.
  posted_.insert(posted_.begin(), std::make_move_iterator(posted.begin() + ptrdiff_t(from)),
                 std::make_move_iterator(posted.end()));
}

DeferredMailbox::Access DeferredMailbox::exclusive(
    const std::function<void(DeferredSdfBackend&)>& call) {
  std::optional<Claim> claim;  // before `lock`: see Claim
  std::unique_lock lock(mutex_);
  if (const Access a = waitToClaim(lock, claim); a != Access::done) return a;
  std::vector<std::function<void(DeferredSdfBackend&)>> posted = std::move(posted_);
  posted_.clear();
  DeferredSdfBackend& device = *device_;
  lock.unlock();
  size_t tried = 0;
  try {
    for (; tried < posted.size(); ++tried) posted[tried](device);
    call(device);
  } catch (...) {
    const bool failed = device.failed();
    lock.lock();
    failed_ = failed_ || failed;
    requeue(posted, tried + 1);
    throw;
  }
  const bool failed = device.failed();
  lock.lock();
  failed_ = failed_ || failed;
  return Access::done;
}

bool DeferredMailbox::shutdown() {
  std::unique_ptr<DeferredSdfBackend> device;
  bool inTime = true;
  {
    std::unique_lock lock(mutex_);
    if (!std::exchange(closed_, true)) {
      failed_ = true;
      posted_.clear();
      // An exclusive call waiting for the device has nothing more to wait for.
      released_.notify_all();
    }
    inTime = released_.wait_for(lock, claimWait_, [&] { return !claimed_; });
    if (inTime) device = std::move(device_);
  }
  device.reset();  // waits for its work in flight, with no lock held
  return inTime;
}

const TriangleMesh* DeferredMailbox::assemble(size_t slot, const Request& r) {
  if (r.mesh.positions == nullptr || r.mesh.indices == nullptr) return nullptr;
  Assembled& a = assembled_[slot];
  if (!a.valid || a.id != r.id || a.version != r.version) {
    a.valid = false;
    a.mesh.positions = *r.mesh.positions;
    a.mesh.indices = *r.mesh.indices;
    a.id = r.id;
    a.version = r.version;
    a.valid = true;
  }
  return &a.mesh;
}

bool DeferredMailbox::pump(bool sharedQueueFree) {
  std::array<Seen, kSlots> seen;  // a refused request is simply not started: poll() says idle
  std::array<bool, kSlots> cancels{};
  std::array<bool, kSlots> cancelled{};
  std::array<bool, kSlots> inFlight{};
  std::vector<std::function<void(DeferredSdfBackend&)>> posted;
  std::optional<Claim> claim;  // before `lock`: see Claim
  std::unique_lock lock(mutex_);
  // Never wait for another thread's device calls: it does this work, or the next pump will.
  if (claimed_ || closed_ || device_ == nullptr) return false;
  claim.emplace(*this);
  posted = std::move(posted_);
  posted_.clear();
  std::map<uint64_t, uint64_t> readbackRequests = std::move(readbackRequests_);
  readbackRequests_.clear();
  std::vector<MeshReadback> readbacks;
  bool readbackUnsupported = false;
  for (size_t i = 0; i < kSlots; ++i) {
    Slot& s = slots_[i];
    cancels[i] = std::exchange(s.cancel, false);
    seen[i].request = std::move(s.queued);
    s.queued.reset();
    inFlight[i] = s.onDevice;
  }
  DeferredSdfBackend& device = *device_;
  lock.unlock();

  size_t postedTried = 0;
  bool ready = false;
  bool needsSubmit = true;  // what an interrupted pump leaves: the next one looks again
  bool finished = false;
  std::exception_ptr thrown;
  try {
    for (; postedTried < posted.size(); ++postedTried) posted[postedTried](device);
    for (size_t i = 0; i < kSlots; ++i) {
      if (!cancels[i]) continue;
      cancelled[i] = true;
      device.cancel(i);
    }
    ready = device.ready();
    // After the posted calls: a readback asked after new buffers were posted reads those.
    for (auto it = readbackRequests.begin(); it != readbackRequests.end();) {
      const Status st = device.requestReadback(it->first, it->second);
      readbackUnsupported = readbackUnsupported || st == Status::unsupported;
      // The owner hears of a refusal as an empty readback (it would wait for it otherwise).
      if (st != Status::ok) readbacks.push_back(MeshReadback{it->first, it->second, {}, {}});
      it = readbackRequests.erase(it);
    }
    for (size_t i = 0; i < kSlots; ++i) {
      Seen& v = seen[i];
      if (!v.request) continue;
      const Request& r = *v.request;
      v.tried = true;
      const Status st = device.request(i, r.id, r.version, assemble(i, r), r.objectFromHand, r.box);
      v.started = st == Status::ok;
      v.busy = st == Status::unsupported;
    }
    if (device.needsSubmit(sharedQueueFree)) (void)device.submit(sharedQueueFree);
    for (size_t i = 0; i < kSlots; ++i) {
      Seen& v = seen[i];
      if (!inFlight[i] && !v.started) continue;
      v.poll = device.poll(i, v.grid);
      v.polled = true;
    }
    for (MeshReadback& r : device.takeReadbacks()) readbacks.push_back(std::move(r));
    needsSubmit = device.needsSubmit(true);
    finished = true;
  } catch (...) {
    thrown = std::current_exception();
  }
  const bool failed = device.failed();

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
    // Busy, or not reached before a device call threw: again at the next pump, unless the owner
    // asked anew meanwhile.
    const bool again = v.busy || (v.request && !v.tried);
    if (again && !s.queued && v.request->generation == s.generation)
      s.queued = std::move(v.request);
    if (cancels[i] && !cancelled[i] && s.onDevice) s.cancel = true;
  }
  failed_ = failed_ || failed;
  readbackUnsupported_ = readbackUnsupported_ || readbackUnsupported;
  for (MeshReadback& r : readbacks) readbacks_.push_back(std::move(r));
  // Requests a device call's exception kept from being handed over: again at the next pump.
  for (const auto& [id, generation] : readbackRequests) {
    uint64_t& wanted = readbackRequests_[id];
    wanted = std::max(wanted, generation);
  }
  if (finished) ready_ = ready;
  deviceNeedsSubmit_ = needsSubmit;
  if (thrown) {
    // The call that threw is dropped; those after it run at the next pump.
    requeue(posted, postedTried + 1);
    lock.unlock();
    claim.reset();
    std::rethrow_exception(thrown);
  }
  return true;
}

}  // namespace sdfg
