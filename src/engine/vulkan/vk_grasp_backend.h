// The grab-box SDF of a grasp session on a borrowed Vulkan device (the OpenXR app's), behind
// DeferredSdfBackend: one VkSdfBuilder per slot (hand), the grid read back through a fence that
// poll() checks without waiting. Targets come as CPU arrays (from GraspSession) or as the app's
// own Vulkan buffers, registered here by id and read by the GPU at every build (skinned meshes).
//
// Queues: submit() is the only call that touches a queue (vkQueueSubmit). Builds go to the
// app's queue (the binding's; the caller passes sharedQueueFree only inside xrBeginFrame /
// xrEndFrame), or, when the layer added a queue of its own to the app's device (`ownQueue`), CPU
// targets' builds go there at any time. Builds of app-buffer targets always use the app's
// queue: the app's writes to its buffers are ordered before them by submission order on that
// queue, which a second queue would need a semaphore for. Everything else (request, poll,
// cancel, destruction) uses device-level calls on objects this backend owns, or fences.
//
// Failure: the first Vulkan error (VK_ERROR_DEVICE_LOST included) logs one line through
// options.log, marks the backend failed, and every later call answers failed / device_lost; the
// session continues on the CPU. Destruction waits (at most 2 s per slot) for work in flight, so
// the app may destroy its device and buffers afterwards.
//
// Preparation (options.prepareInBackground, the layer's choice): create() returns at once; a
// thread of the backend makes the builders (shader modules, pipelines: device-level create
// calls, which Vulkan allows from any thread), then each builder runs two small warm-up builds
// on its queue, submitted by submit() like any build, so that a driver that compiles at the
// first dispatch (Mesa's lavapipe: seconds with a cold shader cache) does so before the user's
// first grab, not during it. ready() says when builds may be requested; until then the owner
// builds on the CPU. Destruction stops the thread between builders and joins it.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <unordered_map>

#include "sdf/sdf_backend.h"
#include "vulkan/vk_mesh_readback.h"
#include "vulkan/vk_sdf_builder.h"

namespace sdfg {

struct VkGraspBackendOptions {
  // Where the one failure line goes (stderr when empty). Called from the preparation thread too.
  std::function<void(const std::string&)> log;
  // Make the builders on a thread of the backend and warm them up (see the header comment)
  // instead of inside create().
  bool prepareInBackground = false;
};

// Test hooks: a simulated VK_ERROR_DEVICE_LOST at the first submission, or at the poll after it
// (the real work then still runs, so destruction must wait for it); or a preparation that never
// ends (ready() stays false: a driver still compiling).
// stuckReadsOnce: the first removeDeviceMesh of a registered mesh finds its reads still running
// past the bound (without waiting), as a hung device would; later ones are real.
enum class VkGraspFault { none, lostAtSubmit, lostAtPoll, neverReady, stuckReadsOnce };

class VkGraspBackend final : public DeferredSdfBackend {
 public:
  // Builds one VkSdfBuilder per slot on `appQueue` (pipelines included: do this outside the
  // frame loop), or on `ownQueue` when given (then app-queue builders are made at the first
  // setDeviceMesh). Errors: those of VkSdfBuilder::create. With prepareInBackground nothing is
  // made here and no error is returned: a failure of the preparation marks the backend failed.
  static Result<std::unique_ptr<VkGraspBackend>> create(const VulkanDevice& appQueue,
                                                        const VulkanDevice* ownQueue = nullptr,
                                                        const VkGraspBackendOptions& options = {});
  ~VkGraspBackend() override;

  std::string_view name() const override { return "vulkan"; }
  Status request(size_t slot, uint64_t id, uint64_t version, const TriangleMesh* mesh,
                 const Pose& objectFromHand, const GridBox& box) override;
  bool hasDeviceMesh(uint64_t id) const override { return deviceMeshes_.count(id) != 0; }
  bool needsSubmit(bool sharedQueueFree) const override;
  Status submit(bool sharedQueueFree) override;
  BuildPoll poll(size_t slot, SdfGrid& out) override;
  void cancel(size_t slot) override;
  bool failed() const override { return failed_; }
  bool ready() override;
  // Gathers on the app's queue (vulkan/vk_mesh_readback.h), one at a time, in the order asked.
  Status requestReadback(uint64_t id, uint64_t generation) override;
  std::vector<MeshReadback> takeReadbacks() override;

