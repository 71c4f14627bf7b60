#include "vulkan_check.h"

#include <algorithm>
#include <memory>
#include <sstream>
#include <vector>

#include "system.h"

namespace sdfg::doctor {
namespace {

// A Vulkan instance destroyed with this object.
class VulkanInstance {
 public:
  VulkanInstance(PFN_vkGetInstanceProcAddr getProcAddr, VkInstance handle)
      : getProcAddr_(getProcAddr), handle_(handle) {}
  ~VulkanInstance() {
    if (handle_ == VK_NULL_HANDLE) return;
    if (auto destroy =
            reinterpret_cast<PFN_vkDestroyInstance>(getProcAddr_(handle_, "vkDestroyInstance")))
      destroy(handle_, nullptr);
  }
  VulkanInstance(const VulkanInstance&) = delete;
  VulkanInstance& operator=(const VulkanInstance&) = delete;
  VkInstance get() const { return handle_; }

 private:
  PFN_vkGetInstanceProcAddr getProcAddr_;
  VkInstance handle_;
};

template <class F>
F xrFunction(PFN_xrGetInstanceProcAddr getProcAddr, XrInstance instance, const char* name) {
  PFN_xrVoidFunction f = nullptr;
  if (getProcAddr(instance, name, &f) != XR_SUCCESS) return nullptr;
  return reinterpret_cast<F>(f);
}

std::string xrFailure(const char* call, XrResult r) {
  return std::string(call) + " failed (" + std::to_string(int(r)) + ")";
}

// The lowest Vulkan version the runtime accepts, as the app's instance asks for it.
uint32_t apiVersionFor(const XrGraphicsRequirementsVulkanKHR& req) {
  const uint32_t major = uint32_t(XR_VERSION_MAJOR(req.minApiVersionSupported));
  const uint32_t minor = uint32_t(XR_VERSION_MINOR(req.minApiVersionSupported));
  return major >= 1 ? VK_MAKE_API_VERSION(0, major, minor, 0) : VK_API_VERSION_1_0;
}

}  // namespace

const char* deviceTypeName(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return "discrete GPU";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return "integrated GPU";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return "virtual GPU";
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return "CPU implementation of Vulkan";
    default:
      return "other";
  }
}

