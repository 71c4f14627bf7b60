// Swapchains: creation checks, the acquire / wait / release order the spec requires, and the
// Vulkan image array handed to the app. A headless session offers no formats.
#include <algorithm>

#include "entry_points.h"
#include "system_constants.h"

namespace sdfg::mock {
namespace {

constexpr XrSwapchainUsageFlags kKnownUsage =
    XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT | XR_SWAPCHAIN_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT |
    XR_SWAPCHAIN_USAGE_UNORDERED_ACCESS_BIT | XR_SWAPCHAIN_USAGE_TRANSFER_SRC_BIT |
    XR_SWAPCHAIN_USAGE_TRANSFER_DST_BIT | XR_SWAPCHAIN_USAGE_SAMPLED_BIT |
    XR_SWAPCHAIN_USAGE_MUTABLE_FORMAT_BIT | XR_SWAPCHAIN_USAGE_INPUT_ATTACHMENT_BIT_MND;

}  // namespace

Swapchain::~Swapchain() = default;

void destroySwapchain(Swapchain* swapchain) {
  Session* session = swapchain->session;
  destroyVulkanImages(*swapchain);
  unregisterHandle(swapchain);
  std::erase_if(session->swapchains, [&](const auto& s) { return s.get() == swapchain; });
}

XrResult enumerateSwapchainFormats(XrSession handle, uint32_t capacity, uint32_t* countOutput,
                                   int64_t* formats) {
  constexpr const char* cmd = "xrEnumerateSwapchainFormats";
  const Session* session = lookup<Session>(handle);
  if (session == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "session is not valid");
  if (!session->vulkan) return twoCall<int64_t>(cmd, capacity, countOutput, formats, nullptr, 0);
  const std::vector<int64_t>& list = vulkanSwapchainFormats(*session);
  return twoCall(cmd, capacity, countOutput, formats, list.data(), uint32_t(list.size()));
}

XrResult createSwapchain(XrSession handle, const XrSwapchainCreateInfo* info, XrSwapchain* out) {
  constexpr const char* cmd = "xrCreateSwapchain";
  Session* session = lookup<Session>(handle);
  if (session == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "session is not valid");
  MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_SWAPCHAIN_CREATE_INFO);
  MOCK_VERIFY_NOT_NULL(cmd, out);
  const XrSwapchainCreateFlags knownFlags =
      XR_SWAPCHAIN_CREATE_PROTECTED_CONTENT_BIT | XR_SWAPCHAIN_CREATE_STATIC_IMAGE_BIT;
  if (info->createFlags & ~knownFlags)
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "unknown createFlags");
  if (info->createFlags & XR_SWAPCHAIN_CREATE_PROTECTED_CONTENT_BIT)
    return fail(cmd, XR_ERROR_FEATURE_UNSUPPORTED, "no protected content");
  if (info->usageFlags & ~kKnownUsage)
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "unknown usageFlags");
  if (!session->vulkan) return fail(cmd, XR_ERROR_SWAPCHAIN_FORMAT_UNSUPPORTED, "headless session");
  const auto& formats = vulkanSwapchainFormats(*session);
  if (std::find(formats.begin(), formats.end(), info->format) == formats.end())
    return fail(cmd, XR_ERROR_SWAPCHAIN_FORMAT_UNSUPPORTED, "format %lld", (long long)info->format);
  if (info->sampleCount == 0 || info->width == 0 || info->height == 0 || info->faceCount == 0 ||
      info->arraySize == 0 || info->mipCount == 0)
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "a zero size, count or sample count");
  if (info->width > kMaxImageSize || info->height > kMaxImageSize)
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "%ux%u exceeds %u", info->width, info->height,
                kMaxImageSize);
  if (info->sampleCount != 1)
    return fail(cmd, XR_ERROR_FEATURE_UNSUPPORTED, "sampleCount %u", info->sampleCount);
  if (info->faceCount != 1)
    return fail(cmd, XR_ERROR_FEATURE_UNSUPPORTED, "faceCount %u", info->faceCount);
  const bool depth = isDepthFormat(info->format);
  if ((depth && (info->usageFlags & XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT)) ||
      (!depth && (info->usageFlags & XR_SWAPCHAIN_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT)))
    return fail(cmd, XR_ERROR_FEATURE_UNSUPPORTED, "usage does not fit the format");
  // Fault "refuse_depth_readback": a runtime that cannot let anyone read its depth images (some
  // compositors allocate them for attachment only), so a layer that adds a read usage to an
  // app's depth swapchain must fall back to the app's own flags.
  if (depth && session->instance->options.fault == "refuse_depth_readback" &&
      (info->usageFlags & (XR_SWAPCHAIN_USAGE_TRANSFER_SRC_BIT | XR_SWAPCHAIN_USAGE_SAMPLED_BIT)))
    return fail(cmd, XR_ERROR_FEATURE_UNSUPPORTED,
                "fault refuse_depth_readback: depth swapchains cannot be read");

  auto swapchain = std::make_unique<Swapchain>();
  swapchain->session = session;
  swapchain->info = *info;
  swapchain->info.next = nullptr;
  swapchain->imageCount =
      (info->createFlags & XR_SWAPCHAIN_CREATE_STATIC_IMAGE_BIT) ? 1 : kImagesPerSwapchain;
  if (XrResult r = createVulkanImages(cmd, *swapchain); r != XR_SUCCESS) return r;
  registerHandle(swapchain.get());
  *out = toHandle<XrSwapchain>(swapchain.get());
  session->swapchains.push_back(std::move(swapchain));
  return XR_SUCCESS;
}

