#include "vulkan_app.h"

#include <algorithm>
#include <cstring>

namespace sdfg::frame_cost {

namespace {

template <class F>
F xrFn(XrInstance instance, const char* name) {
  PFN_xrVoidFunction f = nullptr;
  if (xrGetInstanceProcAddr(instance, name, &f) != XR_SUCCESS) return nullptr;
  return reinterpret_cast<F>(f);
}

const char* typeName(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return "integrated-gpu";
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return "discrete-gpu";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return "virtual-gpu";
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return "cpu";
    default:
      return "other";
  }
}

bool failed(std::string& error, const std::string& what, VkResult r) {
  error = what + " failed (VkResult " + std::to_string(int(r)) + ")";
  return false;
}

}  // namespace

VulkanApp::~VulkanApp() {
  destroy();
}

bool VulkanApp::create(XrInstance instance, XrSystemId system, std::string& error) {
  auto requirements = xrFn<PFN_xrGetVulkanGraphicsRequirements2KHR>(
      instance, "xrGetVulkanGraphicsRequirements2KHR");
  auto createInstance = xrFn<PFN_xrCreateVulkanInstanceKHR>(instance, "xrCreateVulkanInstanceKHR");
  auto getDevice =
      xrFn<PFN_xrGetVulkanGraphicsDevice2KHR>(instance, "xrGetVulkanGraphicsDevice2KHR");
  auto createDevice = xrFn<PFN_xrCreateVulkanDeviceKHR>(instance, "xrCreateVulkanDeviceKHR");
  if (!requirements || !createInstance || !getDevice || !createDevice) {
    error = "the runtime lacks XR_KHR_vulkan_enable2's functions";
    return false;
  }
  // The spec requires the call before creating the instance; its versions fit Vulkan 1.1.
  XrGraphicsRequirementsVulkan2KHR req{XR_TYPE_GRAPHICS_REQUIREMENTS_VULKAN2_KHR};
  if (requirements(instance, system, &req) != XR_SUCCESS) {
    error = "xrGetVulkanGraphicsRequirements2KHR failed";
    return false;
  }
  VkApplicationInfo appInfo{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  appInfo.pApplicationName = "autograsp-frame-cost";
  appInfo.apiVersion = VK_API_VERSION_1_1;
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &appInfo;
  XrVulkanInstanceCreateInfoKHR xi{XR_TYPE_VULKAN_INSTANCE_CREATE_INFO_KHR};
  xi.systemId = system;
  xi.pfnGetInstanceProcAddr = &vkGetInstanceProcAddr;
  xi.vulkanCreateInfo = &ici;
  VkResult vr = VK_ERROR_UNKNOWN;
  if (createInstance(instance, &xi, &instance_, &vr) != XR_SUCCESS || vr != VK_SUCCESS)
    return failed(error, "xrCreateVulkanInstanceKHR (is there a Vulkan driver? VK_DRIVER_FILES)",
                  vr);
  XrVulkanGraphicsDeviceGetInfoKHR gi{XR_TYPE_VULKAN_GRAPHICS_DEVICE_GET_INFO_KHR};
  gi.systemId = system;
  gi.vulkanInstance = instance_;
  if (getDevice(instance, &gi, &physicalDevice_) != XR_SUCCESS) {
    error = "xrGetVulkanGraphicsDevice2KHR failed (no physical device?)";
    return false;
  }
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(physicalDevice_, &props);
  deviceName_ = props.deviceName;
  deviceType_ = typeName(props.deviceType);
  vkGetPhysicalDeviceMemoryProperties(physicalDevice_, &memory_);

  uint32_t familyCount = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice_, &familyCount, nullptr);
  std::vector<VkQueueFamilyProperties> families(familyCount);
  vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice_, &familyCount, families.data());
  // A renderer's queue: graphics and compute (the layer's builds run on it).
  const VkQueueFlags want = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
  while (family_ < familyCount && (families[family_].queueFlags & want) != want) ++family_;
  if (family_ == familyCount) {
    error = "the device " + deviceName_ + " has no graphics and compute queue family";
    return false;
  }
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo qi{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qi.queueFamilyIndex = family_;
  qi.queueCount = 1;
  qi.pQueuePriorities = &priority;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qi;
  XrVulkanDeviceCreateInfoKHR xd{XR_TYPE_VULKAN_DEVICE_CREATE_INFO_KHR};
  xd.systemId = system;
  xd.pfnGetInstanceProcAddr = &vkGetInstanceProcAddr;
  xd.vulkanPhysicalDevice = physicalDevice_;
  xd.vulkanCreateInfo = &dci;
  vr = VK_ERROR_UNKNOWN;
  if (createDevice(instance, &xd, &device_, &vr) != XR_SUCCESS || vr != VK_SUCCESS)
    return failed(error, "xrCreateVulkanDeviceKHR on " + deviceName_, vr);
  vkGetDeviceQueue(device_, family_, 0, &queue_);
  VkCommandPoolCreateInfo pi{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pi.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pi.queueFamilyIndex = family_;
  if (VkResult r = vkCreateCommandPool(device_, &pi, nullptr, &pool_); r != VK_SUCCESS)
    return failed(error, "vkCreateCommandPool", r);
  return true;
}

XrGraphicsBindingVulkan2KHR VulkanApp::binding() const {
  XrGraphicsBindingVulkan2KHR b{XR_TYPE_GRAPHICS_BINDING_VULKAN2_KHR};
  b.instance = instance_;
  b.physicalDevice = physicalDevice_;
  b.device = device_;
  b.queueFamilyIndex = family_;
  b.queueIndex = 0;
  return b;
}

bool VulkanApp::createBuffer(VkDeviceSize bytes, VkBufferUsageFlags usage, MappedBuffer& out) {
  VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bi.size = bytes;
  bi.usage = usage;
  bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;  // only the binding's family uses it
  if (vkCreateBuffer(device_, &bi, nullptr, &out.buffer) != VK_SUCCESS) return false;
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device_, out.buffer, &req);
  const VkMemoryPropertyFlags want =
      VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  uint32_t type = 0;
  while (type < memory_.memoryTypeCount &&
         (!(req.memoryTypeBits & (1u << type)) ||
          (memory_.memoryTypes[type].propertyFlags & want) != want))
    ++type;
  VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  ai.allocationSize = req.size;
  ai.memoryTypeIndex = type;
  out.size = bytes;
  if (type == memory_.memoryTypeCount ||
      vkAllocateMemory(device_, &ai, nullptr, &out.memory) != VK_SUCCESS ||
      vkBindBufferMemory(device_, out.buffer, out.memory, 0) != VK_SUCCESS ||
      vkMapMemory(device_, out.memory, 0, VK_WHOLE_SIZE, 0, &out.mapped) != VK_SUCCESS) {
    freeBuffer(out);
    return false;
  }
  return true;
}

