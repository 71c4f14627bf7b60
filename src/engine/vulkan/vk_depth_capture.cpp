#define VK_NO_PROTOTYPES  // every call goes through the borrowed device's function table
#include "vulkan/vk_depth_capture.h"

#include <cstring>
#include <iostream>

namespace sdfg {

namespace {

constexpr uint64_t kDestroyWaitNs = 2'000'000'000ull;

// Bytes a texel of the depth aspect takes in a buffer copy (the Vulkan spec's table of depth
// aspect copies: D24 formats are 32-bit words with the depth in the low 24 bits).
uint32_t depthTexelBytes(VkFormat f) {
  switch (f) {
    case VK_FORMAT_D16_UNORM:
    case VK_FORMAT_D16_UNORM_S8_UINT:
      return 2;
    case VK_FORMAT_X8_D24_UNORM_PACK32:
    case VK_FORMAT_D24_UNORM_S8_UINT:
    case VK_FORMAT_D32_SFLOAT:
    case VK_FORMAT_D32_SFLOAT_S8_UINT:
      return 4;
    default:
      return 0;
  }
}

bool inside(const VkDepthImage& im, const VkDepthRect& r) {
  return r.layer < im.layers && r.x >= 0 && r.y >= 0 && r.width > 0 && r.height > 0 &&
         uint64_t(r.x) + r.width <= im.width && uint64_t(r.y) + r.height <= im.height;
}

bool hasStencil(VkFormat f) {
  return f == VK_FORMAT_D16_UNORM_S8_UINT || f == VK_FORMAT_D24_UNORM_S8_UINT ||
         f == VK_FORMAT_D32_SFLOAT_S8_UINT;
}

float storedValue(VkFormat f, const unsigned char* texel) {
  switch (f) {
    case VK_FORMAT_D16_UNORM:
    case VK_FORMAT_D16_UNORM_S8_UINT: {
      uint16_t v;
      std::memcpy(&v, texel, sizeof v);
      return float(v) / 65535.0f;
    }
    case VK_FORMAT_X8_D24_UNORM_PACK32:
    case VK_FORMAT_D24_UNORM_S8_UINT: {
      uint32_t v;
      std::memcpy(&v, texel, sizeof v);
      return float(v & 0xffffffu) / 16777215.0f;
    }
    default: {
      float v;
      std::memcpy(&v, texel, sizeof v);
      return v;
    }
  }
}

}  // namespace

struct VkDepthCapture::Slot {
  enum class State { free, inFlight, finished };
  State state = State::free;
  bool discarded = false;  // the caller is done with it: free once finished
  uint64_t ticket = 0;
  VkDepthImage image;
  std::vector<VkDepthRect> regions;
  std::vector<VkDeviceSize> offsets;     // per region: where its texels start in the buffer
  VkCommandBuffer cmd = VK_NULL_HANDLE;  // from pool_
  VkOwned<VkFence> fence;
  VkBufferAlloc buffer;  // grown to the largest image copied
};

VkDepthCapture::VkDepthCapture() = default;

bool VkDepthCapture::readableFormat(VkFormat format) {
  return depthTexelBytes(format) != 0;
}

Result<std::unique_ptr<VkDepthCapture>> VkDepthCapture::create(
    const VulkanDevice& device, std::function<void(const std::string&)> log) {
  auto ctx = VkContext::create(device);
  if (!ctx) return ctx.error();
  std::unique_ptr<VkDepthCapture> c(new VkDepthCapture());
  c->ctx_ = std::move(ctx.value());
  c->log_ = std::move(log);
  const VkContext& x = *c->ctx_;
  const VkFunctions& fn = x.fn();
  auto poolInfo = vkStruct<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
  poolInfo.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  poolInfo.queueFamilyIndex = x.device().queueFamilyIndex;
  VkCommandPool pool = VK_NULL_HANDLE;
  if (VkResult r = fn.vkCreateCommandPool(x.handle(), &poolInfo, nullptr, &pool))
    return vkCallError(r, "vkCreateCommandPool");
  c->pool_ = VkOwned<VkCommandPool>(x, pool);
  for (auto& slot : c->slots_) {
    slot = std::make_unique<Slot>();
    auto alloc =
        vkStruct<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
    alloc.commandPool = pool;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    if (VkResult r = fn.vkAllocateCommandBuffers(x.handle(), &alloc, &slot->cmd))
      return vkCallError(r, "vkAllocateCommandBuffers");
    auto fenceInfo = vkStruct<VkFenceCreateInfo>(VK_STRUCTURE_TYPE_FENCE_CREATE_INFO);
    VkFence fence = VK_NULL_HANDLE;
    if (VkResult r = fn.vkCreateFence(x.handle(), &fenceInfo, nullptr, &fence))
      return vkCallError(r, "vkCreateFence");
    slot->fence = VkOwned<VkFence>(x, fence);
  }
  return c;
}

VkDepthCapture::~VkDepthCapture() {
  if (!ctx_) return;
  std::vector<VkFence> fences;
  for (const auto& s : slots_)
    if (s && s->state == Slot::State::inFlight) fences.push_back(s->fence.get());
  if (fences.empty()) return;
  if (ctx_->fn().vkWaitForFences(ctx_->handle(), uint32_t(fences.size()), fences.data(), VK_TRUE,
                                 kDestroyWaitNs) == VK_SUCCESS)
    return;
  // A device that does not finish a copy in 2 s is hung or lost: destroying what it may still
  // write is worse than leaking it.
  for (auto& s : slots_) {
    if (!s) continue;
    s->buffer.buffer.release();
    s->buffer.memory.release();
    s->fence.release();
  }
  pool_.release();
}

Error VkDepthCapture::fail(VkResult result, const char* what) {
  const Error e = vkCallError(result, what);
  if (!failed_) {
    const std::string line = "sdfg: depth capture disabled: " + e.message;
    if (log_)
      log_(line);
    else
      std::cerr << line << std::endl;
  }
  failed_ = true;
  return e;
}

VkDepthCapture::Slot* VkDepthCapture::slotOf(uint64_t ticket) const {
  for (const auto& s : slots_)
    if (s->state != Slot::State::free && s->ticket == ticket) return s.get();
  return nullptr;
}

void VkDepthCapture::retire() {
  for (auto& s : slots_) {
    if (s->state == Slot::State::inFlight &&
        ctx_->fn().vkGetFenceStatus(ctx_->handle(), s->fence.get()) == VK_SUCCESS)
      s->state = Slot::State::finished;
    if (s->state == Slot::State::finished && s->discarded) {
      s->state = Slot::State::free;
      s->discarded = false;
      s->ticket = 0;
    }
  }
}

Result<uint64_t> VkDepthCapture::submit(const VkDepthImage& image,
                                        std::span<const VkDepthRect> regions) {
  if (failed_) return makeError(Status::device_lost, "depth capture: the device failed before");
  const uint32_t bytes = depthTexelBytes(image.format);
  if (bytes == 0 || image.image == VK_NULL_HANDLE || image.width == 0 || image.height == 0 ||
      image.layers == 0)
    return makeError(Status::invalid_argument, "depth capture: not a readable depth image");
  if (regions.empty() || regions.size() > 64)
    return makeError(Status::invalid_argument, "depth capture: no region, or too many");
  std::vector<VkDeviceSize> offsets;
  VkDeviceSize size = 0;
  for (const VkDepthRect& r : regions) {
    if (!inside(image, r))
      return makeError(Status::invalid_argument, "depth capture: a region outside the image");
    offsets.push_back(size);
    // Each region starts 4-byte aligned, as a buffer copy's offset must for depth.
    size += (VkDeviceSize(r.width) * r.height * bytes + 3) & ~VkDeviceSize(3);
  }
  retire();
  Slot* slot = nullptr;
  for (auto& s : slots_)
    if (s->state == Slot::State::free) slot = s.get();
  if (slot == nullptr) return makeError(Status::unsupported, "depth capture: every copy is busy");

  const VkContext& c = *ctx_;
  const VkFunctions& fn = c.fn();
  if (slot->buffer.size < size) {
    slot->buffer = VkBufferAlloc{};
    auto made = createBuffer(c, size, VK_BUFFER_USAGE_TRANSFER_DST_BIT, VkMemoryKind::readback);
    if (!made) {
      // Out of memory for this size: the frame goes without depth, the capture stays usable.
      return made.error();
    }
    slot->buffer = std::move(made.value());
  }

  VkCommandBuffer cmd = slot->cmd;
  if (VkResult r = fn.vkResetCommandBuffer(cmd, 0)) return fail(r, "vkResetCommandBuffer");
  auto begin = vkStruct<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  if (VkResult r = fn.vkBeginCommandBuffer(cmd, &begin)) return fail(r, "vkBeginCommandBuffer");
  // A combined format's layout changes for both aspects together; only depth is copied.
  const VkImageAspectFlags aspects =
      VK_IMAGE_ASPECT_DEPTH_BIT | (hasStencil(image.format) ? VK_IMAGE_ASPECT_STENCIL_BIT : 0);
  auto toSrc = vkStruct<VkImageMemoryBarrier>(VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER);
  // The app's depth writes, submitted earlier on this queue (a depth pass, or a copy into the
  // image), finish before the copy reads: every stage, since the app's last barrier may end in any.
  toSrc.srcAccessMask = VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  toSrc.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  toSrc.oldLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
  toSrc.newLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
  toSrc.srcQueueFamilyIndex = toSrc.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  toSrc.image = image.image;
  toSrc.subresourceRange = {aspects, 0, 1, 0, image.layers};
  fn.vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                          0, 0, nullptr, 0, nullptr, 1, &toSrc);
  std::vector<VkBufferImageCopy> copies(regions.size());
  for (size_t i = 0; i < regions.size(); ++i) {
    const VkDepthRect& r = regions[i];
    copies[i].bufferOffset = offsets[i];
    copies[i].imageSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, r.layer, 1};
    copies[i].imageOffset = {r.x, r.y, 0};
    copies[i].imageExtent = {r.width, r.height, 1};
  }
  fn.vkCmdCopyImageToBuffer(cmd, image.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                            slot->buffer.buffer.get(), uint32_t(copies.size()), copies.data());
  // Back to the layout the runtime is promised; whatever it does next (sample, copy, attach)
  // waits for the copy's read.
  auto back = toSrc;
  back.srcAccessMask = 0;
  back.dstAccessMask = VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                       VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_SHADER_READ_BIT |
                       VK_ACCESS_TRANSFER_READ_BIT;
  back.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
  back.newLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
  auto toHost = vkStruct<VkBufferMemoryBarrier>(VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER);
  toHost.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  toHost.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  toHost.srcQueueFamilyIndex = toHost.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  toHost.buffer = slot->buffer.buffer.get();
  toHost.size = VK_WHOLE_SIZE;
  fn.vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT,
                          VK_PIPELINE_STAGE_ALL_COMMANDS_BIT | VK_PIPELINE_STAGE_HOST_BIT, 0, 0,
                          nullptr, 1, &toHost, 1, &back);
  if (VkResult r = fn.vkEndCommandBuffer(cmd)) return fail(r, "vkEndCommandBuffer");
  const VkFence fence = slot->fence.get();
  if (VkResult r = fn.vkResetFences(c.handle(), 1, &fence)) return fail(r, "vkResetFences");
  auto info = vkStruct<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
  info.commandBufferCount = 1;
  info.pCommandBuffers = &cmd;
  if (VkResult r = fn.vkQueueSubmit(c.queue(), 1, &info, fence)) return fail(r, "vkQueueSubmit");
  slot->state = Slot::State::inFlight;
  slot->discarded = false;
  slot->ticket = nextTicket_++;
  slot->image = image;
  slot->regions.assign(regions.begin(), regions.end());
  slot->offsets = std::move(offsets);
  return slot->ticket;
}

