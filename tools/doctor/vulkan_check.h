// Which Vulkan device the runtime would hand a Vulkan app (xrGetVulkanGraphicsDevice(2)KHR), as
// the layer then sees it in the session's graphics binding: its name and whether it is a GPU or a
// CPU implementation of Vulkan, which decides where the layer builds grab-box SDFs (docs/layer.md,
// "SDFs on the app's Vulkan device"). The Vulkan loader is opened at run time, as the layer takes
// the app's: a machine without one gets a diagnosis.
#pragma once

#include <string>

// Vulkan's types first: openxr_platform.h's Vulkan part uses them. No prototypes: every Vulkan
// function comes from the loader opened at run time.
#define VK_NO_PROTOTYPES
#include <vulkan/vulkan.h>

#define XR_USE_GRAPHICS_API_VULKAN
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>

namespace sdfg::doctor {

struct RuntimeVulkanDevice {
  std::string error;  // empty when the device was found
  std::string name;
  VkPhysicalDeviceType type = VK_PHYSICAL_DEVICE_TYPE_OTHER;
};

// Asks the runtime of `instance` (created with XR_KHR_vulkan_enable2 when `enable2`, else with
// XR_KHR_vulkan_enable) for the device of `system`, through a Vulkan instance made as such an app
// makes one.
RuntimeVulkanDevice runtimeVulkanDevice(XrInstance instance, XrSystemId system,
                                        PFN_xrGetInstanceProcAddr getProcAddr, bool enable2);

const char* deviceTypeName(VkPhysicalDeviceType type);

}  // namespace sdfg::doctor
