// The Vulkan path of the layer: grab-box SDFs built on the app's Vulkan device by the core's
// VkGraspBackend. What this file translates:
// - Vulkan entry points. Enable2 apps pass their vkGetInstanceProcAddr in
//   xrCreateVulkanInstanceKHR / xrCreateVulkanDeviceKHR: recorded per VkInstance. Enable (v1) apps
//   create their instance with the Vulkan loader they link; the layer takes that loader's
//   vkGetInstanceProcAddr from the process (platform.h: never loads a second copy). The layer
//   links no Vulkan loader.
// - Queues. The binding's queue is externally synchronized and the runtime may use it only in
//   xrBeginFrame, xrEndFrame, xrAcquireSwapchainImage and xrReleaseSwapchainImage, where the app
//   guarantees exclusive access: the layer submits on it only inside xrBeginFrame / xrEndFrame.
//   For enable2 apps the layer asks one more queue of a family the app uses when the family has
//   a spare one (xrCreateVulkanDeviceKHR); builds of CPU-array targets go there right after
//   xrSyncActions.
// - Failures: the backend logs one line and the session continues on the CPU.
#include <exception>
#include <vector>

#include "intercepts.h"
#include "log.h"
#include "platform.h"
#include "state.h"

#if SDFG_LAYER_VULKAN
#include "vulkan/vk_extra_queue.h"
#include "vulkan/vk_grasp_backend.h"
#endif

