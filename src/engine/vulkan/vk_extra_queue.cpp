#include "vulkan/vk_extra_queue.h"

namespace sdfg {

ExtraQueuePlan planExtraQueue(const VkDeviceCreateInfo& app,
                              std::span<const VkQueueFamilyProperties> families) {
  ExtraQueuePlan plan;
  if (app.queueCreateInfoCount == 0 || app.pQueueCreateInfos == nullptr) return plan;
  const std::span<const VkDeviceQueueCreateInfo> infos(app.pQueueCreateInfos,
                                                       app.queueCreateInfoCount);
  for (size_t i = 0; i < infos.size(); ++i) {
    const VkDeviceQueueCreateInfo& q = infos[i];
    // Protected or otherwise flagged queues, and chained structs (global priority...), are left
    // alone: the layer's queue would inherit properties it did not ask for.
    if (q.flags != 0 || q.pNext != nullptr || q.queueCount == 0 || q.pQueuePriorities == nullptr)
      continue;
    if (q.queueFamilyIndex >= families.size()) return plan;  // malformed: do not touch it
    const VkQueueFamilyProperties& f = families[q.queueFamilyIndex];
    if ((f.queueFlags & VK_QUEUE_COMPUTE_BIT) == 0 || q.queueCount >= f.queueCount) continue;
    plan.planned = true;
    plan.family = q.queueFamilyIndex;
    plan.index = q.queueCount;
    plan.priorities.assign(q.pQueuePriorities, q.pQueuePriorities + q.queueCount);
    // Below the app's lowest priority: its rendering goes first.
    float lowest = 1.0f;
    for (float p : plan.priorities) lowest = p < lowest ? p : lowest;
    plan.priorities.push_back(lowest);
    plan.queueInfos.assign(infos.begin(), infos.end());
    plan.queueInfos[i].queueCount = q.queueCount + 1;
    plan.queueInfos[i].pQueuePriorities = plan.priorities.data();
    return plan;
  }
  return plan;
}

}  // namespace sdfg