bool VkDepthCapture::finished(uint64_t ticket) {
  if (failed_) return false;
  Slot* s = slotOf(ticket);
  if (s == nullptr) return false;
  if (s->state == Slot::State::inFlight) {
    const VkResult r = ctx_->fn().vkGetFenceStatus(ctx_->handle(), s->fence.get());
    if (r == VK_SUCCESS) {
      s->state = Slot::State::finished;
    } else if (r != VK_NOT_READY) {
      (void)fail(r, "vkGetFenceStatus");
      return false;
    }
  }
  return s->state == Slot::State::finished;
}

std::vector<float> VkDepthCapture::read(uint64_t ticket, const VkDepthRect& rect,
                                        uint32_t step) const {
  const Slot* s = slotOf(ticket);
  if (s == nullptr || s->state != Slot::State::finished || step == 0 || rect.width == 0 ||
      rect.height == 0)
    return {};
  // The region of the rect's layer that holds it.
  size_t k = 0;
  for (; k < s->regions.size(); ++k) {
    const VkDepthRect& r = s->regions[k];
    if (r.layer == rect.layer && rect.x >= r.x && rect.y >= r.y &&
        int64_t(rect.x) + rect.width <= int64_t(r.x) + r.width &&
        int64_t(rect.y) + rect.height <= int64_t(r.y) + r.height)
      break;
  }
  if (k == s->regions.size()) return {};
  if (invalidateBuffer(*ctx_, s->buffer) != VK_SUCCESS) return {};
  const VkDepthRect& region = s->regions[k];
  const uint32_t bytes = depthTexelBytes(s->image.format);
  const auto* base = static_cast<const unsigned char*>(s->buffer.mapped) + s->offsets[k];
  const uint32_t w = (rect.width + step - 1) / step, h = (rect.height + step - 1) / step;
  std::vector<float> out(size_t(w) * h);
  for (uint32_t j = 0; j < h; ++j) {
    const uint32_t y = uint32_t(rect.y - region.y) + std::min(j * step + step / 2, rect.height - 1);
    const unsigned char* row = base + size_t(y) * region.width * bytes;
    for (uint32_t i = 0; i < w; ++i) {
      const uint32_t x =
          uint32_t(rect.x - region.x) + std::min(i * step + step / 2, rect.width - 1);
      out[size_t(j) * w + i] = storedValue(s->image.format, row + size_t(x) * bytes);
    }
  }
  return out;
}

void VkDepthCapture::discard(uint64_t ticket) {
  if (Slot* s = slotOf(ticket)) s->discarded = true;
  if (!failed_) retire();
}

int VkDepthCapture::held() const {
  int n = 0;
  for (const auto& s : slots_) n += s->state != Slot::State::free ? 1 : 0;
  return n;
}

bool VkDepthCapture::forget(VkImage image, uint64_t timeoutNs) {
  std::vector<VkFence> fences;
  for (const auto& s : slots_)
    if (s->state == Slot::State::inFlight && s->image.image == image)
      fences.push_back(s->fence.get());
  bool clear = true;
  if (!fences.empty()) {
    clear = ctx_->fn().vkWaitForFences(ctx_->handle(), uint32_t(fences.size()), fences.data(),
                                       VK_TRUE, timeoutNs) == VK_SUCCESS;
  }
  for (auto& s : slots_) {
    if (s->state == Slot::State::free || s->image.image != image) continue;
    if (clear) {
      s->state = Slot::State::free;
      s->discarded = false;
      s->ticket = 0;
      s->image = {};
      s->regions.clear();
    } else {
      s->discarded = true;
    }
  }
  return clear;
}

}  // namespace sdfg
