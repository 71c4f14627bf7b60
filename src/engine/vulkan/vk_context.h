// A Vulkan device someone else created (the OpenXR app's, or the layer's extra queue on it), as
// the SDF compute backend borrows it: handles, the queue it may submit to, and the functions it
// calls, loaded through the vkGetInstanceProcAddr the owner passes in (the app's loader; this
// library never links a Vulkan loader of its own).
//
// Nothing here owns the instance, device or queue. The queue is externally synchronized: the
// caller guarantees no other thread uses it during a call that submits (VkSdfBuilder::submit*).
// VkOwned<T> owns one object created on the device and destroys it with its owner.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <utility>

#include <vulkan/vulkan_core.h>

#include "base/status.h"

namespace sdfg {

// What the layer gets from XrGraphicsBindingVulkanKHR (or its own extra queue).
struct VulkanDevice {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physicalDevice = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  uint32_t queueFamilyIndex = 0;  // must support compute
  uint32_t queueIndex = 0;
  PFN_vkGetInstanceProcAddr getInstanceProcAddr = nullptr;  // the app's loader entry point
};

// Device-level entry points the backend uses, loaded once per context.
struct VkFunctions {
#define SDFG_VK_INSTANCE_FUNCTIONS(X)    \
  X(vkGetDeviceProcAddr)                 \
  X(vkGetPhysicalDeviceProperties)       \
  X(vkGetPhysicalDeviceMemoryProperties) \
  X(vkGetPhysicalDeviceQueueFamilyProperties)
#define SDFG_VK_DEVICE_FUNCTIONS(X) \
  X(vkGetDeviceQueue)               \
  X(vkCreateBuffer)                 \
  X(vkDestroyBuffer)                \
  X(vkGetBufferMemoryRequirements)  \
  X(vkAllocateMemory)               \
  X(vkFreeMemory)                   \
  X(vkBindBufferMemory)             \
  X(vkMapMemory)                    \
  X(vkUnmapMemory)                  \
  X(vkFlushMappedMemoryRanges)      \
  X(vkInvalidateMappedMemoryRanges) \
  X(vkCreateShaderModule)           \
  X(vkDestroyShaderModule)          \
  X(vkCreateDescriptorSetLayout)    \
  X(vkDestroyDescriptorSetLayout)   \
  X(vkCreatePipelineLayout)         \
  X(vkDestroyPipelineLayout)        \
  X(vkCreateComputePipelines)       \
  X(vkDestroyPipeline)              \
  X(vkCreateDescriptorPool)         \
  X(vkDestroyDescriptorPool)        \
  X(vkAllocateDescriptorSets)       \
  X(vkUpdateDescriptorSets)         \
  X(vkCreateCommandPool)            \
  X(vkDestroyCommandPool)           \
  X(vkAllocateCommandBuffers)       \
  X(vkResetCommandBuffer)           \
  X(vkBeginCommandBuffer)           \
  X(vkEndCommandBuffer)             \
  X(vkCmdBindPipeline)              \
  X(vkCmdBindDescriptorSets)        \
  X(vkCmdPushConstants)             \
  X(vkCmdDispatch)                  \
  X(vkCmdPipelineBarrier)           \
  X(vkCmdCopyBuffer)                \
  X(vkCmdCopyImageToBuffer)         \
  X(vkCmdFillBuffer)                \
  X(vkCreateFence)                  \
  X(vkDestroyFence)                 \
  X(vkResetFences)                  \
  X(vkGetFenceStatus)               \
  X(vkWaitForFences)                \
  X(vkQueueSubmit)                  \
  X(vkCreateQueryPool)              \
  X(vkDestroyQueryPool)             \
  X(vkCmdResetQueryPool)            \
  X(vkCmdWriteTimestamp)            \
  X(vkGetQueryPoolResults)
#define SDFG_VK_DECLARE(name) PFN_##name name = nullptr;
  SDFG_VK_INSTANCE_FUNCTIONS(SDFG_VK_DECLARE)
  SDFG_VK_DEVICE_FUNCTIONS(SDFG_VK_DECLARE)
#undef SDFG_VK_DECLARE
};

class VkContext {
 public:
  // Loads the functions and checks the device: Vulkan 1.1 or later, a queue family with compute
  // and the queue index in range. Errors: invalid_argument (null handle or function, bad queue),
  // unsupported (older device, no compute on that family, a function the driver lacks).
  static Result<std::unique_ptr<VkContext>> create(const VulkanDevice& device);