  // Registers (or replaces) the app-buffer mesh of target `id`. The buffers are borrowed: see
  // VkMeshBuffers. Errors: invalid_argument (see VkSdfBuilder::setMesh(VkMeshBuffers)),
  // device_lost (failed), or those of VkSdfBuilder::create (app-queue builders made here).
  Status setDeviceMesh(uint64_t id, const VkMeshBuffers& buffers);
  // Forgets the mesh of `id`; first waits (at most 2 s a slot) for the builds in flight that read
  // its buffers, so the app may destroy them when this returns true. False: a build still reads
  // them after that wait, and the mesh stays registered (call again later).
  bool removeDeviceMesh(uint64_t id);

  void injectFault(VkGraspFault fault) { fault_ = fault; }
  // Whether CPU targets build on a queue of the layer's own.
  bool hasOwnQueue() const { return ownQueue_; }

 private:
  struct Builder {
    std::unique_ptr<VkSdfBuilder> builder;
    bool shared = true;   // on the app's queue
    uint64_t meshId = 0;  // the mesh set on the builder (0: none)
    uint64_t meshVersion = 0;
    bool meshOnDevice = false;
    int warmups = kWarmups;  // warm-up builds submitted (kWarmups: none left to do)
  };
  // Warm-up builds per builder: an open triangle (winding-number sign, cluster pass) and a
  // closed tetrahedron (pseudo-normal sign, repair pass), so every pipeline a build uses runs.
  static constexpr int kWarmups = 2;
  // What the preparation thread made, handed over under prepMutex_.
  struct Prepared {
    std::array<std::unique_ptr<VkSdfBuilder>, kSlots> main, app;
    std::unique_ptr<VkMeshReadback> readback;  // null: readbacks unavailable (logged)
    std::optional<Error> error;
  };
  enum class Prep { making, warming, done };
  struct Slot {
    Builder main;               // own queue when there is one, else the app's
    Builder app;                // app-buffer targets when `main` is on the own queue
    Builder* active = nullptr;  // the builder of the recorded or running build
    bool recorded = false;      // waits for submit()
    bool inFlight = false;      // submitted, fence not yet seen
    bool discard = false;       // cancelled while in flight
    GridBox box{};
    Pose objectFromHand{};
  };
  struct DeviceMesh {
    VkMeshBuffers buffers;
    uint64_t version = 1;
    bool indicesRead = false;  // a readback brought its indices (they come once)
  };

  VkGraspBackend() = default;
  Status markFailed(Status status);
  void logOnce(const std::string& line);
  Result<std::unique_ptr<VkSdfBuilder>> makeBuilder(const VulkanDevice& device);
  // Body of the preparation thread: makes every builder into made_.
  void prepare(VulkanDevice mainQueue, bool appBuilders);
  // Takes what the finished thread made into the slots (or fails the backend).
  void adoptPrepared();
  // Submits the next warm-up build of each builder whose queue may be used now.
  Status submitWarmups(bool sharedQueueFree);
  // Collects a finished readback, then starts the next one asked for (app's queue only).
  void pumpReadbacks(bool sharedQueueFree);
  void collectReadback();

  std::array<Slot, kSlots> slots_;
  VulkanDevice appQueue_{};
  bool ownQueue_ = false;
  std::unordered_map<uint64_t, DeviceMesh> deviceMeshes_;
  // Readbacks: the gatherer (on the app's queue; null until prepared, or when it could not be
  // made), the ids asked for in order with their newest generation, and the finished ones.
  std::unique_ptr<VkMeshReadback> readback_;
  std::deque<uint64_t> readbackOrder_;
  std::unordered_map<uint64_t, uint64_t> readbackWanted_;
  std::vector<MeshReadback> readbacksDone_;
  VkGraspBackendOptions options_;
  VkGraspFault fault_ = VkGraspFault::none;
  bool failed_ = false;
  std::mutex logMutex_;  // logOnce runs on the preparation thread too
  bool logged_ = false;  // guarded by logMutex_

  Prep prep_ = Prep::done;
  std::thread preparer_;
  std::atomic<bool> prepared_{false};    // the thread has stored its result in made_
  std::atomic<bool> cancelPrep_{false};  // destruction: stop between builders
  std::mutex prepMutex_;
  Prepared made_;  // guarded by prepMutex_
};

}  // namespace sdfg
