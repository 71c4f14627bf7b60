// VK_NO_PROTOTYPES: every Vulkan call goes through the table loaded from the owner's
// vkGetInstanceProcAddr, so a stray direct call fails to link instead of binding to some loader.
#define VK_NO_PROTOTYPES
#include "vulkan/vk_context.h"

#include <string>
#include <vector>

namespace sdfg {

Result<std::unique_ptr<VkContext>> VkContext::create(const VulkanDevice& device) {
  if (device.instance == VK_NULL_HANDLE || device.physicalDevice == VK_NULL_HANDLE ||
      device.device == VK_NULL_HANDLE || device.getInstanceProcAddr == nullptr) {
    return makeError(Status::invalid_argument,
                     "vulkan: instance, physical device, device and vkGetInstanceProcAddr must "
                     "all be given");
  }
  std::unique_ptr<VkContext> ctx(new VkContext());
  ctx->device_ = device;
  VkFunctions& fn = ctx->fn_;
#define SDFG_VK_LOAD_INSTANCE(name)                                                           \
  fn.name = reinterpret_cast<PFN_##name>(device.getInstanceProcAddr(device.instance, #name)); \
  if (fn.name == nullptr) {                                                                   \
    return makeError(Status::unsupported, "vulkan: the loader has no " #name);                \
  }
  SDFG_VK_INSTANCE_FUNCTIONS(SDFG_VK_LOAD_INSTANCE)
#undef SDFG_VK_LOAD_INSTANCE
#define SDFG_VK_LOAD_DEVICE(name)                                                       \
  fn.name = reinterpret_cast<PFN_##name>(fn.vkGetDeviceProcAddr(device.device, #name)); \
  if (fn.name == nullptr) {                                                             \
    return makeError(Status::unsupported, "vulkan: the device has no " #name);          \
  }
  SDFG_VK_DEVICE_FUNCTIONS(SDFG_VK_LOAD_DEVICE)
#undef SDFG_VK_LOAD_DEVICE

  fn.vkGetPhysicalDeviceProperties(device.physicalDevice, &ctx->properties_);
  fn.vkGetPhysicalDeviceMemoryProperties(device.physicalDevice, &ctx->memory_);
  if (ctx->properties_.apiVersion < VK_API_VERSION_1_1) {
    return makeError(Status::unsupported, std::string("vulkan: device '") +
                                              ctx->properties_.deviceName +
                                              "' supports only Vulkan 1.0; 1.1 is required");
  }
  uint32_t familyCount = 0;
  fn.vkGetPhysicalDeviceQueueFamilyProperties(device.physicalDevice, &familyCount, nullptr);
  std::vector<VkQueueFamilyProperties> families(familyCount);
  fn.vkGetPhysicalDeviceQueueFamilyProperties(device.physicalDevice, &familyCount, families.data());
  if (device.queueFamilyIndex >= familyCount ||
      device.queueIndex >= families[device.queueFamilyIndex].queueCount) {
    return makeError(Status::invalid_argument,
                     "vulkan: queue family " + std::to_string(device.queueFamilyIndex) + " index " +
                         std::to_string(device.queueIndex) + " does not exist on this device");
  }
  if ((families[device.queueFamilyIndex].queueFlags & VK_QUEUE_COMPUTE_BIT) == 0) {
    return makeError(Status::unsupported, "vulkan: queue family " +
                                              std::to_string(device.queueFamilyIndex) +
                                              " has no compute support");
  }
  fn.vkGetDeviceQueue(device.device, device.queueFamilyIndex, device.queueIndex, &ctx->queue_);
  return ctx;
}

uint32_t VkContext::findMemoryType(uint32_t typeBits, VkMemoryPropertyFlags required,
                                   VkMemoryPropertyFlags preferred) const {
  uint32_t fallback = UINT32_MAX;
  for (uint32_t i = 0; i < memory_.memoryTypeCount; ++i) {
    const VkMemoryPropertyFlags flags = memory_.memoryTypes[i].propertyFlags;
    if ((typeBits & (1u << i)) == 0 || (flags & required) != required) continue;
    if ((flags & preferred) == preferred) return i;
    if (fallback == UINT32_MAX) fallback = i;
  }
  return fallback;
}

void destroyVk(const VkContext& c, VkBuffer h) {
  c.fn().vkDestroyBuffer(c.handle(), h, nullptr);
}
void destroyVk(const VkContext& c, VkDeviceMemory h) {
  c.fn().vkFreeMemory(c.handle(), h, nullptr);
}
void destroyVk(const VkContext& c, VkShaderModule h) {
  c.fn().vkDestroyShaderModule(c.handle(), h, nullptr);
}
void destroyVk(const VkContext& c, VkDescriptorSetLayout h) {
  c.fn().vkDestroyDescriptorSetLayout(c.handle(), h, nullptr);
}
void destroyVk(const VkContext& c, VkPipelineLayout h) {
  c.fn().vkDestroyPipelineLayout(c.handle(), h, nullptr);
}
void destroyVk(const VkContext& c, VkPipeline h) {
  c.fn().vkDestroyPipeline(c.handle(), h, nullptr);
}
void destroyVk(const VkContext& c, VkDescriptorPool h) {
  c.fn().vkDestroyDescriptorPool(c.handle(), h, nullptr);
}
void destroyVk(const VkContext& c, VkCommandPool h) {
  c.fn().vkDestroyCommandPool(c.handle(), h, nullptr);
}
void destroyVk(const VkContext& c, VkFence h) {
  c.fn().vkDestroyFence(c.handle(), h, nullptr);
}

void destroyVk(const VkContext& c, VkQueryPool h) {
  c.fn().vkDestroyQueryPool(c.handle(), h, nullptr);
}

Result<VkBufferAlloc> createBuffer(const VkContext& ctx, VkDeviceSize size,
                                   VkBufferUsageFlags usage, VkMemoryKind kind) {
  const VkFunctions& fn = ctx.fn();
  VkBufferAlloc out;
  out.size = size;
  auto info = vkStruct<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
  info.size = size;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VkBuffer buffer = VK_NULL_HANDLE;
  if (VkResult r = fn.vkCreateBuffer(ctx.handle(), &info, nullptr, &buffer); r != VK_SUCCESS) {
    return makeError(r == VK_ERROR_DEVICE_LOST ? Status::device_lost : Status::out_of_memory,
                     std::string("vulkan: vkCreateBuffer failed: ") + vkResultName(r));
  }
  out.buffer = VkOwned<VkBuffer>(ctx, buffer);
  VkMemoryRequirements req{};
  fn.vkGetBufferMemoryRequirements(ctx.handle(), buffer, &req);

  VkMemoryPropertyFlags required = 0, preferred = 0;
  switch (kind) {
    case VkMemoryKind::device:
      preferred = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
      break;
    case VkMemoryKind::upload:
      required = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT;
      preferred = VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
      break;
    case VkMemoryKind::readback:
      required = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT;
      preferred = VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
      break;
  }
  const uint32_t type = ctx.findMemoryType(req.memoryTypeBits, required, preferred);
  if (type == UINT32_MAX) {
    return makeError(Status::unsupported, "vulkan: no memory type fits a storage buffer");
  }
  auto alloc = vkStruct<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
  alloc.allocationSize = req.size;
  alloc.memoryTypeIndex = type;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  if (VkResult r = fn.vkAllocateMemory(ctx.handle(), &alloc, nullptr, &memory); r != VK_SUCCESS) {
    return makeError(r == VK_ERROR_DEVICE_LOST ? Status::device_lost : Status::out_of_memory,
                     std::string("vulkan: vkAllocateMemory of ") + std::to_string(req.size) +
                         " bytes failed: " + vkResultName(r));
  }
  out.memory = VkOwned<VkDeviceMemory>(ctx, memory);
  if (VkResult r = fn.vkBindBufferMemory(ctx.handle(), buffer, memory, 0); r != VK_SUCCESS) {
    return makeError(Status::internal,
                     std::string("vulkan: vkBindBufferMemory failed: ") + vkResultName(r));
  }
  const VkMemoryPropertyFlags flags = ctx.memoryProperties().memoryTypes[type].propertyFlags;
  if (flags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) {
    if (VkResult r = fn.vkMapMemory(ctx.handle(), memory, 0, VK_WHOLE_SIZE, 0, &out.mapped);
        r != VK_SUCCESS) {
      return makeError(Status::out_of_memory,
                       std::string("vulkan: vkMapMemory failed: ") + vkResultName(r));
    }
    out.coherent = (flags & VK_MEMORY_PROPERTY_HOST_COHERENT_BIT) != 0;
    out.atomSize = ctx.properties().limits.nonCoherentAtomSize;
  }
  return out;
}

namespace {
VkMappedMemoryRange wholeRange(const VkBufferAlloc& b) {
  auto range = vkStruct<VkMappedMemoryRange>(VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE);
  range.memory = b.memory.get();
  range.offset = 0;
  range.size = VK_WHOLE_SIZE;  // the buffer owns its allocation from offset 0
  return range;
}
}  // namespace

VkResult flushBuffer(const VkContext& ctx, const VkBufferAlloc& b) {
  if (b.coherent || b.mapped == nullptr) return VK_SUCCESS;
  const VkMappedMemoryRange range = wholeRange(b);
  return ctx.fn().vkFlushMappedMemoryRanges(ctx.handle(), 1, &range);
}

VkResult invalidateBuffer(const VkContext& ctx, const VkBufferAlloc& b) {
  if (b.coherent || b.mapped == nullptr) return VK_SUCCESS;
  const VkMappedMemoryRange range = wholeRange(b);
  return ctx.fn().vkInvalidateMappedMemoryRanges(ctx.handle(), 1, &range);
}

const char* vkResultName(VkResult result) {
  switch (result) {
#define SDFG_VK_RESULT(name) \
  case name:                 \
    return #name;
    SDFG_VK_RESULT(VK_SUCCESS)
    SDFG_VK_RESULT(VK_NOT_READY)
    SDFG_VK_RESULT(VK_TIMEOUT)
    SDFG_VK_RESULT(VK_INCOMPLETE)
    SDFG_VK_RESULT(VK_ERROR_OUT_OF_HOST_MEMORY)
    SDFG_VK_RESULT(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    SDFG_VK_RESULT(VK_ERROR_INITIALIZATION_FAILED)
    SDFG_VK_RESULT(VK_ERROR_DEVICE_LOST)
    SDFG_VK_RESULT(VK_ERROR_MEMORY_MAP_FAILED)
    SDFG_VK_RESULT(VK_ERROR_FEATURE_NOT_PRESENT)
    SDFG_VK_RESULT(VK_ERROR_TOO_MANY_OBJECTS)
    SDFG_VK_RESULT(VK_ERROR_UNKNOWN)
#undef SDFG_VK_RESULT
    default:
      return "VkResult error";
  }
}

Error vkCallError(VkResult r, const char* what) {
  return makeError(r == VK_ERROR_OUT_OF_HOST_MEMORY || r == VK_ERROR_OUT_OF_DEVICE_MEMORY
                       ? Status::out_of_memory
                   : r == VK_ERROR_DEVICE_LOST ? Status::device_lost
                                               : Status::internal,
                   std::string("vulkan: ") + what + " failed: " + vkResultName(r));
}

Result<VkOwned<VkPipeline>> createComputePipeline(const VkContext& ctx, VkPipelineLayout layout,
                                                  std::span<const uint32_t> code,
                                                  uint32_t groupSize) {
  const VkFunctions& fn = ctx.fn();
  auto moduleInfo = vkStruct<VkShaderModuleCreateInfo>(VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO);
  moduleInfo.codeSize = code.size_bytes();
  moduleInfo.pCode = code.data();
  VkShaderModule module = VK_NULL_HANDLE;
  if (VkResult r = fn.vkCreateShaderModule(ctx.handle(), &moduleInfo, nullptr, &module))
    return vkCallError(r, "vkCreateShaderModule");
  const VkOwned<VkShaderModule> ownedModule(ctx, module);
  const VkSpecializationMapEntry entry{0, 0, sizeof(uint32_t)};  // constant_id 0: local_size_x
  const VkSpecializationInfo spec{1, &entry, sizeof(uint32_t), &groupSize};
  auto pipeInfo =
      vkStruct<VkComputePipelineCreateInfo>(VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO);
  pipeInfo.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  pipeInfo.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  pipeInfo.stage.module = module;
  pipeInfo.stage.pName = "main";
  pipeInfo.stage.pSpecializationInfo = &spec;
  pipeInfo.layout = layout;
  VkPipeline pipeline = VK_NULL_HANDLE;
  if (VkResult r = fn.vkCreateComputePipelines(ctx.handle(), VK_NULL_HANDLE, 1, &pipeInfo, nullptr,
                                               &pipeline))
    return vkCallError(r, "vkCreateComputePipelines");
  return VkOwned<VkPipeline>(ctx, pipeline);
}

std::optional<Error> createComputeLayouts(const VkContext& ctx, uint32_t bindings,
                                          uint32_t pushBytes,
                                          VkOwned<VkDescriptorSetLayout>& setLayout,
                                          VkOwned<VkPipelineLayout>& pipelineLayout) {
  const VkFunctions& fn = ctx.fn();
  std::vector<VkDescriptorSetLayoutBinding> list(bindings);
  for (uint32_t i = 0; i < bindings; ++i) {
    list[i].binding = i;
    list[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    list[i].descriptorCount = 1;
    list[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
  }
  auto setInfo = vkStruct<VkDescriptorSetLayoutCreateInfo>(
      VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO);
  setInfo.bindingCount = bindings;
  setInfo.pBindings = list.data();
  VkDescriptorSetLayout set = VK_NULL_HANDLE;
  if (VkResult r = fn.vkCreateDescriptorSetLayout(ctx.handle(), &setInfo, nullptr, &set))
    return vkCallError(r, "vkCreateDescriptorSetLayout");
  setLayout = VkOwned<VkDescriptorSetLayout>(ctx, set);
  const VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, pushBytes};
  auto layoutInfo =
      vkStruct<VkPipelineLayoutCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO);
  layoutInfo.setLayoutCount = 1;
  layoutInfo.pSetLayouts = &set;
  layoutInfo.pushConstantRangeCount = 1;
  layoutInfo.pPushConstantRanges = &push;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  if (VkResult r = fn.vkCreatePipelineLayout(ctx.handle(), &layoutInfo, nullptr, &layout))
    return vkCallError(r, "vkCreatePipelineLayout");
  pipelineLayout = VkOwned<VkPipelineLayout>(ctx, layout);
  return std::nullopt;
}

std::optional<Error> createSubmitObjects(const VkContext& ctx, VkDescriptorSetLayout setLayout,
                                         uint32_t bindings, VkSubmitObjects& out) {
  const VkFunctions& fn = ctx.fn();
  const VkDevice dev = ctx.handle();
  const VkDescriptorPoolSize poolSize{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, bindings};
  auto poolInfo =
      vkStruct<VkDescriptorPoolCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO);
  poolInfo.maxSets = 1;
  poolInfo.poolSizeCount = 1;
  poolInfo.pPoolSizes = &poolSize;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  if (VkResult r = fn.vkCreateDescriptorPool(dev, &poolInfo, nullptr, &pool))
    return vkCallError(r, "vkCreateDescriptorPool");
  out.descriptorPool = VkOwned<VkDescriptorPool>(ctx, pool);
  auto setAlloc =
      vkStruct<VkDescriptorSetAllocateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO);
  setAlloc.descriptorPool = pool;
  setAlloc.descriptorSetCount = 1;
  setAlloc.pSetLayouts = &setLayout;
  if (VkResult r = fn.vkAllocateDescriptorSets(dev, &setAlloc, &out.set))
    return vkCallError(r, "vkAllocateDescriptorSets");

  auto cmdPoolInfo = vkStruct<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
  cmdPoolInfo.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  cmdPoolInfo.queueFamilyIndex = ctx.device().queueFamilyIndex;
  VkCommandPool cmdPool = VK_NULL_HANDLE;
  if (VkResult r = fn.vkCreateCommandPool(dev, &cmdPoolInfo, nullptr, &cmdPool))
    return vkCallError(r, "vkCreateCommandPool");
  out.commandPool = VkOwned<VkCommandPool>(ctx, cmdPool);
  auto cmdAlloc =
      vkStruct<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
  cmdAlloc.commandPool = cmdPool;
  cmdAlloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cmdAlloc.commandBufferCount = 1;
  if (VkResult r = fn.vkAllocateCommandBuffers(dev, &cmdAlloc, &out.cmd))
    return vkCallError(r, "vkAllocateCommandBuffers");

  auto fenceInfo = vkStruct<VkFenceCreateInfo>(VK_STRUCTURE_TYPE_FENCE_CREATE_INFO);
  VkFence fence = VK_NULL_HANDLE;
  if (VkResult r = fn.vkCreateFence(dev, &fenceInfo, nullptr, &fence))
    return vkCallError(r, "vkCreateFence");
  out.fence = VkOwned<VkFence>(ctx, fence);
  return std::nullopt;
}

void recordMemoryBarrier(const VkContext& ctx, VkCommandBuffer cmd, VkPipelineStageFlags srcStage,
                         VkAccessFlags srcAccess, VkPipelineStageFlags dstStage,
                         VkAccessFlags dstAccess) {
  auto mb = vkStruct<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
  mb.srcAccessMask = srcAccess;
  mb.dstAccessMask = dstAccess;
  ctx.fn().vkCmdPipelineBarrier(cmd, srcStage, dstStage, 0, 1, &mb, 0, nullptr, 0, nullptr);
}

}  // namespace sdfg