void VulkanApp::freeBuffer(MappedBuffer& b) {
  if (b.buffer != VK_NULL_HANDLE) vkDestroyBuffer(device_, b.buffer, nullptr);
  if (b.memory != VK_NULL_HANDLE) vkFreeMemory(device_, b.memory, nullptr);
  b = MappedBuffer{};
}

bool VulkanApp::uploadMesh(const Object& o, XrGraspTargetVulkanBuffersSDFG& desc,
                           std::string& error) {
  const VkDeviceSize vertexBytes = o.vertices.size() * sizeof(XrVector3f);
  const VkDeviceSize indexBytes = o.indices.size() * sizeof(uint32_t);
  // TRANSFER_DST: the deforming phase copies new positions in (writeVertices).
  if (!createBuffer(vertexBytes,
                    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                    vertices_) ||
      !createBuffer(indexBytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, indices_)) {
    error = "cannot make host-visible storage buffers of " +
            std::to_string(vertexBytes + indexBytes) + " bytes on " + deviceName_;
    return false;
  }
  // Nothing reads them yet: written through the mapping (coherent, so the target's first build,
  // submitted later, sees them).
  std::memcpy(vertices_.mapped, o.vertices.data(), vertexBytes);
  std::memcpy(indices_.mapped, o.indices.data(), indexBytes);
  XrVector3f lo{1e30f, 1e30f, 1e30f}, hi{-1e30f, -1e30f, -1e30f};
  for (const XrVector3f& p : o.vertices) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  desc = XrGraspTargetVulkanBuffersSDFG{XR_TYPE_GRASP_TARGET_VULKAN_BUFFERS_SDFG};
  desc.vertexBuffer = vertices_.buffer;
  desc.vertexOffset = 0;
  desc.vertexStride = sizeof(XrVector3f);
  desc.vertexCount = uint32_t(o.vertices.size());
  desc.indexBuffer = indices_.buffer;
  desc.indexOffset = 0;
  desc.indexType = VK_INDEX_TYPE_UINT32;
  desc.indexCount = uint32_t(o.indices.size());
  desc.boundsMin = lo;
  desc.boundsMax = hi;
  return true;
}