  const VulkanDevice& device() const { return device_; }
  VkDevice handle() const { return device_.device; }
  VkQueue queue() const { return queue_; }
  const VkFunctions& fn() const { return fn_; }
  const VkPhysicalDeviceProperties& properties() const { return properties_; }
  const VkPhysicalDeviceMemoryProperties& memoryProperties() const { return memory_; }

  // A memory type allowed by `typeBits` with every `required` flag, preferring ones that also
  // have `preferred`; UINT32_MAX when none.
  uint32_t findMemoryType(uint32_t typeBits, VkMemoryPropertyFlags required,
                          VkMemoryPropertyFlags preferred) const;

  // Objects this context created and has not destroyed yet (leak checks in tests).
  int64_t liveObjects() const { return live_.load(std::memory_order_relaxed); }
  void countCreated() const { live_.fetch_add(1, std::memory_order_relaxed); }
  void countDestroyed() const { live_.fetch_sub(1, std::memory_order_relaxed); }

 private:
  VkContext() = default;
  VulkanDevice device_;
  VkFunctions fn_;
  VkQueue queue_ = VK_NULL_HANDLE;
  VkPhysicalDeviceProperties properties_{};
  VkPhysicalDeviceMemoryProperties memory_{};
  mutable std::atomic<int64_t> live_{0};
};

// Destroys one handle of each kind the backend creates.
void destroyVk(const VkContext& ctx, VkBuffer h);
void destroyVk(const VkContext& ctx, VkDeviceMemory h);
void destroyVk(const VkContext& ctx, VkShaderModule h);
void destroyVk(const VkContext& ctx, VkDescriptorSetLayout h);
void destroyVk(const VkContext& ctx, VkPipelineLayout h);
void destroyVk(const VkContext& ctx, VkPipeline h);
void destroyVk(const VkContext& ctx, VkDescriptorPool h);
void destroyVk(const VkContext& ctx, VkCommandPool h);
void destroyVk(const VkContext& ctx, VkFence h);
void destroyVk(const VkContext& ctx, VkQueryPool h);

// Sole owner of one Vulkan object; destroys it when reset or destroyed. Move-only. The context
// must outlive it (VkSdfBuilder declares its context first, so it is destroyed last).
template <class T>
class VkOwned {
 public:
  VkOwned() = default;
  VkOwned(const VkContext& ctx, T handle) : ctx_(&ctx), handle_(handle) {
    if (handle_ != VK_NULL_HANDLE) ctx_->countCreated();
  }
  ~VkOwned() { reset(); }
  VkOwned(const VkOwned&) = delete;
  VkOwned& operator=(const VkOwned&) = delete;
  VkOwned(VkOwned&& other) noexcept
      : ctx_(other.ctx_), handle_(std::exchange(other.handle_, VK_NULL_HANDLE)) {}
  VkOwned& operator=(VkOwned&& other) noexcept {
    if (this != &other) {
      reset();
      ctx_ = other.ctx_;
      handle_ = std::exchange(other.handle_, VK_NULL_HANDLE);
    }
    return *this;
  }

  T get() const { return handle_; }
  explicit operator bool() const { return handle_ != VK_NULL_HANDLE; }
  void reset() {
    if (handle_ != VK_NULL_HANDLE) {
      destroyVk(*ctx_, handle_);
      ctx_->countDestroyed();
      handle_ = VK_NULL_HANDLE;
    }
  }
  // Gives up ownership without destroying (only when the device can no longer be trusted to
  // be idle: destroying an object in use is worse than leaking it).
  T release() { return std::exchange(handle_, VK_NULL_HANDLE); }

