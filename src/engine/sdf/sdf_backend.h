// Where the grab-box SDF is built: one interface, so the CPU builder (headless and OpenGL
// sessions, and the fallback) and the Vulkan compute backend (the app's device) plug in alike.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

#include "base/pose.h"
#include "base/status.h"
#include "mesh/mesh.h"
#include "mesh/mesh_distance.h"
#include "sdf/sdf_cpu.h"
#include "sdf/sdf_grid.h"

namespace sdfg {

class SdfBackend {
 public:
  virtual ~SdfBackend() = default;
  virtual std::string_view name() const = 0;
  // Fills `out` (resized to `box`) with the signed distance of `target` at every node;
  // `objectFromHand` places hand-space points in the mesh's space. A backend that fails with
  // device_lost or unsupported lets the caller fall back to the CPU. Once `limit` is reached
  // the build stops with timed_out and leaves `out` as it was.
  virtual Status build(const MeshDistance& target, const Pose& objectFromHand, const GridBox& box,
                       SdfGrid& out, const WorkLimit& limit) = 0;
  Status build(const MeshDistance& target, const Pose& objectFromHand, const GridBox& box,
               SdfGrid& out) {
    return build(target, objectFromHand, box, out, WorkLimit::none());
  }
};

// The CPU builder (CpuSdfBuilder) behind the interface; threads == 0: one per hardware thread.
// `options` (validated at each build: a bad band fails the build with invalid_argument) can turn
// on the far-field mode; the default is exact at every node.
std::unique_ptr<SdfBackend> makeCpuSdfBackend(unsigned threads, const CpuSdfOptions& options = {});

enum class BuildPoll {
  idle,     // nothing requested for the slot
  pending,  // requested and not yet submitted, or running on the device
  ready,    // done: the grid was written to the caller's SdfGrid
  failed,   // the device failed; the backend is unusable from now on
};

// A mesh handed to a backend that may keep it past the call (DeferredMailbox keeps it until its
// next pump): nobody changes what it points to once shared, so new positions come as a new
// `positions` beside the same `indices`, and no one copies a mesh while holding a lock.
struct SharedMesh {
  std::shared_ptr<const std::vector<glm::vec3>> positions;
  std::shared_ptr<const std::vector<uint32_t>> indices;
};

// A device mesh read back to the CPU (DeferredSdfBackend::requestReadback): the vertices (a
// position the device's buffer does not hold reads as NaN) and, when they were read too, the
// indices (an index the buffer does not hold reads as UINT32_MAX). The CPU's mesh checks refuse
// both, so a bad description ends as a refused set-up, never as a read out of bounds.
// No positions at all: the request was refused after it was taken (the device cannot read
// meshes back, or no longer has the mesh).
struct MeshReadback {
  uint64_t id = 0;
  uint64_t generation = 0;  // the requester's, echoed
  std::vector<glm::vec3> positions;
  std::vector<uint32_t> indices;  // empty: positions only
};

// A backend that builds on a device queue its owner may use only at certain moments (the app's
// Vulkan queue, which the layer may touch only inside xrBeginFrame / xrEndFrame). request()
// records a build and returns at once; submit() hands every recorded build to the device and
// must be called only where the queue may be used; poll() collects a finished build without
// waiting (one frame of latency). Builds run per slot (one per hand), one per slot at a time.
// After any device failure (device lost included) the backend logs one line, answers failed /
// device_lost from then on, and its owner continues on the CPU. Not thread-safe: the owner
// serializes calls.
class DeferredSdfBackend {
 public:
  static constexpr size_t kSlots = 2;
  virtual ~DeferredSdfBackend() = default;
  virtual std::string_view name() const = 0;

  // Records a build for `slot` of target `id` placed by `objectFromHand` in `box`. `mesh` is the
  // target's CPU arrays (copied now when the slot does not hold this id and `version` yet), or
  // null for a target whose mesh the backend holds itself (hasDeviceMesh). Errors:
  // invalid_argument (slot out of range, no mesh for `id`, bad box or pose), unsupported (the
  // slot has a build recorded or running), device_lost / out_of_memory / internal (failed).
  virtual Status request(size_t slot, uint64_t id, uint64_t version, const TriangleMesh* mesh,
                         const Pose& objectFromHand, const GridBox& box) = 0;
  // request() with a mesh of CPU arrays shared instead of lent: a backend that keeps the mesh
  // past the call keeps these pointers, which is what lets an owner request under its lock. By
  // default the arrays are copied into a TriangleMesh for request(). Errors as request();
  // invalid_argument for a null array.
  virtual Status requestShared(size_t slot, uint64_t id, uint64_t version, const SharedMesh& mesh,
                               const Pose& objectFromHand, const GridBox& box) {
    if (mesh.positions == nullptr || mesh.indices == nullptr) return Status::invalid_argument;
    const TriangleMesh copy{*mesh.positions, *mesh.indices};
    return request(slot, id, version, &copy, objectFromHand, box);
  }
  // Whether `id` names a mesh registered with the concrete backend (the app's device buffers).
  virtual bool hasDeviceMesh(uint64_t id) const = 0;
  // Whether a recorded build waits for submit(sharedQueueFree).
  virtual bool needsSubmit(bool sharedQueueFree) const = 0;
  // Submits the recorded builds: those for a queue of the backend's own at any time, those for
  // the queue it shares with the app only when `sharedQueueFree` (the owner may use it now).
  // Errors as request().
  virtual Status submit(bool sharedQueueFree) = 0;
  // Non-blocking. On ready, `out` holds the grid of the slot's last request (resized to its
  // box) and the slot is idle again.
  virtual BuildPoll poll(size_t slot, SdfGrid& out) = 0;
  // Forgets the slot's request: an unsubmitted one is dropped, a running one's result discarded.
  virtual void cancel(size_t slot) = 0;
  virtual bool failed() const = 0;
  // Whether builds may be requested now. A backend that prepares itself after creation
  // (pipelines made on a thread of its own, a warm-up build that makes the driver compile them)
  // answers false until that is done, advancing it without waiting; its owner builds on the CPU
  // meanwhile. A failure of the preparation shows in failed().
  virtual bool ready() { return true; }

  // Reads device mesh `id` (hasDeviceMesh) back to CPU arrays at the next submit() that may use
  // the queue the app writes it on, as it is then; a newer request for the same id replaces one
  // not yet started. The indices come along the first time and whenever the mesh was registered
  // again with other index buffers. Errors: invalid_argument (no such mesh), unsupported (this
  // backend cannot read meshes back: the default), device_lost (failed).
  virtual Status requestReadback(uint64_t id, uint64_t generation) {
    (void)id;
    (void)generation;
    return Status::unsupported;
  }
  // The readbacks finished since the last call, oldest first; never waits.
  virtual std::vector<MeshReadback> takeReadbacks() { return {}; }
};

}  // namespace sdfg