namespace sdfg::layer {
namespace {

std::shared_ptr<InstanceState> instanceOf(XrInstance handle) {
  return instances().find(key(handle));
}

#if SDFG_LAYER_VULKAN
// The app's Vulkan loader entry point for `vkInstance`.
PFN_vkGetInstanceProcAddr appGetInstanceProcAddr(InstanceState& inst, VkInstance vkInstance) {
  {
    std::lock_guard lock(inst.vulkanMutex);
    auto it = inst.vulkanGipa.find(key(vkInstance));
    if (it != inst.vulkanGipa.end()) return it->second;
  }
  // Enable (v1): the loader the app linked (or loaded) is in the process already.
  return reinterpret_cast<PFN_vkGetInstanceProcAddr>(platform::loadedVulkanGetInstanceProcAddr());
}

VkGraspFault faultFromConfig(const std::string& name) {
  if (name == "lost_at_submit") return VkGraspFault::lostAtSubmit;
  if (name == "lost_at_poll") return VkGraspFault::lostAtPoll;
  if (name == "never_ready") return VkGraspFault::neverReady;
  if (name == "stuck_reads_once") return VkGraspFault::stuckReadsOnce;
  return VkGraspFault::none;
}
#endif

}  // namespace

#if SDFG_LAYER_VULKAN
VulkanDevice appVulkanDevice(SessionState& s) {
  const XrGraphicsBindingVulkanKHR& b = s.vulkanBinding;
  VulkanDevice app;
  app.instance = b.instance;
  app.physicalDevice = b.physicalDevice;
  app.device = b.device;
  app.queueFamilyIndex = b.queueFamilyIndex;
  app.queueIndex = b.queueIndex;
  app.getInstanceProcAddr = appGetInstanceProcAddr(*s.instance, b.instance);
  return app;
}
#endif

std::unique_ptr<DeferredSdfBackend> makeVulkanBackend(SessionState& s) {
  constexpr const char* cmd = "xrCreateSession";
  s.gpu = nullptr;
  s.ownQueue = false;
  s.gpuForArrayTargets = false;
  if (!s.vulkan) return nullptr;
#if SDFG_LAYER_VULKAN
  InstanceState& inst = *s.instance;
  if (inst.config.gpu == Config::Gpu::off) {
    SDFG_LOG_INFO(cmd, "gpu = off: grab-box SDFs on the CPU");
    return nullptr;
  }
  const XrGraphicsBindingVulkanKHR& b = s.vulkanBinding;
  const VulkanDevice app = appVulkanDevice(s);
  if (app.getInstanceProcAddr == nullptr) {
    SDFG_LOG_WARN(cmd, "no Vulkan loader in the process: grab-box SDFs on the CPU");
    return nullptr;
  }
  std::optional<VulkanDevice> own;
  {
    std::lock_guard lock(inst.vulkanMutex);
    auto it = inst.extraQueues.find(key(b.device));
    if (it != inst.extraQueues.end()) {
      own = app;
      own->queueFamilyIndex = it->second.family;
      own->queueIndex = it->second.index;
    }
  }
  VkGraspBackendOptions options;
  options.log = [](const std::string& line) { SDFG_LOG_WARN("sdfg vulkan", "%s", line.c_str()); };
  // Pipelines are made on the backend's own thread and warmed up by small builds in the first
  // frames: neither this xrCreateSession nor the user's first grab waits for the driver's
  // compiler (seconds on lavapipe with a cold shader cache). Grabs before then use the CPU.
  options.prepareInBackground = true;
  auto backend = VkGraspBackend::create(app, own ? &*own : nullptr, options);
  if (!backend) {
    SDFG_LOG_WARN(cmd, "Vulkan SDF backend unavailable, grab-box SDFs on the CPU: %s",
                  backend.error().message.c_str());
    return nullptr;
  }
  (*backend)->injectFault(faultFromConfig(inst.config.testGpuFault));
  s.ownQueue = own.has_value();
  // A CPU implementation of Vulkan runs our compute passes on the cores the CPU builder would
  // use, several times slower (docs/benchmarks-vulkan.md): with gpu = auto only targets that
  // exist solely in the app's buffers go there.
  VkPhysicalDeviceProperties props{};
  if (auto getProps = reinterpret_cast<PFN_vkGetPhysicalDeviceProperties>(
          app.getInstanceProcAddr(b.instance, "vkGetPhysicalDeviceProperties")))
    getProps(b.physicalDevice, &props);
  const bool cpuDevice = props.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
  s.gpuForArrayTargets = inst.config.gpu == Config::Gpu::on || !cpuDevice;
  SDFG_LOG_INFO(
      cmd, "grab-box SDFs of %s on the app's Vulkan device '%s' (%s)",
      s.gpuForArrayTargets ? "every target" : "buffer targets only (gpu = auto, CPU device)",
      props.deviceName,
      s.ownQueue ? "the layer's own queue" : "the app's queue inside frame calls");
  // The engine records builds through the mailbox under the session's lock; pumpGpu() makes the
  // device calls with no lock held.
  s.gpu = std::make_shared<DeferredMailbox>(std::move(backend.value()));
  return DeferredMailbox::ownerSide(s.gpu);
#else
  SDFG_LOG_INFO(cmd, "built without the Vulkan backend: grab-box SDFs on the CPU");
  return nullptr;
#endif
}

void pumpGpu(SessionState& s, bool inFrame) {
  std::shared_ptr<DeferredMailbox> gpu;
  {
    std::lock_guard lock(s.mutex);
    gpu = s.gpu;
  }
  // A pump on another thread is not waited for: it, or the next, does the work. A device
  // failure is the backend's to log (once) and shows in the engine as failed (CPU from then on).
  if (gpu == nullptr) return;
  // A device call that throws (out of memory in the backend) ends the pump only: the mailbox has
  // given the device back, and the app's call, whose own work is done, succeeds.
  try {
    (void)gpu->pump(inFrame);
  } catch (const std::exception& e) {
    SDFG_LOG_WARN("sdfg vulkan", "a GPU call failed (%s); the next pump goes on", e.what());
  } catch (...) {
    SDFG_LOG_WARN("sdfg vulkan", "a GPU call failed; the next pump goes on");
  }
}

namespace {

// xrBeginFrame and xrEndFrame: the app holds its queue for the runtime during these calls, so
// pending builds may go on it before the call goes down.
template <typename Info, typename Next>
XrResult pumpThenCallDown(const char* cmd, XrSession session, const Info* info, Next next) {
  auto s = sessions().find(key(session));
  if (s == nullptr) return logError(XR_ERROR_HANDLE_INVALID, cmd, "(session) is not valid");
  if (s->vulkan) {
    try {
      pumpGpu(*s, true);
    } catch (...) {
      SDFG_LOG_WARN(cmd, "GPU submission failed; the call goes down as the app made it");
    }
  }
  return (s->instance->next.*next)(session, info);
}

}  // namespace

XrResult XRAPI_CALL SdfgXrBeginFrame(XrSession session, const XrFrameBeginInfo* info) {
  constexpr const char* cmd = "xrBeginFrame";
  SDFG_ENTRY_BEGIN
  return pumpThenCallDown(cmd, session, info, &NextDispatch::xrBeginFrame);
  SDFG_ENTRY_END(cmd)
}

XrResult XRAPI_CALL SdfgXrEndFrame(XrSession session, const XrFrameEndInfo* info) {
  constexpr const char* cmd = "xrEndFrame";
  SDFG_ENTRY_BEGIN
  // The depth the app submits with this frame (depth_capture.h); changes nothing passed down.
  if (auto s = sessions().find(key(session)); s != nullptr && s->depth != nullptr)
    captureDepthAtEndFrame(*s, info);
  return pumpThenCallDown(cmd, session, info, &NextDispatch::xrEndFrame);
  SDFG_ENTRY_END(cmd)
}

XrResult XRAPI_CALL SdfgXrCreateVulkanInstanceKHR(XrInstance instance,
                                                  const XrVulkanInstanceCreateInfoKHR* info,
                                                  VkInstance* vulkanInstance,
                                                  VkResult* vulkanResult) {
  constexpr const char* cmd = "xrCreateVulkanInstanceKHR";
  SDFG_ENTRY_BEGIN
  auto state = instanceOf(instance);
  if (state == nullptr) return logError(XR_ERROR_HANDLE_INVALID, cmd, "(instance) is not valid");
  const XrResult r =
      state->next.xrCreateVulkanInstanceKHR(instance, info, vulkanInstance, vulkanResult);
  if (XR_SUCCEEDED(r) && info != nullptr && vulkanInstance != nullptr &&
      *vulkanInstance != VK_NULL_HANDLE && info->pfnGetInstanceProcAddr != nullptr) {
    std::lock_guard lock(state->vulkanMutex);
    state->vulkanGipa[key(*vulkanInstance)] = info->pfnGetInstanceProcAddr;
    state->lastVulkanInstance = *vulkanInstance;
  }
  return r;
  SDFG_ENTRY_END(cmd)
}

XrResult XRAPI_CALL SdfgXrCreateVulkanDeviceKHR(XrInstance instance,
                                                const XrVulkanDeviceCreateInfoKHR* info,
                                                VkDevice* device, VkResult* vulkanResult) {
  constexpr const char* cmd = "xrCreateVulkanDeviceKHR";
  SDFG_ENTRY_BEGIN
  auto state = instanceOf(instance);
  if (state == nullptr) return logError(XR_ERROR_HANDLE_INVALID, cmd, "(instance) is not valid");
  auto& next = state->next.xrCreateVulkanDeviceKHR;
#if SDFG_LAYER_VULKAN
  VkInstance vkInstance = VK_NULL_HANDLE;
  {
    std::lock_guard lock(state->vulkanMutex);
    vkInstance = state->lastVulkanInstance;
  }
  if (state->config.gpu != Config::Gpu::off && state->config.extraQueue && info != nullptr &&
      info->type == XR_TYPE_VULKAN_DEVICE_CREATE_INFO_KHR && info->vulkanCreateInfo != nullptr &&
      info->pfnGetInstanceProcAddr != nullptr && info->vulkanPhysicalDevice != VK_NULL_HANDLE &&
      vkInstance != VK_NULL_HANDLE && device != nullptr && vulkanResult != nullptr) {
    auto families = reinterpret_cast<PFN_vkGetPhysicalDeviceQueueFamilyProperties>(
        info->pfnGetInstanceProcAddr(vkInstance, "vkGetPhysicalDeviceQueueFamilyProperties"));
    std::vector<VkQueueFamilyProperties> props;
    if (families != nullptr) {
      uint32_t n = 0;
      families(info->vulkanPhysicalDevice, &n, nullptr);
      props.resize(n);
      families(info->vulkanPhysicalDevice, &n, props.data());
    }
    const ExtraQueuePlan plan = planExtraQueue(*info->vulkanCreateInfo, props);
    if (plan.planned) {
      VkDeviceCreateInfo dci = *info->vulkanCreateInfo;
      dci.queueCreateInfoCount = uint32_t(plan.queueInfos.size());
      dci.pQueueCreateInfos = plan.queueInfos.data();
      XrVulkanDeviceCreateInfoKHR copy = *info;
      copy.vulkanCreateInfo = &dci;
      const XrResult r = next(instance, &copy, device, vulkanResult);
      if (XR_SUCCEEDED(r) && *vulkanResult == VK_SUCCESS) {
        try {
          std::lock_guard lock(state->vulkanMutex);
          state->extraQueues[key(*device)] = {plan.family, plan.index};
        } catch (...) {
          // The app's device is fine as it is: the layer only does without its queue.
          SDFG_LOG_WARN(cmd, "could not record the layer's queue; the layer does without it");
          return r;
        }
        SDFG_LOG_INFO(cmd, "added queue %u of family %u for the layer", plan.index, plan.family);
        return r;
      }
      SDFG_LOG_WARN(cmd,
                    "the device refused the layer's extra queue (%d, %d); creating it as "
                    "the app asked",
                    int(r), int(*vulkanResult));
    }
  }
#endif
  return next(instance, info, device, vulkanResult);
  SDFG_ENTRY_END(cmd)
}

}  // namespace sdfg::layer
