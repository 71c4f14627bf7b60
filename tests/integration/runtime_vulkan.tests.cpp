// XR_KHR_vulkan_enable2 on lavapipe, in process: the runtime creates the app's VkInstance and
// VkDevice, hands out swapchain images in COLOR_ATTACHMENT_OPTIMAL, checks the acquire / wait /
// release order, and copies the submitted image to memory, where the test reads back the exact
// colour it cleared. The Khronos Vulkan validation layer and the OpenXR core validation layer
// are both on, and neither may report anything.
#include <vulkan/vulkan.h>
// openxr_platform.h needs the Vulkan types first.
#define XR_USE_GRAPHICS_API_VULKAN
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>

#include <catch2/catch.hpp>

#include <cstring>
#include <string>
#include <vector>

#include "xr_test_support.h"

using sdfg::test::XrHarness;

namespace {

std::vector<std::string>& vulkanMessages() {
  static std::vector<std::string> messages;
  return messages;
}

VKAPI_ATTR VkBool32 VKAPI_CALL onVulkanMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                               VkDebugUtilsMessageTypeFlagsEXT,
                                               const VkDebugUtilsMessengerCallbackDataEXT* data,
                                               void*) {
  if (severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT)
    vulkanMessages().push_back(data->pMessage);
  return VK_FALSE;
}

bool hasValidationLayer() {
  uint32_t count = 0;
  vkEnumerateInstanceLayerProperties(&count, nullptr);
  std::vector<VkLayerProperties> layers(count);
  vkEnumerateInstanceLayerProperties(&count, layers.data());
  for (const auto& l : layers) {
    if (std::strcmp(l.layerName, "VK_LAYER_KHRONOS_validation") == 0) return true;
  }
  return false;
}

// The app side: Vulkan objects made through the runtime, and one session with one swapchain.
struct VulkanApp {
  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  VkPhysicalDevice physicalDevice = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  uint32_t family = 0;
  VkQueue queue = VK_NULL_HANDLE;
  VkCommandPool pool = VK_NULL_HANDLE;
  XrSession session = XR_NULL_HANDLE;
  XrSwapchain swapchain = XR_NULL_HANDLE;
  std::vector<VkImage> images;
  XrSpace local = XR_NULL_HANDLE;

  ~VulkanApp() {
    if (session != XR_NULL_HANDLE) xrDestroySession(session);  // takes the swapchain with it
    if (device != VK_NULL_HANDLE) {
      vkDeviceWaitIdle(device);
      if (pool != VK_NULL_HANDLE) vkDestroyCommandPool(device, pool, nullptr);
      vkDestroyDevice(device, nullptr);
    }
    if (messenger != VK_NULL_HANDLE) {
      auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
      destroy(instance, messenger, nullptr);
    }
    if (instance != VK_NULL_HANDLE) vkDestroyInstance(instance, nullptr);
  }
};

constexpr uint32_t kSize = 64;

