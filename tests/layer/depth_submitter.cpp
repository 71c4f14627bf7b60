#include "depth_submitter.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

namespace sdfg::test {
namespace {

bool hasStencil(VkFormat f) {
  return f == VK_FORMAT_D24_UNORM_S8_UINT || f == VK_FORMAT_D32_SFLOAT_S8_UINT;
}

VkImageAspectFlags depthAspects(VkFormat f) {
  // A barrier on a combined format names both aspects (no separateDepthStencilLayouts here).
  return hasStencil(f) ? VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT
                       : VK_IMAGE_ASPECT_DEPTH_BIT;
}

// Bytes per texel of the depth aspect in a buffer copy: D24 comes as 32 bits, depth in the low 24.
uint32_t depthTexelBytes(VkFormat f) {
  return f == VK_FORMAT_D16_UNORM ? 2 : 4;
}

}  // namespace

float storedDepthValue(float distance, float infoNearZ, float infoFarZ) {
  const double a = std::isinf(infoNearZ) ? 0.0 : 1.0 / double(infoNearZ);
  const double b = std::isinf(infoFarZ) ? 0.0 : 1.0 / double(infoFarZ);
  // Nothing drawn is at infinity; a point at or behind the eye is clamped to the near plane.
  double inv = 0.0;
  if (!std::isnan(distance) && !std::isinf(distance))
    inv = distance > 0.0f ? 1.0 / double(distance) : std::numeric_limits<double>::infinity();
  const double d = (inv - a) / (b - a);
  return float(std::clamp(d, 0.0, 1.0));
}

DepthSubmitter::DepthSubmitter(App& app, DepthSubmitOptions options)
    : app_(app), options_(options) {
  if (app_.session == XR_NULL_HANDLE || app_.vk.device == VK_NULL_HANDLE) {
    fail("the app has no Vulkan session");
    return;
  }
  uint32_t count = 0;
  if (XrResult r = xrEnumerateSwapchainFormats(app_.session, 0, &count, nullptr); r != XR_SUCCESS) {
    fail("xrEnumerateSwapchainFormats", r);
    return;
  }
  std::vector<int64_t> formats(count);
  xrEnumerateSwapchainFormats(app_.session, count, &count, formats.data());
  if (std::find(formats.begin(), formats.end(), int64_t(options_.format)) == formats.end()) {
    fail("the runtime does not offer depth format " + std::to_string(int(options_.format)));
    return;
  }
  const uint32_t chains = options_.arraySwapchain ? 1 : 2;
  const uint32_t arraySize = options_.arraySwapchain ? 2 : 1;
  depth_.resize(chains);
  colour_.resize(chains);
  for (uint32_t i = 0; i < chains; ++i) {
    if (!createChain(options_.format, options_.usage, arraySize, depth_[i])) return;
    // The colour is only there because a projection view needs one; the test never looks at it.
    if (!createChain(VK_FORMAT_R8G8B8A8_SRGB,
                     XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT | XR_SWAPCHAIN_USAGE_TRANSFER_DST_BIT,
                     arraySize, colour_[i]))
      return;
  }
  createVulkanObjects();
}

DepthSubmitter::~DepthSubmitter() {
  // A projection of ours left for a frame after this one would point at freed structs.
  if (!app_.layers.empty() &&
      app_.layers.front() == reinterpret_cast<const XrCompositionLayerBaseHeader*>(&projection_))
    app_.layers.clear();
  const VkDevice device = app_.vk.device;
  if (device != VK_NULL_HANDLE) {
    // Only a failed wait leaves an upload in flight; the swapchain images must outlive it.
    if (app_.vk.queue != VK_NULL_HANDLE) vkQueueWaitIdle(app_.vk.queue);
    if (staging_ != VK_NULL_HANDLE) vkDestroyBuffer(device, staging_, nullptr);
    if (stagingMemory_ != VK_NULL_HANDLE) vkFreeMemory(device, stagingMemory_, nullptr);
    if (fence_ != VK_NULL_HANDLE) vkDestroyFence(device, fence_, nullptr);
    if (pool_ != VK_NULL_HANDLE) vkDestroyCommandPool(device, pool_, nullptr);  // frees commands_
  }
  // With the session gone its swapchains went with it.
  if (app_.session != XR_NULL_HANDLE) {
    for (std::vector<Chain>* list : {&depth_, &colour_}) {
      for (Chain& c : *list) {
        if (c.swapchain != XR_NULL_HANDLE) xrDestroySwapchain(c.swapchain);
      }
    }
  }
}

bool DepthSubmitter::fail(const std::string& what, XrResult r) {
  if (error_.empty()) {
    char name[XR_MAX_RESULT_STRING_SIZE] = {};
    if (r != XR_SUCCESS && xrResultToString(app_.instance, r, name) != XR_SUCCESS)
      std::snprintf(name, sizeof name, "XrResult %d", int(r));
    error_ = r == XR_SUCCESS ? what : what + ": " + name;
    result_ = r;
  }
  return false;
}

bool DepthSubmitter::createChain(int64_t format, XrSwapchainUsageFlags usage, uint32_t arraySize,
                                 Chain& out) {
  XrSwapchainCreateInfo ci{XR_TYPE_SWAPCHAIN_CREATE_INFO};
  ci.usageFlags = usage;
  ci.format = format;
  ci.sampleCount = 1;
  ci.width = options_.width;
  ci.height = options_.height;
  ci.faceCount = 1;
  ci.arraySize = arraySize;
  ci.mipCount = 1;
  if (XrResult r = xrCreateSwapchain(app_.session, &ci, &out.swapchain); r != XR_SUCCESS) {
    out.swapchain = XR_NULL_HANDLE;
    return fail("xrCreateSwapchain of format " + std::to_string(format), r);
  }
  uint32_t count = 0;
  if (XrResult r = xrEnumerateSwapchainImages(out.swapchain, 0, &count, nullptr); r != XR_SUCCESS)
    return fail("xrEnumerateSwapchainImages", r);
  // XrSwapchainImageVulkan2KHR is the same struct with the same type value.
  std::vector<XrSwapchainImageVulkanKHR> images(count, {XR_TYPE_SWAPCHAIN_IMAGE_VULKAN_KHR});
  if (XrResult r =
          xrEnumerateSwapchainImages(out.swapchain, count, &count,
                                     reinterpret_cast<XrSwapchainImageBaseHeader*>(images.data()));
      r != XR_SUCCESS)
    return fail("xrEnumerateSwapchainImages", r);
  for (const auto& i : images) out.images.push_back(i.image);
  return true;
}

bool DepthSubmitter::createVulkanObjects() {
  const VkDevice device = app_.vk.device;
  VkCommandPoolCreateInfo pi{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pi.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pi.queueFamilyIndex = app_.vk.family;
  if (vkCreateCommandPool(device, &pi, nullptr, &pool_) != VK_SUCCESS)
    return fail("vkCreateCommandPool");
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = pool_;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  if (vkAllocateCommandBuffers(device, &ai, &commands_) != VK_SUCCESS)
    return fail("vkAllocateCommandBuffers");
  VkFenceCreateInfo fi{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  if (vkCreateFence(device, &fi, nullptr, &fence_) != VK_SUCCESS) return fail("vkCreateFence");

  // Copy offsets into a depth/stencil image must be multiples of 4.
  const VkDeviceSize texels = VkDeviceSize(options_.width) * options_.height;
  depthBytes_ = (texels * depthTexelBytes(options_.format) + 3) / 4 * 4;
  stencilOffset_ = 2 * depthBytes_;
  const VkDeviceSize size = stencilOffset_ + (hasStencil(options_.format) ? texels : 0);
  VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bi.size = size;
  bi.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
  bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  if (vkCreateBuffer(device, &bi, nullptr, &staging_) != VK_SUCCESS) return fail("vkCreateBuffer");
  VkMemoryRequirements req{};
  vkGetBufferMemoryRequirements(device, staging_, &req);
  const uint32_t type = hostCoherentMemoryType(app_.vk, req.memoryTypeBits);
  if (type == UINT32_MAX) return fail("no host-visible coherent memory");
  VkMemoryAllocateInfo mi{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mi.allocationSize = req.size;
  mi.memoryTypeIndex = type;
  void* mapped = nullptr;
  if (vkAllocateMemory(device, &mi, nullptr, &stagingMemory_) != VK_SUCCESS ||
      vkBindBufferMemory(device, staging_, stagingMemory_, 0) != VK_SUCCESS ||
      vkMapMemory(device, stagingMemory_, 0, VK_WHOLE_SIZE, 0, &mapped) != VK_SUCCESS)
    return fail("staging memory");
  mapped_ = static_cast<uint8_t*>(mapped);
  std::memset(mapped_, 0, size_t(size));  // the stencil plane stays 0
  return true;
}

bool DepthSubmitter::acquire(const Chain& chain, uint32_t& index) {
  XrSwapchainImageAcquireInfo ai{XR_TYPE_SWAPCHAIN_IMAGE_ACQUIRE_INFO};
  if (XrResult r = xrAcquireSwapchainImage(chain.swapchain, &ai, &index); r != XR_SUCCESS)
    return fail("xrAcquireSwapchainImage", r);
  XrSwapchainImageWaitInfo wi{XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO};
  wi.timeout = XR_INFINITE_DURATION;
  if (XrResult r = xrWaitSwapchainImage(chain.swapchain, &wi); r != XR_SUCCESS)
    return fail("xrWaitSwapchainImage", r);
  if (index >= chain.images.size()) return fail("acquired image index out of range");
  return true;
}

bool DepthSubmitter::release(const Chain& chain) {
  XrSwapchainImageReleaseInfo ri{XR_TYPE_SWAPCHAIN_IMAGE_RELEASE_INFO};
  if (XrResult r = xrReleaseSwapchainImage(chain.swapchain, &ri); r != XR_SUCCESS)
    return fail("xrReleaseSwapchainImage", r);
  return true;
}

void DepthSubmitter::writeStaging(const std::vector<float>& distances, uint32_t view) {
  const XrCompositionLayerDepthInfoKHR& info = depthInfos_[view];
  uint8_t* out = mapped_ + view * depthBytes_;
  for (size_t i = 0; i < distances.size(); ++i) {
    const float v = storedDepthValue(distances[i], info.nearZ, info.farZ);
    switch (options_.format) {
      case VK_FORMAT_D16_UNORM: {
        const auto q = uint16_t(std::lround(double(v) * 65535.0));
        std::memcpy(out + 2 * i, &q, 2);
        break;
      }
      case VK_FORMAT_D24_UNORM_S8_UINT: {
        const auto q = uint32_t(std::lround(double(v) * 16777215.0)) & 0xFFFFFFu;
        std::memcpy(out + 4 * i, &q, 4);
        break;
      }
      default:  // D32_SFLOAT, and the depth aspect of D32_SFLOAT_S8_UINT
        std::memcpy(out + 4 * i, &v, 4);
        break;
    }
  }
}

bool DepthSubmitter::upload(const std::array<uint32_t, 2>& depthIndex,
                            const std::array<uint32_t, 2>& colourIndex) {
  const VkFormat format = options_.format;
  const bool array = options_.arraySwapchain;
  const uint32_t images = array ? 1 : 2;
  const uint32_t layers = array ? 2 : 1;
  if (vkResetCommandBuffer(commands_, 0) != VK_SUCCESS) return fail("vkResetCommandBuffer");
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  if (vkBeginCommandBuffer(commands_, &begin) != VK_SUCCESS) return fail("vkBeginCommandBuffer");

  // Into TRANSFER_DST from the layouts the runtime hands images out in after the wait (what an
  // earlier frame's rendering or the runtime's reads did is ordered before by the stages).
  std::vector<VkImageMemoryBarrier> toDst, back;
  for (uint32_t i = 0; i < images; ++i) {
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcAccessMask = VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.oldLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
    b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = depth_[i].images[depthIndex[i]];
    b.subresourceRange = {depthAspects(format), 0, 1, 0, layers};
    toDst.push_back(b);
    // XR_KHR_vulkan_enable: a depth image is released in DEPTH_STENCIL_ATTACHMENT_OPTIMAL.
    b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask =
        VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
    b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.newLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
    back.push_back(b);

    VkImageMemoryBarrier c{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    c.srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
    c.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    c.oldLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    c.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    c.srcQueueFamilyIndex = c.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    c.image = colour_[i].images[colourIndex[i]];
    c.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, layers};
    toDst.push_back(c);
    c.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    c.dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
    c.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    c.newLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    back.push_back(c);
  }
  const VkPipelineStageFlags attachmentStages = VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
                                                VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT |
                                                VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  vkCmdPipelineBarrier(commands_, attachmentStages, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr,
                       0, nullptr, uint32_t(toDst.size()), toDst.data());

  for (uint32_t v = 0; v < 2; ++v) {
    const VkImage image = depth_[array ? 0 : v].images[depthIndex[array ? 0 : v]];
    const uint32_t layer = array ? v : 0;
    VkBufferImageCopy region{};
    region.bufferOffset = v * depthBytes_;
    region.imageSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, layer, 1};
    region.imageExtent = {options_.width, options_.height, 1};
    vkCmdCopyBufferToImage(commands_, staging_, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                           &region);
    if (hasStencil(format)) {
      // A real depth pass clears stencil too; left undefined it would be the one random input.
      region.bufferOffset = stencilOffset_;
      region.imageSubresource.aspectMask = VK_IMAGE_ASPECT_STENCIL_BIT;
      vkCmdCopyBufferToImage(commands_, staging_, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                             &region);
    }
  }
  const VkClearColorValue grey{{0.2f, 0.2f, 0.2f, 1.0f}};
  for (uint32_t i = 0; i < images; ++i) {
    const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, layers};
    vkCmdClearColorImage(commands_, colour_[i].images[colourIndex[i]],
                         VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &grey, 1, &range);
  }
  vkCmdPipelineBarrier(commands_, VK_PIPELINE_STAGE_TRANSFER_BIT, attachmentStages, 0, 0, nullptr,
                       0, nullptr, uint32_t(back.size()), back.data());
  if (vkEndCommandBuffer(commands_) != VK_SUCCESS) return fail("vkEndCommandBuffer");

  // The test app waits the simple way; the runtime and the layer use the queue only inside
  // their own calls, so it is ours here.
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &commands_;
  if (vkQueueSubmit(app_.vk.queue, 1, &si, fence_) != VK_SUCCESS) return fail("vkQueueSubmit");
  const VkResult waited = vkWaitForFences(app_.vk.device, 1, &fence_, VK_TRUE, UINT64_MAX);
  vkResetFences(app_.vk.device, 1, &fence_);
  if (waited != VK_SUCCESS) return fail("vkWaitForFences");
  return true;
}

bool DepthSubmitter::submit(const Render& render) {
  if (!ok()) return false;
  if (app_.lastTime <= 0) return fail("submit() outside a frame (no display time)");
  XrViewLocateInfo li{XR_TYPE_VIEW_LOCATE_INFO};
  li.viewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
  li.displayTime = app_.lastTime;
  li.space = app_.local;
  XrViewState state{XR_TYPE_VIEW_STATE};
  views_.fill(XrView{XR_TYPE_VIEW});
  uint32_t count = 0;
  if (XrResult r = xrLocateViews(app_.session, &li, &state, 2, &count, views_.data());
      r != XR_SUCCESS)
    return fail("xrLocateViews", r);
  const XrViewStateFlags valid =
      XR_VIEW_STATE_ORIENTATION_VALID_BIT | XR_VIEW_STATE_POSITION_VALID_BIT;
  if (count != 2 || (state.viewStateFlags & valid) != valid)
    return fail("xrLocateViews: not two valid views");

  const float far = options_.infiniteFar ? std::numeric_limits<float>::infinity() : options_.farZ;
  for (uint32_t v = 0; v < 2; ++v) {
    const Chain& d = depth_[options_.arraySwapchain ? 0 : v];
    const Chain& c = colour_[options_.arraySwapchain ? 0 : v];
    const XrRect2Di rect{{0, 0}, {int32_t(options_.width), int32_t(options_.height)}};
    const uint32_t slice = options_.arraySwapchain ? v : 0;
    XrCompositionLayerDepthInfoKHR& info = depthInfos_[v];
    info = XrCompositionLayerDepthInfoKHR{XR_TYPE_COMPOSITION_LAYER_DEPTH_INFO_KHR};
    info.subImage = {d.swapchain, rect, slice};
    info.minDepth = 0.0f;
    info.maxDepth = 1.0f;
    // The extension's planes are where stored minDepth and maxDepth lie: reversed depth stores
    // its far plane at 0, so its nearZ is the far plane.
    info.nearZ = options_.reversed ? far : options_.nearZ;
    info.farZ = options_.reversed ? options_.nearZ : far;
    XrCompositionLayerProjectionView& pv = projectionViews_[v];
    pv = XrCompositionLayerProjectionView{XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW};
    pv.next = &info;
    pv.pose = views_[v].pose;
    pv.fov = views_[v].fov;
    pv.subImage = {c.swapchain, rect, slice};

    const std::vector<float> distances = render(views_[v], options_.width, options_.height);
    if (distances.size() != size_t(options_.width) * options_.height)
      return fail("render returned " + std::to_string(distances.size()) + " distances");
    writeStaging(distances, v);
  }

  std::array<uint32_t, 2> depthIndex{}, colourIndex{};
  for (size_t i = 0; i < depth_.size(); ++i) {
    if (!acquire(depth_[i], depthIndex[i]) || !acquire(colour_[i], colourIndex[i])) return false;
  }
  if (!upload(depthIndex, colourIndex)) return false;
  for (size_t i = 0; i < depth_.size(); ++i) {
    if (!release(depth_[i]) || !release(colour_[i])) return false;
  }

  projection_ = XrCompositionLayerProjection{XR_TYPE_COMPOSITION_LAYER_PROJECTION};
  projection_.space = app_.local;
  projection_.viewCount = 2;
  projection_.views = projectionViews_.data();
  app_.layers = {reinterpret_cast<const XrCompositionLayerBaseHeader*>(&projection_)};
  ++submitted_;
  return true;
}

}  // namespace sdfg::test
