// XR_KHR_vulkan_enable and XR_KHR_vulkan_enable2, and the runtime's Vulkan work on the app's
// device: swapchain images, their initial layout, and the copy of submitted images to memory.
//
// Queue rule (XR_KHR_vulkan_enable): the runtime may use the app's queue only inside
// xrBeginFrame, xrEndFrame, xrAcquireSwapchainImage and xrReleaseSwapchainImage. Layout
// transitions therefore happen at the first acquire of each image, captures in xrEndFrame;
// both wait on a fence before returning, so nothing of ours is in flight outside those calls.
#include <cstring>

#include "entry_points.h"
#include "system_constants.h"

namespace sdfg::mock {

struct VulkanContext {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physicalDevice = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  uint32_t queueFamily = 0;
  VkQueue queue = VK_NULL_HANDLE;  // the app's queue (binding), used as above
  VkPhysicalDeviceMemoryProperties memory{};
  VkCommandPool pool = VK_NULL_HANDLE;        // runtime-owned, on the binding's family
  VkCommandBuffer commands = VK_NULL_HANDLE;  // re-recorded for each one-shot submission
  VkFence fence = VK_NULL_HANDLE;             // one-shot submissions finish before we return
  VkBuffer readback = VK_NULL_HANDLE;         // host-visible target of image captures
  VkDeviceMemory readbackMemory = VK_NULL_HANDLE;
  VkDeviceSize readbackSize = 0;
  std::vector<int64_t> formats;  // xrEnumerateSwapchainFormats: what this device can make
};

namespace {

bool findMemoryType(const VulkanContext& vk, uint32_t typeBits, VkMemoryPropertyFlags wanted,
                    uint32_t* out) {
  for (uint32_t i = 0; i < vk.memory.memoryTypeCount; ++i) {
    if ((typeBits & (1u << i)) && (vk.memory.memoryTypes[i].propertyFlags & wanted) == wanted) {
      *out = i;
      return true;
    }
  }
  return false;
}

VkImageAspectFlags aspectOf(VkFormat f) {
  if (f == VK_FORMAT_D24_UNORM_S8_UINT || f == VK_FORMAT_D32_SFLOAT_S8_UINT)
    return VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT;
  return isDepthFormat(f) ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
}

// Records into the context's command buffer, submits it on the app's queue and waits.
template <class Record>
VkResult submitAndWait(VulkanContext& vk, Record record) {
  VkResult r = vkResetCommandBuffer(vk.commands, 0);
  if (r != VK_SUCCESS) return r;
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  if ((r = vkBeginCommandBuffer(vk.commands, &begin)) != VK_SUCCESS) return r;
  record(vk.commands);
  if ((r = vkEndCommandBuffer(vk.commands)) != VK_SUCCESS) return r;
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &vk.commands;
  if ((r = vkQueueSubmit(vk.queue, 1, &submit, vk.fence)) != VK_SUCCESS) return r;
  r = vkWaitForFences(vk.device, 1, &vk.fence, VK_TRUE, UINT64_MAX);
  vkResetFences(vk.device, 1, &vk.fence);
  return r;
}

XrResult pickPhysicalDevice(const char* cmd, Instance& instance, VkInstance vkInstance,
                            VkPhysicalDevice* out) {
  uint32_t count = 0;
  if (vkEnumeratePhysicalDevices(vkInstance, &count, nullptr) != VK_SUCCESS || count == 0)
    return fail(cmd, XR_ERROR_RUNTIME_FAILURE, "the Vulkan instance has no physical device");
  std::vector<VkPhysicalDevice> devices(count);
  vkEnumeratePhysicalDevices(vkInstance, &count, devices.data());
  // Any device will do; the tests pin lavapipe with VK_ICD_FILENAMES.
  *out = devices[0];
  instance.lastPhysicalDevice = devices[0];
  instance.lastVkInstance = vkInstance;
  return XR_SUCCESS;
}

XrResult verifySystemId(const char* cmd, const Instance& instance, XrSystemId systemId) {
  if (systemId != kSystemId || !instance.systemFetched)
    return fail(cmd, XR_ERROR_SYSTEM_INVALID, "systemId %llu", (unsigned long long)systemId);
  return XR_SUCCESS;
}

// Preferred first, as the spec asks: sRGB colour, then UNORM, then depth. D32_SFLOAT is offered
// as it always was (Vulkan guarantees it or X8_D24 as an attachment, and every device the tests
// meet has it); the others only where the device can attach them, since an app that picks an
// offered format must be able to render into it.
std::vector<int64_t> offeredFormats(VkPhysicalDevice device) {
  std::vector<int64_t> formats = {VK_FORMAT_R8G8B8A8_SRGB, VK_FORMAT_B8G8R8A8_SRGB,
                                  VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_B8G8R8A8_UNORM,
                                  VK_FORMAT_D32_SFLOAT};
  for (VkFormat f :
       {VK_FORMAT_D16_UNORM, VK_FORMAT_D24_UNORM_S8_UINT, VK_FORMAT_D32_SFLOAT_S8_UINT}) {
    VkFormatProperties props{};
    vkGetPhysicalDeviceFormatProperties(device, f, &props);
    if (props.optimalTilingFeatures & VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT)
      formats.push_back(f);
  }
  return formats;
}

}  // namespace

const std::vector<int64_t>& vulkanSwapchainFormats(const Session& session) {
  return session.vulkan->formats;
}

XrResult createVulkanContext(const char* cmd, Instance& instance,
                             const XrGraphicsBindingVulkanKHR& binding, VulkanContextPtr& out) {
  if (binding.instance == VK_NULL_HANDLE || binding.physicalDevice == VK_NULL_HANDLE ||
      binding.device == VK_NULL_HANDLE)
    return fail(cmd, XR_ERROR_GRAPHICS_DEVICE_INVALID, "null Vulkan handle in the binding");
  if (instance.lastPhysicalDevice != VK_NULL_HANDLE &&
      binding.physicalDevice != instance.lastPhysicalDevice)
    return fail(cmd, XR_ERROR_GRAPHICS_DEVICE_INVALID,
                "physicalDevice is not the one xrGetVulkanGraphicsDevice(2)KHR returned");
  uint32_t familyCount = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(binding.physicalDevice, &familyCount, nullptr);
  std::vector<VkQueueFamilyProperties> families(familyCount);
  vkGetPhysicalDeviceQueueFamilyProperties(binding.physicalDevice, &familyCount, families.data());
  if (binding.queueFamilyIndex >= familyCount ||
      binding.queueIndex >= families[binding.queueFamilyIndex].queueCount)
    return fail(cmd, XR_ERROR_GRAPHICS_DEVICE_INVALID, "queue %u of family %u does not exist",
                binding.queueIndex, binding.queueFamilyIndex);

  VulkanContextPtr vk(new VulkanContext);
  vk->instance = binding.instance;
  vk->physicalDevice = binding.physicalDevice;
  vk->device = binding.device;
  vk->queueFamily = binding.queueFamilyIndex;
  vkGetDeviceQueue(vk->device, binding.queueFamilyIndex, binding.queueIndex, &vk->queue);
  vkGetPhysicalDeviceMemoryProperties(vk->physicalDevice, &vk->memory);
  vk->formats = offeredFormats(vk->physicalDevice);
  VkCommandPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  poolInfo.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  poolInfo.queueFamilyIndex = vk->queueFamily;
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  VkFenceCreateInfo fenceInfo{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  if (vkCreateCommandPool(vk->device, &poolInfo, nullptr, &vk->pool) != VK_SUCCESS ||
      (alloc.commandPool = vk->pool, vkAllocateCommandBuffers(vk->device, &alloc, &vk->commands)) !=
          VK_SUCCESS ||
      vkCreateFence(vk->device, &fenceInfo, nullptr, &vk->fence) != VK_SUCCESS) {
    return fail(cmd, XR_ERROR_RUNTIME_FAILURE, "cannot create the runtime's command pool or fence");
  }
  out = std::move(vk);
  return XR_SUCCESS;
}

void VulkanContextDeleter::operator()(VulkanContext* context) const {
  destroyVulkanContext(context);
  delete context;
}

void destroyVulkanContext(VulkanContext* vk) {
  if (vk->readback != VK_NULL_HANDLE) vkDestroyBuffer(vk->device, vk->readback, nullptr);
  if (vk->readbackMemory != VK_NULL_HANDLE) vkFreeMemory(vk->device, vk->readbackMemory, nullptr);
  if (vk->fence != VK_NULL_HANDLE) vkDestroyFence(vk->device, vk->fence, nullptr);
  if (vk->commands != VK_NULL_HANDLE) vkFreeCommandBuffers(vk->device, vk->pool, 1, &vk->commands);
  if (vk->pool != VK_NULL_HANDLE) vkDestroyCommandPool(vk->device, vk->pool, nullptr);
  *vk = VulkanContext{};
}

XrResult createVulkanImages(const char* cmd, Swapchain& sc) {
  VulkanContext& vk = *sc.session->vulkan;
  const XrSwapchainCreateInfo& info = sc.info;
  const VkFormat format = VkFormat(info.format);
  VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ci.flags = (info.usageFlags & XR_SWAPCHAIN_USAGE_MUTABLE_FORMAT_BIT)
                 ? VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT
                 : 0;
  ci.imageType = VK_IMAGE_TYPE_2D;
  ci.format = format;
  ci.extent = {info.width, info.height, 1};
  ci.mipLevels = info.mipCount;
  ci.arrayLayers = info.arraySize;
  ci.samples = VK_SAMPLE_COUNT_1_BIT;
  ci.tiling = VK_IMAGE_TILING_OPTIMAL;
  // TRANSFER_SRC is ours: captures copy the submitted image to memory.
  ci.usage = VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  if (info.usageFlags & XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT)
    ci.usage |= VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
  if (info.usageFlags & XR_SWAPCHAIN_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT)
    ci.usage |= VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
  if (info.usageFlags & XR_SWAPCHAIN_USAGE_UNORDERED_ACCESS_BIT)
    ci.usage |= VK_IMAGE_USAGE_STORAGE_BIT;
  if (info.usageFlags & XR_SWAPCHAIN_USAGE_TRANSFER_DST_BIT)
    ci.usage |= VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  if (info.usageFlags & XR_SWAPCHAIN_USAGE_SAMPLED_BIT) ci.usage |= VK_IMAGE_USAGE_SAMPLED_BIT;
  if (info.usageFlags & XR_SWAPCHAIN_USAGE_INPUT_ATTACHMENT_BIT_MND)
    ci.usage |= VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT;
  ci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  ci.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;

  VkImageFormatProperties props{};
  if (vkGetPhysicalDeviceImageFormatProperties(vk.physicalDevice, format, ci.imageType, ci.tiling,
                                               ci.usage, ci.flags, &props) != VK_SUCCESS ||
      props.maxArrayLayers < info.arraySize || props.maxMipLevels < info.mipCount)
    return fail(cmd, XR_ERROR_FEATURE_UNSUPPORTED, "the device cannot make such an image");

  for (uint32_t i = 0; i < sc.imageCount; ++i) {
    VkImage image = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    if (vkCreateImage(vk.device, &ci, nullptr, &image) != VK_SUCCESS) {
      destroyVulkanImages(sc);
      return fail(cmd, XR_ERROR_RUNTIME_FAILURE, "vkCreateImage failed");
    }
    sc.images.push_back(image);
    VkMemoryRequirements req{};
    vkGetImageMemoryRequirements(vk.device, image, &req);
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = req.size;
    if (!findMemoryType(vk, req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT,
                        &ai.memoryTypeIndex) &&
        !findMemoryType(vk, req.memoryTypeBits, 0, &ai.memoryTypeIndex)) {
      destroyVulkanImages(sc);
      return fail(cmd, XR_ERROR_RUNTIME_FAILURE, "no memory type for the image");
    }
    if (vkAllocateMemory(vk.device, &ai, nullptr, &memory) != VK_SUCCESS) {
      destroyVulkanImages(sc);
      return fail(cmd, XR_ERROR_OUT_OF_MEMORY, "vkAllocateMemory failed");
    }
    sc.memory.push_back(memory);
    if (vkBindImageMemory(vk.device, image, memory, 0) != VK_SUCCESS) {
      destroyVulkanImages(sc);
      return fail(cmd, XR_ERROR_RUNTIME_FAILURE, "vkBindImageMemory failed");
    }
  }
  sc.layoutReady.assign(sc.imageCount, false);
  return XR_SUCCESS;
}

void destroyVulkanImages(Swapchain& sc) {
  if (!sc.session->vulkan) return;
  VulkanContext& vk = *sc.session->vulkan;
  // The app's last frames may still read or write the images.
  if (!sc.images.empty()) vkQueueWaitIdle(vk.queue);
  for (VkImage image : sc.images) vkDestroyImage(vk.device, image, nullptr);
  for (VkDeviceMemory memory : sc.memory) vkFreeMemory(vk.device, memory, nullptr);
  sc.images.clear();
  sc.memory.clear();
}

XrResult prepareVulkanImage(const char* cmd, Swapchain& sc, uint32_t index) {
  if (!sc.session->vulkan || sc.layoutReady[index]) return XR_SUCCESS;
  if (sc.session->instance->options.fault == "skip_layout_transition") {
    sc.layoutReady[index] = true;
    return XR_SUCCESS;
  }
  VulkanContext& vk = *sc.session->vulkan;
  const VkFormat format = VkFormat(sc.info.format);
  const bool depth = isDepthFormat(format);
  const VkResult r = submitAndWait(vk, [&](VkCommandBuffer cb) {
    // UNDEFINED -> the layout XR_KHR_vulkan_enable promises after xrWaitSwapchainImage;
    // orders the transition before anything the app records on this queue later.
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcAccessMask = 0;
    b.dstAccessMask =
        depth ? VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                    VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT
              : VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
    b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    b.newLayout = depth ? VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL
                        : VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = sc.images[index];
    b.subresourceRange = {aspectOf(format), 0, sc.info.mipCount, 0, sc.info.arraySize};
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                         0, 0, nullptr, 0, nullptr, 1, &b);
  });
  if (r != VK_SUCCESS)
    return fail(cmd, XR_ERROR_RUNTIME_FAILURE, "layout transition failed: %d", int(r));
  sc.layoutReady[index] = true;
  return XR_SUCCESS;
}

bool captureVulkanImage(Session& session, Swapchain& sc, uint32_t index, uint32_t layer,
                        CapturedImage& out) {
  VulkanContext& vk = *session.vulkan;
  const VkFormat format = VkFormat(sc.info.format);
  const bool bgra = format == VK_FORMAT_B8G8R8A8_SRGB || format == VK_FORMAT_B8G8R8A8_UNORM;
  const bool rgba = format == VK_FORMAT_R8G8B8A8_SRGB || format == VK_FORMAT_R8G8B8A8_UNORM;
  if (!bgra && !rgba) return false;
  const VkDeviceSize size = VkDeviceSize(sc.info.width) * sc.info.height * 4;
  if (vk.readbackSize < size) {
    if (vk.readback != VK_NULL_HANDLE) vkDestroyBuffer(vk.device, vk.readback, nullptr);
    if (vk.readbackMemory != VK_NULL_HANDLE) vkFreeMemory(vk.device, vk.readbackMemory, nullptr);
    vk.readback = VK_NULL_HANDLE;
    vk.readbackMemory = VK_NULL_HANDLE;
    vk.readbackSize = 0;
    VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bi.size = size;
    bi.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    if (vkCreateBuffer(vk.device, &bi, nullptr, &vk.readback) != VK_SUCCESS) return false;
    VkMemoryRequirements req{};
    vkGetBufferMemoryRequirements(vk.device, vk.readback, &req);
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = req.size;
    if (!findMemoryType(vk, req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT,
                        &ai.memoryTypeIndex) ||
        vkAllocateMemory(vk.device, &ai, nullptr, &vk.readbackMemory) != VK_SUCCESS ||
        vkBindBufferMemory(vk.device, vk.readback, vk.readbackMemory, 0) != VK_SUCCESS)
      return false;
    vk.readbackSize = size;
  }
  const VkImage image = sc.images[index];
  const VkResult r = submitAndWait(vk, [&](VkCommandBuffer cb) {
    // The app's rendering, submitted earlier on this queue, must finish writing before the copy.
    VkImageMemoryBarrier toSrc{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    toSrc.srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
    toSrc.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    toSrc.oldLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    toSrc.newLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    toSrc.srcQueueFamilyIndex = toSrc.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    toSrc.image = image;
    toSrc.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, layer, 1};
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                         VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0, nullptr, 1, &toSrc);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, layer, 1};
    region.imageExtent = {sc.info.width, sc.info.height, 1};
    vkCmdCopyImageToBuffer(cb, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, vk.readback, 1,
                           &region);
    // Back to the layout the app owns; its next rendering waits for our read to finish.
    VkImageMemoryBarrier back = toSrc;
    back.srcAccessMask = 0;
    back.dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
    back.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    back.newLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    // The copy's writes must be visible to the host read after the fence.
    VkBufferMemoryBarrier toHost{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
    toHost.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    toHost.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    toHost.srcQueueFamilyIndex = toHost.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    toHost.buffer = vk.readback;
    toHost.size = VK_WHOLE_SIZE;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT,
                         VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_HOST_BIT,
                         0, 0, nullptr, 1, &toHost, 1, &back);
  });
  if (r != VK_SUCCESS) return false;
  void* mapped = nullptr;
  if (vkMapMemory(vk.device, vk.readbackMemory, 0, VK_WHOLE_SIZE, 0, &mapped) != VK_SUCCESS)
    return false;
  VkMappedMemoryRange range{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE};
  range.memory = vk.readbackMemory;
  range.size = VK_WHOLE_SIZE;
  vkInvalidateMappedMemoryRanges(vk.device, 1, &range);
  out.width = sc.info.width;
  out.height = sc.info.height;
  out.rgba.resize(size_t(size));
  std::memcpy(out.rgba.data(), mapped, size_t(size));
  vkUnmapMemory(vk.device, vk.readbackMemory);
  if (bgra) {
    for (size_t i = 0; i + 3 < out.rgba.size(); i += 4) std::swap(out.rgba[i], out.rgba[i + 2]);
  }
  return true;
}

