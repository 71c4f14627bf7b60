// A buffer target's mesh brought to the CPU: one compute dispatch on the app's queue gathers
// the positions out of the app's Vulkan buffers (any offset and stride) and, when asked, the
// indices (16- or 32-bit), into a host-visible buffer of the layer's own; poll() collects them
// once the fence signals, without waiting. With those arrays the engine gives a buffer target
// everything a CPU mesh has (the exact distance, a member of scenes, the outer hand, exact
// contacts), at most a frame or two behind what the app last wrote.
//
// Why a shader and not vkCmdCopyBuffer: a copy needs the app's buffers to carry the
// transfer-source usage, which buffer targets never asked for, and cannot unpack a stride or
// 16-bit indices. The shader needs the storage usage that every buffer target has already.
//
// One gather at a time. The queue is the borrowed device's (the app's), externally synchronized:
// submit() only where the caller may use it. Every object is owned here and destroyed with it,
// after the gather in flight (waited for at most 2 s). Not thread-safe.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "base/status.h"
#include "sdf/sdf_backend.h"
#include "vulkan/vk_context.h"
#include "vulkan/vk_sdf_builder.h"

namespace sdfg {

class VkMeshReadback {
 public:
  // Makes the pipeline and fixed objects on `device` (its queue is the one gathers run on).
  // Errors: those of VkContext::create, out_of_memory or internal.
  static Result<std::unique_ptr<VkMeshReadback>> create(
      const VulkanDevice& device, std::function<void(const std::string&)> log = {});
  ~VkMeshReadback();
  VkMeshReadback(const VkMeshReadback&) = delete;
  VkMeshReadback& operator=(const VkMeshReadback&) = delete;

  // Records and submits the gather of `buffers` (with the indices when `withIndices`), returns
  // at once. The app's earlier writes on this queue are made visible to it by a barrier; writes
  // from another queue need the app's own semaphore, as for builds. Errors: invalid_argument
  // (VkSdfBuilder::setMesh's checks), unsupported (a gather is in flight), device_lost /
  // out_of_memory / internal (the readback is unusable from then on, having logged one line).
  Status submit(uint64_t id, uint64_t generation, const VkMeshBuffers& buffers, bool withIndices);
  // Whether a gather was submitted and not yet collected; and whose.
  bool busy() const { return pending_; }
  uint64_t busyWith() const { return pending_ ? id_ : 0; }
  // Non-blocking: the finished gather, moved out (nothing while it runs or when none is in
  // flight). `failed` says the device failed (the readback is then unusable).
  std::optional<MeshReadback> poll();
  // Waits up to `timeoutNs` for the gather in flight, then as poll(). For a removal that must
  // know the app's buffers are no longer read; never in a frame.
  std::optional<MeshReadback> wait(uint64_t timeoutNs);
  bool failed() const { return failed_; }
  // Test hook: the next submit or poll behaves as if the device returned VK_ERROR_DEVICE_LOST.
  void simulateDeviceLostForTesting() { simulateLost_ = true; }

 private:
  struct Objects;
  VkMeshReadback();
  Status fail(VkResult result, const char* what);
  std::optional<MeshReadback> collect();

  std::unique_ptr<VkContext> ctx_;  // first: destroyed last
  std::unique_ptr<Objects> objects_;
  std::function<void(const std::string&)> log_;
  uint32_t groupSize_ = 64;
  bool pending_ = false;
  bool failed_ = false;
  bool simulateLost_ = false;
  uint64_t id_ = 0;
  uint64_t generation_ = 0;
  uint32_t vertexCount_ = 0;
  uint32_t indexCount_ = 0;  // 0: positions only
};

}  // namespace sdfg