 private:
  const VkContext* ctx_ = nullptr;
  T handle_ = VK_NULL_HANDLE;
};

// A buffer with its own memory, mapped for its whole life when host-visible.
struct VkBufferAlloc {
  VkOwned<VkDeviceMemory> memory;  // declared first: destroyed after the buffer bound to it
  VkOwned<VkBuffer> buffer;
  VkDeviceSize size = 0;      // bytes requested
  void* mapped = nullptr;     // null unless host-visible
  bool coherent = true;       // false: flush after host writes, invalidate before host reads
  VkDeviceSize atomSize = 1;  // nonCoherentAtomSize, for flush/invalidate ranges
};

enum class VkMemoryKind {
  device,    // device-local, no host access
  upload,    // host-visible, written by the host (prefers device-local and coherent)
  readback,  // host-visible, read by the host (prefers cached)
};

// Creates a buffer of `size` bytes (> 0) with `usage`. Errors carry the failing VkResult.
Result<VkBufferAlloc> createBuffer(const VkContext& ctx, VkDeviceSize size,
                                   VkBufferUsageFlags usage, VkMemoryKind kind);

// Flushes (host -> device) or invalidates (device -> host) a whole mapped buffer; no-ops on
// coherent memory. Returns the VkResult.
VkResult flushBuffer(const VkContext& ctx, const VkBufferAlloc& b);
VkResult invalidateBuffer(const VkContext& ctx, const VkBufferAlloc& b);

const char* vkResultName(VkResult result);

// The error a failed call `what` returned: out_of_memory, device_lost or internal, with a
// message that names the call and the VkResult.
Error vkCallError(VkResult result, const char* what);

// A compute pipeline of `code` (SPIR-V, entry point main) on `layout`, whose local_size_x is
// specialization constant 0, set to `groupSize`. The shader module lives only until the
// pipeline exists. Errors: vkCallError of the failing call.
Result<VkOwned<VkPipeline>> createComputePipeline(const VkContext& ctx, VkPipelineLayout layout,
                                                  std::span<const uint32_t> code,
                                                  uint32_t groupSize);

// The layouts of a compute pass: one descriptor set of `bindings` storage buffers (bindings 0..
// bindings - 1) and `pushBytes` of push constants. Errors: vkCallError of the failing call.
std::optional<Error> createComputeLayouts(const VkContext& ctx, uint32_t bindings,
                                          uint32_t pushBytes,
                                          VkOwned<VkDescriptorSetLayout>& setLayout,
                                          VkOwned<VkPipelineLayout>& pipelineLayout);

// What a compute pass submitted one at a time owns besides its layouts and pipelines: one
// descriptor set (its pool holds only it), one resettable command buffer for the context's queue
// family, and the fence its submissions signal. Declared in destruction order reversed.
struct VkSubmitObjects {
  VkOwned<VkDescriptorPool> descriptorPool;  // owns `set`
  VkDescriptorSet set = VK_NULL_HANDLE;
  VkOwned<VkCommandPool> commandPool;    // owns `cmd`
  VkCommandBuffer cmd = VK_NULL_HANDLE;  // re-recorded for every submission
  VkOwned<VkFence> fence;                // signalled when a submission completes (polled)
};
// Makes them, the set of `setLayout` with its `bindings` storage buffers. Errors: vkCallError of
// the failing call.
std::optional<Error> createSubmitObjects(const VkContext& ctx, VkDescriptorSetLayout setLayout,
                                         uint32_t bindings, VkSubmitObjects& out);

// Records one global memory barrier into `cmd`.
void recordMemoryBarrier(const VkContext& ctx, VkCommandBuffer cmd, VkPipelineStageFlags srcStage,
                         VkAccessFlags srcAccess, VkPipelineStageFlags dstStage,
                         VkAccessFlags dstAccess);

// A zeroed Vulkan info struct with its sType set.
template <class T>
T vkStruct(VkStructureType type) {
  T info{};
  info.sType = type;
  return info;
}

}  // namespace sdfg