XrResult getVulkanGraphicsRequirements(XrInstance handle, XrSystemId systemId,
                                       XrGraphicsRequirementsVulkanKHR* requirements) {
  constexpr const char* cmd = "xrGetVulkanGraphicsRequirements(2)KHR";
  Instance* instance = lookup<Instance>(handle);
  if (instance == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "instance is not valid");
  if (XrResult r = verifySystemId(cmd, *instance, systemId); r != XR_SUCCESS) return r;
  MOCK_VERIFY_TYPE(cmd, requirements, XR_TYPE_GRAPHICS_REQUIREMENTS_VULKAN_KHR);
  requirements->minApiVersionSupported = XR_MAKE_VERSION(1, 0, 0);
  requirements->maxApiVersionSupported = XR_MAKE_VERSION(1, 3, 0);
  instance->graphicsRequirementsQueried = true;
  return XR_SUCCESS;
}

// The runtime needs no Vulkan extensions; an empty list is still the string "" (count 1).
XrResult getVulkanInstanceExtensions(XrInstance handle, XrSystemId systemId, uint32_t capacity,
                                     uint32_t* countOutput, char* buffer) {
  constexpr const char* cmd = "xrGetVulkanInstanceExtensionsKHR";
  Instance* instance = lookup<Instance>(handle);
  if (instance == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "instance is not valid");
  if (XrResult r = verifySystemId(cmd, *instance, systemId); r != XR_SUCCESS) return r;
  return twoCallString(cmd, capacity, countOutput, buffer, "");
}

