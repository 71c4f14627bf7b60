// A DeferredSdfBackend (the app's Vulkan device) whose device calls happen outside every lock of
// its owner. DESIGN.md section 3: no layer lock is held across a call into the runtime or Vulkan.
//
// The owner (GraspSession, under the layer's session lock) talks to ownerSide(), which never
// calls the device: a request is recorded with a copy of the mesh it names, a cancel is noted,
// and poll(), ready() and failed() answer what the last pump found. pump() does the device calls
// (records the requests, cancels, submits, polls fences and the backend's readiness) and is
// called by the layer with no lock held: after xrSyncActions's grab update (the own queue) and in
// xrBeginFrame / xrEndFrame (the app's queue, `sharedQueueFree`). One pump runs at a time; a pump
// that finds another running returns at once instead of waiting (the running one, or the next,
// does the work), so no app call waits for another thread's Vulkan call.
//
// Calls that need the device itself go through post() (run at the start of the next pump: the
// registration of the app's buffers, which an app may update every frame) or exclusive() (run
// now, after waiting for a pump in progress: the removal of a buffer target, which must wait for
// the GPU's reads of the app's buffers anyway). shutdown() destroys the device, waiting for its
// work in flight; the layer calls it in xrDestroySession, outside its locks.
// Thread-safe: every function may be called from any thread.
#pragma once

#include <array>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <vector>

#include "sdf/sdf_backend.h"

namespace sdfg {

class DeferredMailbox {
 public:
  static constexpr size_t kSlots = DeferredSdfBackend::kSlots;

  explicit DeferredMailbox(std::unique_ptr<DeferredSdfBackend> device);
  // Destroys the device if shutdown() did not (waiting for its work in flight).
  ~DeferredMailbox();
  DeferredMailbox(const DeferredMailbox&) = delete;
  DeferredMailbox& operator=(const DeferredMailbox&) = delete;

  // The owner's side: a DeferredSdfBackend that never calls the device. Its submit() does
  // nothing (pump() submits). It keeps the mailbox alive.
  static std::unique_ptr<DeferredSdfBackend> ownerSide(std::shared_ptr<DeferredMailbox> mailbox);

  // Does the device calls: posted calls, cancels, the backend's readiness, recorded requests,
  // submission (builds for the queue shared with the app only when `sharedQueueFree`), the poll
  // of builds in flight. Returns false without doing anything when another pump (or an
  // exclusive call) is running, or after shutdown().
  bool pump(bool sharedQueueFree);

  // Runs `call` at the start of the next pump, in the order posted.
  void post(std::function<void(DeferredSdfBackend&)> call);
  // Runs the posted calls and then `call` now, after a pump in progress has ended (waiting for it
  // without holding the mailbox's lock). Does nothing after shutdown().
  void exclusive(const std::function<void(DeferredSdfBackend&)>& call);
  // The owner's record of the meshes it registered on the device by id (hasDeviceMesh()).
  void noteDeviceMesh(uint64_t id, bool present);

  // Destroys the device now (after a pump in progress), waiting for its work in flight; pumps
  // and calls after it do nothing and the owner's side answers failed.
  void shutdown();

 private:
  class OwnerSide;
  struct Request {
    uint64_t generation = 0;
    uint64_t id = 0;
    uint64_t version = 0;
    std::shared_ptr<const TriangleMesh> mesh;  // null: a mesh the device holds itself
    Pose objectFromHand;
    GridBox box;
  };
  // A slot's state. `generation` counts the owner's requests and cancels: what the pump finds
  // for an older generation is dropped.
  struct Slot {
    uint64_t generation = 0;
    std::optional<Request> queued;  // waits for the next pump
    bool cancel = false;            // the device must drop the slot's build
    bool onDevice = false;          // requested on the device, not yet seen done
    uint64_t deviceGeneration = 0;  // the generation of that request
    // Of generation `generation`, for the owner's poll. Neither this, nor a request queued or on
    // the device: the device refused or lost it, and poll() says idle (the owner redoes it).
    std::optional<SdfGrid> result;
  };
  // What one pump saw of a slot on the device.
  struct Seen {
    std::optional<Request> request;  // taken from the queue
    bool started = false;            // the device took it
    bool busy = false;               // the device is still busy with an earlier build: again later
    bool refused = false;            // the device refused it
    bool polled = false;
    BuildPoll poll = BuildPoll::idle;
    SdfGrid grid;
  };

  // The owner's side.
  Status request(size_t slot, uint64_t id, uint64_t version, const TriangleMesh* mesh,
                 const Pose& objectFromHand, const GridBox& box);
  BuildPoll poll(size_t slot, SdfGrid& out);
  void cancel(size_t slot);
  bool hasDeviceMesh(uint64_t id) const;
  bool needsSubmit() const;
  bool failed() const;
  bool ready() const;

  // Takes the device for the calling thread, waiting (unlocked) for whoever has it; false after
  // shutdown().
  bool claim(std::unique_lock<std::mutex>& lock);
  void release(std::unique_lock<std::mutex>& lock);

  mutable std::mutex mutex_;  // guards everything below; never held across a device call
  std::condition_variable released_;
  bool claimed_ = false;  // a thread has the device (pump or exclusive)
  std::unique_ptr<DeferredSdfBackend> device_;
  std::array<Slot, kSlots> slots_;
  // The mesh each slot's last request copied, to copy again only when it changed.
  struct MeshCopy {
    uint64_t id = 0;
    uint64_t version = 0;
    std::shared_ptr<const TriangleMesh> mesh;
  };
  std::array<MeshCopy, kSlots> meshes_;
  std::vector<std::function<void(DeferredSdfBackend&)>> posted_;
  std::set<uint64_t> deviceMeshes_;
  bool failed_ = false;
  bool ready_ = false;
  bool deviceNeedsSubmit_ = false;
};

}  // namespace sdfg