XrResult destroySwapchainEntry(XrSwapchain handle) {
  Swapchain* swapchain = lookup<Swapchain>(handle);
  if (swapchain == nullptr) return fail("xrDestroySwapchain", XR_ERROR_HANDLE_INVALID, "swapchain");
  destroySwapchain(swapchain);
  return XR_SUCCESS;
}

XrResult enumerateSwapchainImages(XrSwapchain handle, uint32_t capacity, uint32_t* countOutput,
                                  XrSwapchainImageBaseHeader* images) {
  constexpr const char* cmd = "xrEnumerateSwapchainImages";
  const Swapchain* swapchain = lookup<Swapchain>(handle);
  if (swapchain == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "swapchain is not valid");
  MOCK_VERIFY_NOT_NULL(cmd, countOutput);
  *countOutput = swapchain->imageCount;
  if (capacity == 0) return XR_SUCCESS;
  if (capacity < swapchain->imageCount)
    return fail(cmd, XR_ERROR_SIZE_INSUFFICIENT, "capacity %u < %u", capacity,
                swapchain->imageCount);
  MOCK_VERIFY_NOT_NULL(cmd, images);
  // The app passes an array of XrSwapchainImageVulkanKHR (same struct for enable2).
  auto* vk = reinterpret_cast<XrSwapchainImageVulkanKHR*>(images);
  for (uint32_t i = 0; i < swapchain->imageCount; ++i) {
    if (vk[i].type != XR_TYPE_SWAPCHAIN_IMAGE_VULKAN_KHR)
      return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "(images[%u].type) is %d, expected Vulkan", i,
                  int(vk[i].type));
  }
  for (uint32_t i = 0; i < swapchain->imageCount; ++i) vk[i].image = swapchain->images[i];
  return XR_SUCCESS;
}

XrResult acquireSwapchainImage(XrSwapchain handle, const XrSwapchainImageAcquireInfo* info,
                               uint32_t* index) {
  constexpr const char* cmd = "xrAcquireSwapchainImage";
  Swapchain* swapchain = lookup<Swapchain>(handle);
  if (swapchain == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "swapchain is not valid");
  if (info != nullptr) MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_SWAPCHAIN_IMAGE_ACQUIRE_INFO);
  MOCK_VERIFY_NOT_NULL(cmd, index);
  if (swapchain->staticImageUsed)
    return fail(cmd, XR_ERROR_CALL_ORDER_INVALID, "a static swapchain is acquired only once");
  if (swapchain->acquired.size() >= swapchain->imageCount)
    return fail(cmd, XR_ERROR_CALL_ORDER_INVALID, "every image is already acquired");
  const uint32_t i = swapchain->nextIndex;
  if (XrResult r = prepareVulkanImage(cmd, *swapchain, i); r != XR_SUCCESS) return r;
  swapchain->nextIndex = (i + 1) % swapchain->imageCount;
  swapchain->acquired.push_back(i);
  if (swapchain->info.createFlags & XR_SWAPCHAIN_CREATE_STATIC_IMAGE_BIT)
    swapchain->staticImageUsed = true;
  *index = i;
  return XR_SUCCESS;
}

XrResult waitSwapchainImage(XrSwapchain handle, const XrSwapchainImageWaitInfo* info) {
  constexpr const char* cmd = "xrWaitSwapchainImage";
  Swapchain* swapchain = lookup<Swapchain>(handle);
  if (swapchain == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "swapchain is not valid");
  MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO);
  if (swapchain->acquired.empty())
    return fail(cmd, XR_ERROR_CALL_ORDER_INVALID, "no image acquired");
  if (swapchain->waited)
    return fail(cmd, XR_ERROR_CALL_ORDER_INVALID, "the waited image has not been released");
  swapchain->waited = true;  // images are idle at once: nothing of ours reads them later
  return XR_SUCCESS;
}

XrResult releaseSwapchainImage(XrSwapchain handle, const XrSwapchainImageReleaseInfo* info) {
  constexpr const char* cmd = "xrReleaseSwapchainImage";
  Swapchain* swapchain = lookup<Swapchain>(handle);
  if (swapchain == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "swapchain is not valid");
  if (info != nullptr) MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_SWAPCHAIN_IMAGE_RELEASE_INFO);
  if (!swapchain->waited)
    return fail(cmd, XR_ERROR_CALL_ORDER_INVALID, "no waited image to release");
  swapchain->lastReleased = swapchain->acquired.front();
  swapchain->acquired.pop_front();
  swapchain->waited = false;
  return XR_SUCCESS;
}

}  // namespace sdfg::mock