void setUp(const XrHarness& xr, VulkanApp& app) {
  auto requirements =
      xr.proc<PFN_xrGetVulkanGraphicsRequirements2KHR>("xrGetVulkanGraphicsRequirements2KHR");
  auto createInstance = xr.proc<PFN_xrCreateVulkanInstanceKHR>("xrCreateVulkanInstanceKHR");
  auto getDevice = xr.proc<PFN_xrGetVulkanGraphicsDevice2KHR>("xrGetVulkanGraphicsDevice2KHR");
  auto createDevice = xr.proc<PFN_xrCreateVulkanDeviceKHR>("xrCreateVulkanDeviceKHR");
  REQUIRE(requirements != nullptr);
  REQUIRE(createDevice != nullptr);
  XrGraphicsRequirementsVulkan2KHR req{XR_TYPE_GRAPHICS_REQUIREMENTS_VULKAN2_KHR};
  REQUIRE(requirements(xr.instance(), xr.system(), &req) == XR_SUCCESS);
  CHECK(XR_VERSION_MAJOR(req.minApiVersionSupported) == 1);

  const char* layer = "VK_LAYER_KHRONOS_validation";
  const char* extension = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
  VkApplicationInfo appInfo{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  appInfo.apiVersion = VK_API_VERSION_1_1;
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &appInfo;
  ici.enabledLayerCount = 1;
  ici.ppEnabledLayerNames = &layer;
  ici.enabledExtensionCount = 1;
  ici.ppEnabledExtensionNames = &extension;
  XrVulkanInstanceCreateInfoKHR xi{XR_TYPE_VULKAN_INSTANCE_CREATE_INFO_KHR};
  xi.systemId = xr.system();
  xi.pfnGetInstanceProcAddr = &vkGetInstanceProcAddr;
  xi.vulkanCreateInfo = &ici;
  VkResult vr = VK_ERROR_UNKNOWN;
  REQUIRE(createInstance(xr.instance(), &xi, &app.instance, &vr) == XR_SUCCESS);
  REQUIRE(vr == VK_SUCCESS);
  VkDebugUtilsMessengerCreateInfoEXT mi{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  mi.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  mi.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                   VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                   VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  mi.pfnUserCallback = &onVulkanMessage;
  auto createMessenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
      vkGetInstanceProcAddr(app.instance, "vkCreateDebugUtilsMessengerEXT"));
  REQUIRE(createMessenger(app.instance, &mi, nullptr, &app.messenger) == VK_SUCCESS);

  XrVulkanGraphicsDeviceGetInfoKHR gi{XR_TYPE_VULKAN_GRAPHICS_DEVICE_GET_INFO_KHR};
  gi.systemId = xr.system();
  gi.vulkanInstance = app.instance;
  REQUIRE(getDevice(xr.instance(), &gi, &app.physicalDevice) == XR_SUCCESS);
  uint32_t familyCount = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(app.physicalDevice, &familyCount, nullptr);
  std::vector<VkQueueFamilyProperties> families(familyCount);
  vkGetPhysicalDeviceQueueFamilyProperties(app.physicalDevice, &familyCount, families.data());
  while (app.family < familyCount && !(families[app.family].queueFlags & VK_QUEUE_GRAPHICS_BIT))
    ++app.family;
  REQUIRE(app.family < familyCount);
  const float priority = 0.0f;
  VkDeviceQueueCreateInfo qi{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qi.queueFamilyIndex = app.family;
  qi.queueCount = 1;
  qi.pQueuePriorities = &priority;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qi;
  XrVulkanDeviceCreateInfoKHR xd{XR_TYPE_VULKAN_DEVICE_CREATE_INFO_KHR};
  xd.systemId = xr.system();
  xd.pfnGetInstanceProcAddr = &vkGetInstanceProcAddr;
  xd.vulkanPhysicalDevice = app.physicalDevice;
  xd.vulkanCreateInfo = &dci;
  REQUIRE(createDevice(xr.instance(), &xd, &app.device, &vr) == XR_SUCCESS);
  REQUIRE(vr == VK_SUCCESS);
  vkGetDeviceQueue(app.device, app.family, 0, &app.queue);
  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.queueFamilyIndex = app.family;
  REQUIRE(vkCreateCommandPool(app.device, &pci, nullptr, &app.pool) == VK_SUCCESS);

  XrGraphicsBindingVulkan2KHR binding{XR_TYPE_GRAPHICS_BINDING_VULKAN2_KHR};
  binding.instance = app.instance;
  binding.physicalDevice = app.physicalDevice;
  binding.device = app.device;
  binding.queueFamilyIndex = app.family;
  binding.queueIndex = 0;
  XrSessionCreateInfo si{XR_TYPE_SESSION_CREATE_INFO};
  si.next = &binding;
  si.systemId = xr.system();
  REQUIRE(xrCreateSession(xr.instance(), &si, &app.session) == XR_SUCCESS);

  uint32_t formatCount = 0;
  REQUIRE(xrEnumerateSwapchainFormats(app.session, 0, &formatCount, nullptr) == XR_SUCCESS);
  std::vector<int64_t> formats(formatCount);
  REQUIRE(xrEnumerateSwapchainFormats(app.session, formatCount, &formatCount, formats.data()) ==
          XR_SUCCESS);
  REQUIRE(std::find(formats.begin(), formats.end(), VK_FORMAT_R8G8B8A8_UNORM) != formats.end());
  XrSwapchainCreateInfo sci{XR_TYPE_SWAPCHAIN_CREATE_INFO};
  sci.usageFlags = XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT | XR_SWAPCHAIN_USAGE_TRANSFER_DST_BIT;
  sci.format = VK_FORMAT_R8G8B8A8_UNORM;  // UNORM: the cleared values come back unchanged
  sci.sampleCount = sci.faceCount = sci.arraySize = sci.mipCount = 1;
  sci.width = sci.height = kSize;
  REQUIRE(xrCreateSwapchain(app.session, &sci, &app.swapchain) == XR_SUCCESS);
  uint32_t imageCount = 0;
  REQUIRE(xrEnumerateSwapchainImages(app.swapchain, 0, &imageCount, nullptr) == XR_SUCCESS);
  std::vector<XrSwapchainImageVulkan2KHR> images(imageCount, {XR_TYPE_SWAPCHAIN_IMAGE_VULKAN2_KHR});
  REQUIRE(xrEnumerateSwapchainImages(
              app.swapchain, imageCount, &imageCount,
              reinterpret_cast<XrSwapchainImageBaseHeader*>(images.data())) == XR_SUCCESS);
  for (const auto& i : images) app.images.push_back(i.image);

  XrReferenceSpaceCreateInfo rsi{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
  rsi.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_LOCAL;
  rsi.poseInReferenceSpace.orientation.w = 1;
  REQUIRE(xrCreateReferenceSpace(app.session, &rsi, &app.local) == XR_SUCCESS);
  xr.pollStates();
  REQUIRE(xr.begin(app.session) == XR_SUCCESS);
}

// Clears `image` (in COLOR_ATTACHMENT_OPTIMAL, as the runtime promises) and leaves it there.
void clear(VulkanApp& app, VkImage image, VkClearColorValue colour) {
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = app.pool;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VkCommandBuffer cb = VK_NULL_HANDLE;
  REQUIRE(vkAllocateCommandBuffers(app.device, &ai, &cb) == VK_SUCCESS);
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  vkBeginCommandBuffer(cb, &bi);
  const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  VkImageMemoryBarrier toDst{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  toDst.srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  toDst.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  toDst.oldLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  toDst.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  toDst.srcQueueFamilyIndex = toDst.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  toDst.image = image;
  toDst.subresourceRange = range;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                       VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0, nullptr, 1, &toDst);
  vkCmdClearColorImage(cb, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &colour, 1, &range);
  VkImageMemoryBarrier back = toDst;
  back.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  back.dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  back.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  back.newLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT,
                       VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, 0, 0, nullptr, 0, nullptr, 1,
                       &back);
  vkEndCommandBuffer(cb);
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cb;
  REQUIRE(vkQueueSubmit(app.queue, 1, &si, VK_NULL_HANDLE) == VK_SUCCESS);
  vkQueueWaitIdle(app.queue);
  vkFreeCommandBuffers(app.device, app.pool, 1, &cb);
}

// One frame that clears the next swapchain image and submits it for both eyes.
void renderFrame(const XrHarness& xr, VulkanApp& app, VkClearColorValue colour) {
  XrFrameState state{XR_TYPE_FRAME_STATE};
  REQUIRE(xrWaitFrame(app.session, nullptr, &state) == XR_SUCCESS);
  REQUIRE(xrBeginFrame(app.session, nullptr) == XR_SUCCESS);
  XrViewLocateInfo li{XR_TYPE_VIEW_LOCATE_INFO};
  li.viewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
  li.displayTime = state.predictedDisplayTime;
  li.space = app.local;
  XrViewState viewState{XR_TYPE_VIEW_STATE};
  XrView views[2] = {{XR_TYPE_VIEW}, {XR_TYPE_VIEW}};
  uint32_t viewCount = 0;
  REQUIRE(xrLocateViews(app.session, &li, &viewState, 2, &viewCount, views) == XR_SUCCESS);
  uint32_t index = 0;
  REQUIRE(xrAcquireSwapchainImage(app.swapchain, nullptr, &index) == XR_SUCCESS);
  XrSwapchainImageWaitInfo wi{XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO};
  wi.timeout = XR_INFINITE_DURATION;
  REQUIRE(xrWaitSwapchainImage(app.swapchain, &wi) == XR_SUCCESS);
  clear(app, app.images[index], colour);
  REQUIRE(xrReleaseSwapchainImage(app.swapchain, nullptr) == XR_SUCCESS);
  XrCompositionLayerProjectionView pv[2] = {{XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW},
                                            {XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW}};
  for (int i = 0; i < 2; ++i) {
    pv[i].pose = views[i].pose;
    pv[i].fov = views[i].fov;
    pv[i].subImage.swapchain = app.swapchain;
    pv[i].subImage.imageRect = {{0, 0}, {int32_t(kSize), int32_t(kSize)}};
  }
  XrCompositionLayerProjection layer{XR_TYPE_COMPOSITION_LAYER_PROJECTION};
  layer.space = app.local;
  layer.viewCount = 2;
  layer.views = pv;
  const XrCompositionLayerBaseHeader* layers[] = {
      reinterpret_cast<XrCompositionLayerBaseHeader*>(&layer)};
  XrFrameEndInfo end{XR_TYPE_FRAME_END_INFO};
  end.displayTime = state.predictedDisplayTime;
  end.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
  end.layerCount = 1;
  end.layers = layers;
  REQUIRE(xrEndFrame(app.session, &end) == XR_SUCCESS);
  (void)xr;
}

}  // namespace

TEST_CASE("A Vulkan2 app's submitted pixels reach the runtime's capture", "[runtime][vulkan]") {
  sdfg::test::useMockRuntime();
  if (!hasValidationLayer())
    FAIL("VK_LAYER_KHRONOS_validation is missing (install vulkan-validationlayers)");
  sdfg::test::ScopedEnv noCache("VK_LAYER_DISABLES",
                                "VK_VALIDATION_FEATURE_DISABLE_SHADER_VALIDATION_CACHE_EXT");
  vulkanMessages().clear();
  sdfg::test::InstanceOptions options;
  options.extensions = {"XR_KHR_vulkan_enable2"};
  XrHarness xr(options);
  REQUIRE(xr.createResult() == XR_SUCCESS);
  REQUIRE(xr.setScript("capture 1\n") == XR_SUCCESS);
  auto getCapture = xr.proc<PFN_xrMockRuntimeGetCaptureSDFG>("xrMockRuntimeGetCaptureSDFG");
  REQUIRE(getCapture != nullptr);
  {
    VulkanApp app;
    setUp(xr, app);

    SECTION("Every pixel of the capture is the colour the app cleared to, frame after frame") {
      for (const VkClearColorValue colour : {VkClearColorValue{{1.0f, 0.5f, 0.25f, 1.0f}},
                                             VkClearColorValue{{0.0f, 1.0f, 0.0f, 0.5f}}}) {
        renderFrame(xr, app, colour);
        uint32_t w = 0, h = 0;
        REQUIRE(getCapture(app.session, 0, 0, &w, &h, nullptr) == XR_SUCCESS);
        REQUIRE(w == kSize);
        REQUIRE(h == kSize);
        std::vector<uint8_t> rgba(size_t(w) * h * 4);
        REQUIRE(getCapture(app.session, 0, uint32_t(rgba.size()), &w, &h, rgba.data()) ==
                XR_SUCCESS);
        size_t wrong = 0;
        for (size_t i = 0; i < rgba.size(); i += 4) {
          for (int c = 0; c < 4; ++c) {
            const int expected = int(colour.float32[c] * 255.0f + 0.5f);
            if (std::abs(int(rgba[i + size_t(c)]) - expected) > 1) ++wrong;
          }
        }
        CHECK(wrong == 0);
      }
      const XrMockRuntimeStatsSDFG stats = xr.stats(app.session);
      CHECK(stats.framesWithLayers == 2);
      CHECK(stats.framesCaptured == 2);
      uint32_t w = 0, h = 0;
      uint8_t small[4];
      CHECK(getCapture(app.session, 1, 4, &w, &h, small) == XR_ERROR_SIZE_INSUFFICIENT);
    }
    SECTION("Swapchain images are waited and released in order") {
      XrSwapchainImageWaitInfo wi{XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO};
      wi.timeout = XR_INFINITE_DURATION;
      CHECK(xrWaitSwapchainImage(app.swapchain, &wi) == XR_ERROR_CALL_ORDER_INVALID);
      CHECK(xrReleaseSwapchainImage(app.swapchain, nullptr) == XR_ERROR_CALL_ORDER_INVALID);
      uint32_t index = 0;
      REQUIRE(xrAcquireSwapchainImage(app.swapchain, nullptr, &index) == XR_SUCCESS);
      CHECK(xrReleaseSwapchainImage(app.swapchain, nullptr) == XR_ERROR_CALL_ORDER_INVALID);
      REQUIRE(xrWaitSwapchainImage(app.swapchain, &wi) == XR_SUCCESS);
      CHECK(xrWaitSwapchainImage(app.swapchain, &wi) == XR_ERROR_CALL_ORDER_INVALID);
      CHECK(xrReleaseSwapchainImage(app.swapchain, nullptr) == XR_SUCCESS);
      uint32_t more = 0;
      for (size_t i = 0; i < app.images.size(); ++i)
        REQUIRE(xrAcquireSwapchainImage(app.swapchain, nullptr, &more) == XR_SUCCESS);
      CHECK(xrAcquireSwapchainImage(app.swapchain, nullptr, &more) == XR_ERROR_CALL_ORDER_INVALID);
    }
  }
  for (const auto& m : vulkanMessages()) UNSCOPED_INFO(m);
  CHECK(vulkanMessages().empty());
  CHECK(xr.validationMessages().empty());
}

TEST_CASE("The Vulkan validation check bites: skipping the layout transition is reported",
          "[runtime][vulkan]") {
  sdfg::test::useMockRuntime();
  if (!hasValidationLayer())
    FAIL("VK_LAYER_KHRONOS_validation is missing (install vulkan-validationlayers)");
  sdfg::test::ScopedEnv noCache("VK_LAYER_DISABLES",
                                "VK_VALIDATION_FEATURE_DISABLE_SHADER_VALIDATION_CACHE_EXT");
  vulkanMessages().clear();
  sdfg::test::InstanceOptions options;
  options.extensions = {"XR_KHR_vulkan_enable2"};
  options.env = {{SDFG_MOCK_ENV_FAULT, "skip_layout_transition"}};
  XrHarness xr(options);
  REQUIRE(xr.createResult() == XR_SUCCESS);
  {
    VulkanApp app;
    setUp(xr, app);
    renderFrame(xr, app, VkClearColorValue{{1.0f, 0.0f, 0.0f, 1.0f}});
  }
  CHECK_FALSE(vulkanMessages().empty());
}