XrResult getVulkanDeviceExtensions(XrInstance handle, XrSystemId systemId, uint32_t capacity,
                                   uint32_t* countOutput, char* buffer) {
  constexpr const char* cmd = "xrGetVulkanDeviceExtensionsKHR";
  Instance* instance = lookup<Instance>(handle);
  if (instance == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "instance is not valid");
  if (XrResult r = verifySystemId(cmd, *instance, systemId); r != XR_SUCCESS) return r;
  return twoCallString(cmd, capacity, countOutput, buffer, "");
}

XrResult getVulkanGraphicsDevice(XrInstance handle, XrSystemId systemId, VkInstance vkInstance,
                                 VkPhysicalDevice* physicalDevice) {
  constexpr const char* cmd = "xrGetVulkanGraphicsDeviceKHR";
  Instance* instance = lookup<Instance>(handle);
  if (instance == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "instance is not valid");
  if (XrResult r = verifySystemId(cmd, *instance, systemId); r != XR_SUCCESS) return r;
  MOCK_VERIFY_NOT_NULL(cmd, vkInstance);
  MOCK_VERIFY_NOT_NULL(cmd, physicalDevice);
  return pickPhysicalDevice(cmd, *instance, vkInstance, physicalDevice);
}

XrResult getVulkanGraphicsDevice2(XrInstance handle, const XrVulkanGraphicsDeviceGetInfoKHR* info,
                                  VkPhysicalDevice* physicalDevice) {
  constexpr const char* cmd = "xrGetVulkanGraphicsDevice2KHR";
  Instance* instance = lookup<Instance>(handle);
  if (instance == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "instance is not valid");
  MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_VULKAN_GRAPHICS_DEVICE_GET_INFO_KHR);
  if (XrResult r = verifySystemId(cmd, *instance, info->systemId); r != XR_SUCCESS) return r;
  MOCK_VERIFY_NOT_NULL(cmd, info->vulkanInstance);
  MOCK_VERIFY_NOT_NULL(cmd, physicalDevice);
  return pickPhysicalDevice(cmd, *instance, info->vulkanInstance, physicalDevice);
}

