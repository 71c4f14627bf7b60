// autograsp-frame-cost's Vulkan side (--session vulkan): what a Vulkan OpenXR app owns. Its
// VkInstance and VkDevice are made through XR_KHR_vulkan_enable2 on the physical device the
// runtime names, and, for --target buffer, the object's mesh lives in host-visible storage
// buffers of that device, which the app rewrites every frame of the deforming phase the way a
// skinning pass would: on the binding's queue, ordered against the layer's reads by barriers.
#pragma once

#define XR_USE_GRAPHICS_API_VULKAN
#include <vulkan/vulkan.h>
// openxr_platform.h needs vulkan.h first.
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>

#include <openxr/XR_SDFG_auto_grasp.h>

#include <cstdint>
#include <string>
#include <vector>

#include "outer_scene.h"

namespace sdfg::frame_cost {

// A host-visible, host-coherent buffer, mapped for its whole life.
struct MappedBuffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  void* mapped = nullptr;
  VkDeviceSize size = 0;
};

class VulkanApp {
 public:
  VulkanApp() = default;
  ~VulkanApp();
  VulkanApp(const VulkanApp&) = delete;
  VulkanApp& operator=(const VulkanApp&) = delete;

  // The instance and device through the runtime (xrCreateVulkanInstanceKHR,
  // xrGetVulkanGraphicsDevice2KHR, xrCreateVulkanDeviceKHR), one queue of the first family with
  // graphics and compute. False with `error` set on any failure.
  bool create(XrInstance instance, XrSystemId system, std::string& error);
  // For xrCreateSession (valid after create()).
  XrGraphicsBindingVulkan2KHR binding() const;
  // VkPhysicalDeviceProperties::deviceName, and its type ("cpu", "discrete-gpu", ...).
  const std::string& deviceName() const { return deviceName_; }
  const std::string& deviceType() const { return deviceType_; }

  // `o`'s positions (stride 12, 32-bit indices) in two storage buffers; `desc` describes them
  // (bounds: the mesh's box, which also holds it shrunk about the origin in the deforming phase).
  bool uploadMesh(const Object& o, XrGraspTargetVulkanBuffersSDFG& desc, std::string& error);
  // New positions into the vertex buffer, as a skinning pass: copied from a staging buffer by a
  // command buffer submitted on the binding's queue now (call between xrBeginFrame and
  // xrEndFrame, where the queue is the app's). Same vertex count as uploadMesh's.
  bool writeVertices(const std::vector<XrVector3f>& vertices, std::string& error);

  // Waits for the device and frees everything; the session must be destroyed first (the layer
  // frees what it made on the device in xrDestroySession).
  void destroy();

 private:
  // A staging buffer, and the command buffer that copies it, in flight until `fence` signals.
  struct Slot {
    MappedBuffer staging;
    VkCommandBuffer commands = VK_NULL_HANDLE;
    VkFence fence = VK_NULL_HANDLE;  // signalled: the slot may be written again
  };

  bool createBuffer(VkDeviceSize bytes, VkBufferUsageFlags usage, MappedBuffer& out);
  void freeBuffer(MappedBuffer& b);
  // A slot whose copy is done: a free one, else a new one up to kMaxSlots, else the oldest once
  // its fence signals (the app waits, as it would for a frame in flight).
  Slot* freeSlot(std::string& error);

  static constexpr size_t kMaxSlots = 8;

  VkInstance instance_ = VK_NULL_HANDLE;
  VkPhysicalDevice physicalDevice_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  uint32_t family_ = 0;
  VkQueue queue_ = VK_NULL_HANDLE;  // the binding's queue
  VkPhysicalDeviceMemoryProperties memory_{};
  std::string deviceName_, deviceType_;
  VkCommandPool pool_ = VK_NULL_HANDLE;  // the skinning copies' command buffers
  MappedBuffer vertices_, indices_;      // the target's mesh (uploadMesh)
  std::vector<Slot> slots_;
  size_t nextSlot_ = 0;  // the oldest slot, waited on when all are in flight
};

}  // namespace sdfg::frame_cost
