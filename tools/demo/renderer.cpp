#include "renderer.h"

#include <cstring>

#include "shaders/scene.frag.h"
#include "shaders/scene.vert.h"

namespace sdfg::demo {
namespace {

constexpr VkFormat kColourFormat = VK_FORMAT_R8G8B8A8_UNORM;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;

struct PushConstants {
  glm::mat4 viewProjection;
  glm::vec4 light;
};

#define DEMO_VK(call)                                                              \
  do {                                                                             \
    const VkResult r_ = (call);                                                    \
    if (r_ != VK_SUCCESS) {                                                        \
      error = std::string(#call) + " failed: VkResult " + std::to_string(int(r_)); \
      return false;                                                                \
    }                                                                              \
  } while (0)

}  // namespace

Renderer::~Renderer() {
  if (device_ == VK_NULL_HANDLE) return;
  vkDeviceWaitIdle(device_);
  destroyTarget();
  destroyBuffer(vertices_);
  destroyBuffer(readback_);
  if (fence_) vkDestroyFence(device_, fence_, nullptr);
  if (commandPool_) vkDestroyCommandPool(device_, commandPool_, nullptr);
  if (litPipeline_) vkDestroyPipeline(device_, litPipeline_, nullptr);
  if (overlayPipeline_) vkDestroyPipeline(device_, overlayPipeline_, nullptr);
  if (layout_) vkDestroyPipelineLayout(device_, layout_, nullptr);
  if (renderPass_) vkDestroyRenderPass(device_, renderPass_, nullptr);
}

bool Renderer::init(VkPhysicalDevice physical, VkDevice device, uint32_t queueFamily, VkQueue queue,
                    std::string& error) {
  physical_ = physical;
  device_ = device;
  queue_ = queue;
  vkGetPhysicalDeviceMemoryProperties(physical_, &memory_);

  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pci.queueFamilyIndex = queueFamily;
  DEMO_VK(vkCreateCommandPool(device_, &pci, nullptr, &commandPool_));
  VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cai.commandPool = commandPool_;
  cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cai.commandBufferCount = 1;
  DEMO_VK(vkAllocateCommandBuffers(device_, &cai, &commands_));
  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  DEMO_VK(vkCreateFence(device_, &fci, nullptr, &fence_));
  return createPipelines(error);
}

bool Renderer::createPipelines(std::string& error) {
  VkAttachmentDescription att[2]{};
  att[0].format = kColourFormat;
  att[0].samples = VK_SAMPLE_COUNT_1_BIT;
  att[0].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  att[0].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  att[0].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  att[0].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  att[0].initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  att[0].finalLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
  att[1] = att[0];
  att[1].format = kDepthFormat;
  att[1].storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  att[1].finalLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
  VkAttachmentReference colourRef{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  VkAttachmentReference depthRef{1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
  VkSubpassDescription sub{};
  sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  sub.colorAttachmentCount = 1;
  sub.pColorAttachments = &colourRef;
  sub.pDepthStencilAttachment = &depthRef;
  VkSubpassDependency deps[2]{};
  // The previous frame's copy out of the colour image (and depth use) before this frame's clear.
  deps[0].srcSubpass = VK_SUBPASS_EXTERNAL;
  deps[0].dstSubpass = 0;
  deps[0].srcStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
  deps[0].srcAccessMask = VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
  deps[0].dstStageMask =
      VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT;
  deps[0].dstAccessMask =
      VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
  // Colour writes before the copy to the readback buffer.
  deps[1].srcSubpass = 0;
  deps[1].dstSubpass = VK_SUBPASS_EXTERNAL;
  deps[1].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  deps[1].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  deps[1].dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
  deps[1].dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  VkRenderPassCreateInfo rpci{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
  rpci.attachmentCount = 2;
  rpci.pAttachments = att;
  rpci.subpassCount = 1;
  rpci.pSubpasses = &sub;
  rpci.dependencyCount = 2;
  rpci.pDependencies = deps;
  DEMO_VK(vkCreateRenderPass(device_, &rpci, nullptr, &renderPass_));

  VkPushConstantRange push{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                           sizeof(PushConstants)};
  VkPipelineLayoutCreateInfo plci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  plci.pushConstantRangeCount = 1;
  plci.pPushConstantRanges = &push;
  DEMO_VK(vkCreatePipelineLayout(device_, &plci, nullptr, &layout_));

  VkShaderModule vert = VK_NULL_HANDLE, frag = VK_NULL_HANDLE;
  VkShaderModuleCreateInfo smci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  smci.codeSize = sizeof(scene_vert_spv);
  smci.pCode = scene_vert_spv;
  DEMO_VK(vkCreateShaderModule(device_, &smci, nullptr, &vert));
  smci.codeSize = sizeof(scene_frag_spv);
  smci.pCode = scene_frag_spv;
  if (vkCreateShaderModule(device_, &smci, nullptr, &frag) != VK_SUCCESS) {
    vkDestroyShaderModule(device_, vert, nullptr);
    error = "vkCreateShaderModule (fragment) failed";
    return false;
  }
  VkPipelineShaderStageCreateInfo stages[2]{};
  stages[0].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
  stages[0].module = vert;
  stages[0].pName = "main";
  stages[1] = stages[0];
  stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
  stages[1].module = frag;

  VkVertexInputBindingDescription binding{0, sizeof(Vertex), VK_VERTEX_INPUT_RATE_VERTEX};
  VkVertexInputAttributeDescription attrs[3] = {
      {0, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, position)},
      {1, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, normal)},
      {2, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, colour)}};
  VkPipelineVertexInputStateCreateInfo vi{
      VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
  vi.vertexBindingDescriptionCount = 1;
  vi.pVertexBindingDescriptions = &binding;
  vi.vertexAttributeDescriptionCount = 3;
  vi.pVertexAttributeDescriptions = attrs;
  VkPipelineInputAssemblyStateCreateInfo ia{
      VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
  ia.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  VkPipelineViewportStateCreateInfo vp{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
  vp.viewportCount = 1;
  vp.scissorCount = 1;
  VkPipelineRasterizationStateCreateInfo rs{
      VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
  rs.polygonMode = VK_POLYGON_MODE_FILL;
  rs.cullMode = VK_CULL_MODE_NONE;  // open meshes and flipped windings stay visible
  rs.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
  rs.lineWidth = 1.0f;
  VkPipelineMultisampleStateCreateInfo ms{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
  ms.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  VkPipelineDepthStencilStateCreateInfo ds{
      VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
  ds.depthTestEnable = VK_TRUE;
  ds.depthWriteEnable = VK_TRUE;
  ds.depthCompareOp = VK_COMPARE_OP_LESS;
  VkPipelineColorBlendAttachmentState blend{};
  blend.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT |
                         VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
  VkPipelineColorBlendStateCreateInfo cb{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
  cb.attachmentCount = 1;
  cb.pAttachments = &blend;
  const VkDynamicState dyn[2] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
  VkPipelineDynamicStateCreateInfo dy{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
  dy.dynamicStateCount = 2;
  dy.pDynamicStates = dyn;
  VkGraphicsPipelineCreateInfo gp{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
  gp.stageCount = 2;
  gp.pStages = stages;
  gp.pVertexInputState = &vi;
  gp.pInputAssemblyState = &ia;
  gp.pViewportState = &vp;
  gp.pRasterizationState = &rs;
  gp.pMultisampleState = &ms;
  gp.pDepthStencilState = &ds;
  gp.pColorBlendState = &cb;
  gp.pDynamicState = &dy;
  gp.layout = layout_;
  gp.renderPass = renderPass_;
  VkResult r = vkCreateGraphicsPipelines(device_, VK_NULL_HANDLE, 1, &gp, nullptr, &litPipeline_);
  if (r == VK_SUCCESS) {
    ds.depthTestEnable = VK_FALSE;
    ds.depthWriteEnable = VK_FALSE;
    r = vkCreateGraphicsPipelines(device_, VK_NULL_HANDLE, 1, &gp, nullptr, &overlayPipeline_);
  }
  vkDestroyShaderModule(device_, vert, nullptr);
  vkDestroyShaderModule(device_, frag, nullptr);
  if (r != VK_SUCCESS) {
    error = "vkCreateGraphicsPipelines failed: VkResult " + std::to_string(int(r));
    return false;
  }
  return true;
}

int32_t Renderer::memoryType(uint32_t bits, VkMemoryPropertyFlags flags) const {
  for (uint32_t i = 0; i < memory_.memoryTypeCount; ++i) {
    if ((bits & (1u << i)) && (memory_.memoryTypes[i].propertyFlags & flags) == flags)
      return int32_t(i);
  }
  return -1;
}

bool Renderer::createImage(VkFormat format, VkImageUsageFlags usage, VkImageAspectFlags aspect,
                           VkImage& image, VkDeviceMemory& memory, VkImageView& view,
                           std::string& error) {
  VkImageCreateInfo ici{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ici.imageType = VK_IMAGE_TYPE_2D;
  ici.format = format;
  ici.extent = {width_, height_, 1};
  ici.mipLevels = 1;
  ici.arrayLayers = 1;
  ici.samples = VK_SAMPLE_COUNT_1_BIT;
  ici.tiling = VK_IMAGE_TILING_OPTIMAL;
  ici.usage = usage;
  ici.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  DEMO_VK(vkCreateImage(device_, &ici, nullptr, &image));
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(device_, image, &req);
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mai.allocationSize = req.size;
  const int32_t type = memoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  mai.memoryTypeIndex = uint32_t(type >= 0 ? type : memoryType(req.memoryTypeBits, 0));
  DEMO_VK(vkAllocateMemory(device_, &mai, nullptr, &memory));
  DEMO_VK(vkBindImageMemory(device_, image, memory, 0));
  VkImageViewCreateInfo vci{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  vci.image = image;
  vci.viewType = VK_IMAGE_VIEW_TYPE_2D;
  vci.format = format;
  vci.subresourceRange = {aspect, 0, 1, 0, 1};
  DEMO_VK(vkCreateImageView(device_, &vci, nullptr, &view));
  return true;
}

bool Renderer::ensureTarget(uint32_t width, uint32_t height, std::string& error) {
  if (width == width_ && height == height_ && framebuffer_ != VK_NULL_HANDLE) return true;
  destroyTarget();
  width_ = width;
  height_ = height;
  if (!createImage(kColourFormat,
                   VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                   VK_IMAGE_ASPECT_COLOR_BIT, colour_, colourMemory_, colourView_, error) ||
      !createImage(kDepthFormat, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                   VK_IMAGE_ASPECT_DEPTH_BIT, depth_, depthMemory_, depthView_, error))
    return false;
  const VkImageView views[2] = {colourView_, depthView_};
  VkFramebufferCreateInfo fci{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
  fci.renderPass = renderPass_;
  fci.attachmentCount = 2;
  fci.pAttachments = views;
  fci.width = width_;
  fci.height = height_;
  fci.layers = 1;
  DEMO_VK(vkCreateFramebuffer(device_, &fci, nullptr, &framebuffer_));
  return ensureBuffer(readback_, VkDeviceSize(width_) * height_ * 4,
                      VK_BUFFER_USAGE_TRANSFER_DST_BIT, error);
}

void Renderer::destroyTarget() {
  if (framebuffer_) vkDestroyFramebuffer(device_, framebuffer_, nullptr);
  if (colourView_) vkDestroyImageView(device_, colourView_, nullptr);
  if (depthView_) vkDestroyImageView(device_, depthView_, nullptr);
  if (colour_) vkDestroyImage(device_, colour_, nullptr);
  if (depth_) vkDestroyImage(device_, depth_, nullptr);
  if (colourMemory_) vkFreeMemory(device_, colourMemory_, nullptr);
  if (depthMemory_) vkFreeMemory(device_, depthMemory_, nullptr);
  framebuffer_ = VK_NULL_HANDLE;
  colourView_ = depthView_ = VK_NULL_HANDLE;
  colour_ = depth_ = VK_NULL_HANDLE;
  colourMemory_ = depthMemory_ = VK_NULL_HANDLE;
  width_ = height_ = 0;
}

bool Renderer::ensureBuffer(Buffer& b, VkDeviceSize size, VkBufferUsageFlags usage,
                            std::string& error) {
  if (b.buffer != VK_NULL_HANDLE && b.size >= size) return true;
  destroyBuffer(b);
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = size;
  bci.usage = usage;
  DEMO_VK(vkCreateBuffer(device_, &bci, nullptr, &b.buffer));
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device_, b.buffer, &req);
  const int32_t type = memoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
                                                          VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  if (type < 0) {
    error = "no host-visible coherent memory type";
    return false;
  }
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = uint32_t(type);
  DEMO_VK(vkAllocateMemory(device_, &mai, nullptr, &b.memory));
  DEMO_VK(vkBindBufferMemory(device_, b.buffer, b.memory, 0));
  DEMO_VK(vkMapMemory(device_, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped));
  b.size = size;
  return true;
}

void Renderer::destroyBuffer(Buffer& b) {
  if (b.memory) vkFreeMemory(device_, b.memory, nullptr);  // unmaps implicitly
  if (b.buffer) vkDestroyBuffer(device_, b.buffer, nullptr);
  b = Buffer{};
}

bool Renderer::render(const DrawList& list, const glm::mat4& viewProjection, const glm::vec3& light,
                      uint32_t width, uint32_t height, const glm::vec3& background,
                      std::vector<uint8_t>& rgba, std::string& error) {
  if (!ensureTarget(width, height, error)) return false;
  const size_t count = list.lit.size() + list.overlay.size();
  if (count > 0) {
    if (!ensureBuffer(vertices_, VkDeviceSize(count * sizeof(Vertex)),
                      VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, error))
      return false;
    // An empty list's data() may be null, which memcpy may not be given even for no bytes.
    if (!list.lit.empty())
      std::memcpy(vertices_.mapped, list.lit.data(), list.lit.size() * sizeof(Vertex));
    if (!list.overlay.empty())
      std::memcpy(static_cast<Vertex*>(vertices_.mapped) + list.lit.size(), list.overlay.data(),
                  list.overlay.size() * sizeof(Vertex));
  }
  DEMO_VK(vkResetCommandBuffer(commands_, 0));
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  DEMO_VK(vkBeginCommandBuffer(commands_, &bi));
  VkClearValue clear[2]{};
  clear[0].color = {{background.r, background.g, background.b, 1.0f}};
  clear[1].depthStencil = {1.0f, 0};
  VkRenderPassBeginInfo rbi{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  rbi.renderPass = renderPass_;
  rbi.framebuffer = framebuffer_;
  rbi.renderArea = {{0, 0}, {width_, height_}};
  rbi.clearValueCount = 2;
  rbi.pClearValues = clear;
  vkCmdBeginRenderPass(commands_, &rbi, VK_SUBPASS_CONTENTS_INLINE);
  const VkViewport viewport{0, 0, float(width_), float(height_), 0.0f, 1.0f};
  const VkRect2D scissor{{0, 0}, {width_, height_}};
  vkCmdSetViewport(commands_, 0, 1, &viewport);
  vkCmdSetScissor(commands_, 0, 1, &scissor);
  const PushConstants push{viewProjection, glm::vec4(light, 0.0f)};
  if (count > 0) {
    const VkDeviceSize offset = 0;
    vkCmdBindVertexBuffers(commands_, 0, 1, &vertices_.buffer, &offset);
    vkCmdPushConstants(commands_, layout_,
                       VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof push,
                       &push);
    if (!list.lit.empty()) {
      vkCmdBindPipeline(commands_, VK_PIPELINE_BIND_POINT_GRAPHICS, litPipeline_);
      vkCmdDraw(commands_, uint32_t(list.lit.size()), 1, 0, 0);
    }
    if (!list.overlay.empty()) {
      vkCmdBindPipeline(commands_, VK_PIPELINE_BIND_POINT_GRAPHICS, overlayPipeline_);
      vkCmdDraw(commands_, uint32_t(list.overlay.size()), 1, uint32_t(list.lit.size()), 0);
    }
  }
  vkCmdEndRenderPass(commands_);
  VkBufferImageCopy copy{};
  copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  copy.imageExtent = {width_, height_, 1};
  vkCmdCopyImageToBuffer(commands_, colour_, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback_.buffer,
                         1, &copy);
  // The copy's writes before the host reads the mapped buffer.
  VkMemoryBarrier toHost{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  toHost.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  toHost.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(commands_, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1,
                       &toHost, 0, nullptr, 0, nullptr);
  DEMO_VK(vkEndCommandBuffer(commands_));
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &commands_;
  DEMO_VK(vkResetFences(device_, 1, &fence_));
  DEMO_VK(vkQueueSubmit(queue_, 1, &si, fence_));
  DEMO_VK(vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX));
  rgba.resize(size_t(width_) * height_ * 4);
  std::memcpy(rgba.data(), readback_.mapped, rgba.size());
  return true;
}

}  // namespace sdfg::demo