VulkanApp::Slot* VulkanApp::freeSlot(std::string& error) {
  for (Slot& s : slots_)
    if (vkGetFenceStatus(device_, s.fence) == VK_SUCCESS) return &s;
  if (slots_.size() < kMaxSlots) {
    Slot s;
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = pool_;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    VkFenceCreateInfo fi{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    fi.flags = VK_FENCE_CREATE_SIGNALED_BIT;
    if (!createBuffer(vertices_.size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, s.staging) ||
        vkAllocateCommandBuffers(device_, &ai, &s.commands) != VK_SUCCESS ||
        vkCreateFence(device_, &fi, nullptr, &s.fence) != VK_SUCCESS) {
      freeBuffer(s.staging);
      if (s.commands != VK_NULL_HANDLE) vkFreeCommandBuffers(device_, pool_, 1, &s.commands);
      error = "cannot make a staging buffer for the vertices";
      return nullptr;
    }
    slots_.push_back(s);
    return &slots_.back();
  }
  Slot& oldest = slots_[nextSlot_];
  nextSlot_ = (nextSlot_ + 1) % slots_.size();
  if (VkResult r = vkWaitForFences(device_, 1, &oldest.fence, VK_TRUE, UINT64_MAX);
      r != VK_SUCCESS) {
    failed(error, "vkWaitForFences (staging)", r);
    return nullptr;
  }
  return &oldest;
}

bool VulkanApp::writeVertices(const std::vector<XrVector3f>& vertices, std::string& error) {
  const VkDeviceSize bytes = vertices.size() * sizeof(XrVector3f);
  if (vertices_.buffer == VK_NULL_HANDLE || bytes != vertices_.size) {
    error = "writeVertices: no mesh, or another vertex count";
    return false;
  }
  Slot* slot = freeSlot(error);
  if (slot == nullptr) return false;
  std::memcpy(slot->staging.mapped, vertices.data(), bytes);
  vkResetFences(device_, 1, &slot->fence);
  vkResetCommandBuffer(slot->commands, 0);
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vkBeginCommandBuffer(slot->commands, &begin);
  // Write after read: the layer's builds submitted earlier on this queue (its compute passes,
  // and any copy it makes of the buffer) finish reading the old positions before the copy.
  VkMemoryBarrier before{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  vkCmdPipelineBarrier(slot->commands,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                       VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &before, 0, nullptr, 0, nullptr);
  VkBufferCopy region{0, 0, bytes};
  vkCmdCopyBuffer(slot->commands, slot->staging.buffer, vertices_.buffer, 1, &region);
  // Read after write: the builds the layer submits later on this queue (from this frame's
  // xrEndFrame on) read the new positions.
  VkMemoryBarrier after{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  after.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  after.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT;
  vkCmdPipelineBarrier(slot->commands, VK_PIPELINE_STAGE_TRANSFER_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1,
                       &after, 0, nullptr, 0, nullptr);
  if (VkResult r = vkEndCommandBuffer(slot->commands); r != VK_SUCCESS)
    return failed(error, "vkEndCommandBuffer", r);
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &slot->commands;
  if (VkResult r = vkQueueSubmit(queue_, 1, &submit, slot->fence); r != VK_SUCCESS)
    return failed(error, "vkQueueSubmit (vertex copy)", r);
  return true;
}

void VulkanApp::destroy() {
  if (device_ != VK_NULL_HANDLE) {
    vkDeviceWaitIdle(device_);
    for (Slot& s : slots_) {
      freeBuffer(s.staging);
      vkDestroyFence(device_, s.fence, nullptr);
    }
    slots_.clear();
    freeBuffer(vertices_);
    freeBuffer(indices_);
    if (pool_ != VK_NULL_HANDLE) vkDestroyCommandPool(device_, pool_, nullptr);
    pool_ = VK_NULL_HANDLE;
    vkDestroyDevice(device_, nullptr);
    device_ = VK_NULL_HANDLE;
  }
  if (instance_ != VK_NULL_HANDLE) vkDestroyInstance(instance_, nullptr);
  instance_ = VK_NULL_HANDLE;
}

}  // namespace sdfg::frame_cost