XrResult createVulkanInstance(XrInstance handle, const XrVulkanInstanceCreateInfoKHR* info,
                              VkInstance* vkInstance, VkResult* vkResult) {
  constexpr const char* cmd = "xrCreateVulkanInstanceKHR";
  Instance* instance = lookup<Instance>(handle);
  if (instance == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "instance is not valid");
  MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_VULKAN_INSTANCE_CREATE_INFO_KHR);
  if (XrResult r = verifySystemId(cmd, *instance, info->systemId); r != XR_SUCCESS) return r;
  if (info->createFlags != 0)
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "createFlags must be 0");
  MOCK_VERIFY_NOT_NULL(cmd, info->pfnGetInstanceProcAddr);
  MOCK_VERIFY_NOT_NULL(cmd, info->vulkanCreateInfo);
  MOCK_VERIFY_NOT_NULL(cmd, vkInstance);
  MOCK_VERIFY_NOT_NULL(cmd, vkResult);
  auto create = reinterpret_cast<PFN_vkCreateInstance>(
      info->pfnGetInstanceProcAddr(nullptr, "vkCreateInstance"));
  if (create == nullptr) return fail(cmd, XR_ERROR_RUNTIME_FAILURE, "no vkCreateInstance");
  *vkResult = create(info->vulkanCreateInfo, info->vulkanAllocator, vkInstance);
  return XR_SUCCESS;
}

