// One more queue for the layer on the app's Vulkan device (XR_KHR_vulkan_enable2 apps, whose
// VkDeviceCreateInfo the layer sees in xrCreateVulkanDeviceKHR): a queue of its own can take the
// layer's compute submissions at any time instead of only inside xrBeginFrame / xrEndFrame.
//
// planExtraQueue picks a family the app already asks queues of, that has compute and a queue
// the app does not take (queueCount above what it requests), and returns the app's queue create
// infos with that family's count raised by one. Nothing is planned when no family qualifies
// (Mesa's lavapipe: one family, one queue) or the app's request is malformed; the app's device is
// then created unchanged. Pure function: testable without a device.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <vulkan/vulkan_core.h>

namespace sdfg {

struct ExtraQueuePlan {
  bool planned = false;
  uint32_t family = 0;  // the family of the extra queue
  uint32_t index = 0;   // its index in the family (the app's own queues keep 0..index-1)
  // The app's queue create infos with the one change; pQueuePriorities of the changed entry
  // point into `priorities`, so the plan must outlive the device creation call.
  std::vector<VkDeviceQueueCreateInfo> queueInfos;
  std::vector<float> priorities;
};

ExtraQueuePlan planExtraQueue(const VkDeviceCreateInfo& app,
                              std::span<const VkQueueFamilyProperties> families);

}  // namespace sdfg