RuntimeVulkanDevice runtimeVulkanDevice(XrInstance instance, XrSystemId system,
                                        PFN_xrGetInstanceProcAddr getProcAddr, bool enable2) {
  RuntimeVulkanDevice out;
  std::string error;
  SharedLibrary loader = SharedLibrary::open(vulkanLoaderName(), error);
  if (!loader.isOpen()) {
    out.error = std::string("no Vulkan loader (") + vulkanLoaderName() + "): " + error;
    return out;
  }
  auto vkGetInstanceProcAddr =
      reinterpret_cast<PFN_vkGetInstanceProcAddr>(loader.symbol("vkGetInstanceProcAddr"));
  if (vkGetInstanceProcAddr == nullptr) {
    out.error = std::string(vulkanLoaderName()) + " has no vkGetInstanceProcAddr";
    return out;
  }

  // Both extensions' requirement calls take the same structure (the enable2 names are aliases).
  const char* requirementsName =
      enable2 ? "xrGetVulkanGraphicsRequirements2KHR" : "xrGetVulkanGraphicsRequirementsKHR";
  auto getRequirements =
      xrFunction<PFN_xrGetVulkanGraphicsRequirementsKHR>(getProcAddr, instance, requirementsName);
  XrGraphicsRequirementsVulkanKHR req{XR_TYPE_GRAPHICS_REQUIREMENTS_VULKAN_KHR};
  if (getRequirements == nullptr) {
    out.error = std::string("no ") + requirementsName;
    return out;
  }
  if (XrResult r = getRequirements(instance, system, &req); XR_FAILED(r)) {
    out.error = xrFailure(requirementsName, r);
    return out;
  }

  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "autograsp-doctor";
  app.apiVersion = apiVersionFor(req);
  VkInstanceCreateInfo ci{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ci.pApplicationInfo = &app;
  VkPhysicalDevice device = VK_NULL_HANDLE;
  std::unique_ptr<VulkanInstance> vk;
  if (enable2) {
    auto create = xrFunction<PFN_xrCreateVulkanInstanceKHR>(getProcAddr, instance,
                                                            "xrCreateVulkanInstanceKHR");
    auto getDevice = xrFunction<PFN_xrGetVulkanGraphicsDevice2KHR>(getProcAddr, instance,
                                                                   "xrGetVulkanGraphicsDevice2KHR");
    if (create == nullptr || getDevice == nullptr) {
      out.error = "XR_KHR_vulkan_enable2's functions are missing";
      return out;
    }
    XrVulkanInstanceCreateInfoKHR info{XR_TYPE_VULKAN_INSTANCE_CREATE_INFO_KHR};
    info.systemId = system;
    info.pfnGetInstanceProcAddr = vkGetInstanceProcAddr;
    info.vulkanCreateInfo = &ci;
    VkInstance handle = VK_NULL_HANDLE;
    VkResult vr = VK_SUCCESS;
    if (XrResult r = create(instance, &info, &handle, &vr); XR_FAILED(r) || vr != VK_SUCCESS) {
      out.error = XR_FAILED(r) ? xrFailure("xrCreateVulkanInstanceKHR", r)
                               : "vkCreateInstance failed (" + std::to_string(int(vr)) + ")";
      return out;
    }
    vk = std::make_unique<VulkanInstance>(vkGetInstanceProcAddr, handle);
    XrVulkanGraphicsDeviceGetInfoKHR get{XR_TYPE_VULKAN_GRAPHICS_DEVICE_GET_INFO_KHR};
    get.systemId = system;
    get.vulkanInstance = handle;
    if (XrResult r = getDevice(instance, &get, &device); XR_FAILED(r)) {
      out.error = xrFailure("xrGetVulkanGraphicsDevice2KHR", r);
      return out;
    }
  } else {
    // XR_KHR_vulkan_enable: the app makes its instance itself, with the extensions the runtime
    // names (one space-separated string).
    auto getExtensions = xrFunction<PFN_xrGetVulkanInstanceExtensionsKHR>(
        getProcAddr, instance, "xrGetVulkanInstanceExtensionsKHR");
    auto getDevice = xrFunction<PFN_xrGetVulkanGraphicsDeviceKHR>(getProcAddr, instance,
                                                                  "xrGetVulkanGraphicsDeviceKHR");
    if (getExtensions == nullptr || getDevice == nullptr) {
      out.error = "XR_KHR_vulkan_enable's functions are missing";
      return out;
    }
    uint32_t size = 0;
    if (XrResult r = getExtensions(instance, system, 0, &size, nullptr); XR_FAILED(r)) {
      out.error = xrFailure("xrGetVulkanInstanceExtensionsKHR", r);
      return out;
    }
    std::string names(size, '\0');
    if (XrResult r = getExtensions(instance, system, size, &size, names.data()); XR_FAILED(r)) {
      out.error = xrFailure("xrGetVulkanInstanceExtensionsKHR", r);
      return out;
    }
    names.resize(std::min(names.size(), names.find('\0')));
    std::vector<std::string> list;
    std::istringstream words(names);
    for (std::string w; words >> w;) list.push_back(w);
    std::vector<const char*> pointers;
    for (const std::string& w : list) pointers.push_back(w.c_str());
    ci.enabledExtensionCount = uint32_t(pointers.size());
    ci.ppEnabledExtensionNames = pointers.data();
    auto createInstance =
        reinterpret_cast<PFN_vkCreateInstance>(vkGetInstanceProcAddr(nullptr, "vkCreateInstance"));
    if (createInstance == nullptr) {
      out.error = "the Vulkan loader has no vkCreateInstance";
      return out;
    }
    VkInstance handle = VK_NULL_HANDLE;
    if (VkResult vr = createInstance(&ci, nullptr, &handle); vr != VK_SUCCESS) {
      out.error = "vkCreateInstance failed (" + std::to_string(int(vr)) + ")";
      return out;
    }
    vk = std::make_unique<VulkanInstance>(vkGetInstanceProcAddr, handle);
    if (XrResult r = getDevice(instance, system, handle, &device); XR_FAILED(r)) {
      out.error = xrFailure("xrGetVulkanGraphicsDeviceKHR", r);
      return out;
    }
  }
  auto properties = reinterpret_cast<PFN_vkGetPhysicalDeviceProperties>(
      vkGetInstanceProcAddr(vk->get(), "vkGetPhysicalDeviceProperties"));
  if (properties == nullptr || device == VK_NULL_HANDLE) {
    out.error = "no device properties";
    return out;
  }
  VkPhysicalDeviceProperties p{};
  properties(device, &p);
  out.name = p.deviceName;
  out.type = p.deviceType;
  return out;
}

}  // namespace sdfg::doctor