XrResult createVulkanDevice(XrInstance handle, const XrVulkanDeviceCreateInfoKHR* info,
                            VkDevice* vkDevice, VkResult* vkResult) {
  constexpr const char* cmd = "xrCreateVulkanDeviceKHR";
  Instance* instance = lookup<Instance>(handle);
  if (instance == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "instance is not valid");
  MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_VULKAN_DEVICE_CREATE_INFO_KHR);
  if (XrResult r = verifySystemId(cmd, *instance, info->systemId); r != XR_SUCCESS) return r;
  if (info->createFlags != 0)
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "createFlags must be 0");
  MOCK_VERIFY_NOT_NULL(cmd, info->pfnGetInstanceProcAddr);
  MOCK_VERIFY_NOT_NULL(cmd, info->vulkanPhysicalDevice);
  MOCK_VERIFY_NOT_NULL(cmd, info->vulkanCreateInfo);
  MOCK_VERIFY_NOT_NULL(cmd, vkDevice);
  MOCK_VERIFY_NOT_NULL(cmd, vkResult);
  if (instance->lastPhysicalDevice != VK_NULL_HANDLE &&
      info->vulkanPhysicalDevice != instance->lastPhysicalDevice)
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE,
                "vulkanPhysicalDevice is not the one xrGetVulkanGraphicsDevice2KHR returned");
  // vkCreateDevice is fetched through an instance: the one xrGetVulkanGraphicsDevice2KHR saw.
  if (instance->lastVkInstance == VK_NULL_HANDLE)
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "call xrGetVulkanGraphicsDevice2KHR first");
  auto create = reinterpret_cast<PFN_vkCreateDevice>(
      info->pfnGetInstanceProcAddr(instance->lastVkInstance, "vkCreateDevice"));
  if (create == nullptr) return fail(cmd, XR_ERROR_RUNTIME_FAILURE, "no vkCreateDevice");
  *vkResult =
      create(info->vulkanPhysicalDevice, info->vulkanCreateInfo, info->vulkanAllocator, vkDevice);
  return XR_SUCCESS;
}

}  // namespace sdfg::mock
