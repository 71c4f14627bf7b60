// A DeferredSdfBackend (the app's Vulkan device) whose device calls happen outside every lock of
// its owner. DESIGN.md section 3: no layer lock is held across a call into the runtime or Vulkan.
//
// The owner (GraspSession, under the layer's session lock) talks to ownerSide(), which never
// calls the device: a request is recorded with the mesh it names (shared through requestShared,
// so nothing mesh-sized is copied there), a cancel is noted, and poll(), ready() and failed()
// answer what the last pump found. pump() does the device calls (records the requests, cancels,
// submits, polls fences and the backend's readiness) and is called by the layer with no lock
// held: after xrSyncActions's grab update (the own queue) and in xrBeginFrame / xrEndFrame (the
// app's queue, `sharedQueueFree`). One pump runs at a time; a pump that finds another running
// returns at once instead of waiting (the running one, or the next, does the work), so no app
// call waits for another thread's Vulkan call.
//
// Calls that need the device itself go through post() (run at the start of the next pump: the
// registration of the app's buffers, which an app may update every frame) or exclusive() (run
// now, after waiting for a pump in progress: the removal of a buffer target, which must wait for
// the GPU's reads of the app's buffers anyway). shutdown() destroys the device, waiting for its
// work in flight; the layer calls it in xrDestroySession, outside its locks.
//
// The device is held by one thread at a time through a Claim, a guard that gives it back and
// wakes the waiters when it ends, also when a device call throws: the exception reaches the
// caller, and the mailbox stays usable (work not yet handed to the device waits for the next
// pump). exclusive() and shutdown() wait for another thread's claim at most `claimWait` and say
// when it ran out, so neither a destroy nor xrDestroySession hangs on a stuck device call.
// Thread-safe: every function may be called from any thread.
#pragma once

#include <array>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
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
  // How long exclusive() and shutdown() wait for another thread's pump or exclusive call. A pump
  // takes milliseconds (it records, submits and polls; it never waits for the GPU), and an
  // exclusive call waits at most 2 s for the GPU itself: a claim held longer is a stuck device.
  static constexpr std::chrono::milliseconds kClaimWait{2000};

  // What a call that needs the device got.
  enum class Access {
    done,       // the device was free within the bound: the call ran
    shut_down,  // shutdown() was called: nothing ran
    timed_out,  // another thread held the device past the bound: nothing ran
  };

  explicit DeferredMailbox(std::unique_ptr<DeferredSdfBackend> device,
                           std::chrono::milliseconds claimWait = kClaimWait);
  // Destroys the device if shutdown() did not, or could not in time (waiting for its work in
  // flight). Nobody holds the device then: a pump or exclusive call holds a reference.
  ~DeferredMailbox();
  DeferredMailbox(const DeferredMailbox&) = delete;
  DeferredMailbox& operator=(const DeferredMailbox&) = delete;

  // The owner's side: a DeferredSdfBackend that never calls the device. Its submit() does
  // nothing (pump() submits). It keeps the mailbox alive.
  static std::unique_ptr<DeferredSdfBackend> ownerSide(std::shared_ptr<DeferredMailbox> mailbox);

  // Does the device calls: posted calls, cancels, the backend's readiness, recorded requests,
  // submission (builds for the queue shared with the app only when `sharedQueueFree`), the poll
  // of builds in flight. Returns false without doing anything when another pump (or an
  // exclusive call) is running, or after shutdown(). A device call that throws ends the pump:
  // the exception propagates, the call that threw is dropped (a request that threw reads as
  // refused: the owner asks again), and the posted calls, cancels and requests it had not
  // reached yet wait for the next pump.
  bool pump(bool sharedQueueFree);

  // Runs `call` at the start of the next pump, in the order posted.
  void post(std::function<void(DeferredSdfBackend&)> call);
  // Runs the posted calls and then `call` now, after a pump or exclusive call in progress on
  // another thread has ended (waited for without holding the mailbox's lock, at most the claim
  // bound). Only `done` ran anything. An exception from a posted call or `call` propagates; the
  // posted calls after the one that threw wait for the next pump.
  Access exclusive(const std::function<void(DeferredSdfBackend&)>& call);
  // The owner's record of the meshes it registered on the device by id (hasDeviceMesh()).
  void noteDeviceMesh(uint64_t id, bool present);

  // Destroys the device now, after a pump or exclusive call in progress (waited for at most the
  // claim bound), waiting for its work in flight; pumps and calls after it do nothing and the
  // owner's side answers failed. Returns false when the claim in progress outlasted the bound:
  // the device is then left to the thread that holds it, and destroyed with the mailbox (whoever
  // holds the claim holds a reference).
  bool shutdown();

 private:
  class OwnerSide;
  class Claim;
  struct Request {
    uint64_t generation = 0;
    uint64_t id = 0;
    uint64_t version = 0;
    SharedMesh mesh;  // null positions: a mesh the device holds itself
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
    bool tried = false;              // handed to the device (it may have thrown)
    bool started = false;            // the device took it
    bool busy = false;               // the device is still busy with an earlier build: again later
    bool refused = false;            // the device refused it
    bool polled = false;
    BuildPoll poll = BuildPoll::idle;
    SdfGrid grid;
  };

  // The owner's side. `mesh`: null positions for a mesh the device holds.
  Status request(size_t slot, uint64_t id, uint64_t version, SharedMesh mesh,
                 const Pose& objectFromHand, const GridBox& box);
  BuildPoll poll(size_t slot, SdfGrid& out);
  void cancel(size_t slot);
  bool hasDeviceMesh(uint64_t id) const;
  bool needsSubmit() const;
  bool failed() const;
  bool ready() const;
  // Readbacks of device meshes (DeferredSdfBackend::requestReadback): asked here, handed to the
  // device by the next pump, and what it finished kept for the owner's takeReadbacks().
  Status requestReadback(uint64_t id, uint64_t generation);
  std::vector<MeshReadback> takeReadbacks();

  // Waits (with `lock` released) until no other thread holds the device, at most claimWait_, and
  // takes it into `claim` when the answer is done.
  Access waitToClaim(std::unique_lock<std::mutex>& lock, std::optional<Claim>& claim);
  // The mesh of a request as the device takes it: the arrays copied into one TriangleMesh, again
  // only for another target or new positions (as the device uploads them). Called by the thread
  // that holds the device, with no lock held.
  const TriangleMesh* assemble(size_t slot, const Request& r);
  // Puts posted calls a device call's exception kept from running back in front of the queue.
  void requeue(std::vector<std::function<void(DeferredSdfBackend&)>>& posted, size_t from);

  const std::chrono::milliseconds claimWait_;
  mutable std::mutex mutex_;  // guards everything below; never held across a device call
  std::condition_variable released_;
  bool claimed_ = false;  // a thread has the device (pump or exclusive): see Claim
  bool closed_ = false;   // shutdown() was called
  std::unique_ptr<DeferredSdfBackend> device_;
  std::array<Slot, kSlots> slots_;
  std::vector<std::function<void(DeferredSdfBackend&)>> posted_;
  std::set<uint64_t> deviceMeshes_;
  bool failed_ = false;
  bool ready_ = false;
  bool deviceNeedsSubmit_ = false;
  std::map<uint64_t, uint64_t> readbackRequests_;  // id -> newest generation asked
  std::vector<MeshReadback> readbacks_;            // finished, for the owner
  bool readbackUnsupported_ = false;               // the device said it cannot

  // The mesh each slot's last request handed the device (assemble()). Only the thread that holds
  // the device touches it.
  struct Assembled {
    uint64_t id = 0;
    uint64_t version = 0;
    bool valid = false;
    TriangleMesh mesh;
  };
  std::array<Assembled, kSlots> assembled_;
};

}  // namespace sdfg
