// planExtraQueue: the layer's extra queue on an XR_KHR_vulkan_enable2 app's device, planned from
// the app's VkDeviceCreateInfo and the device's queue families (no device needed; lavapipe's one
// family with one queue is the case where nothing can be planned).
#include <catch2/catch.hpp>

#include "vulkan/vk_extra_queue.h"

namespace {

VkQueueFamilyProperties family(VkQueueFlags flags, uint32_t count) {
  VkQueueFamilyProperties f{};
  f.queueFlags = flags;
  f.queueCount = count;
  return f;
}

}  // namespace

TEST_CASE("planExtraQueue adds one queue to a family the app uses when one is spare",
          "[vulkan][extra-queue]") {
  const float priorities[2] = {1.0f, 0.5f};
  VkDeviceQueueCreateInfo queues[2]{};
  queues[0].sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
  queues[0].queueFamilyIndex = 0;
  queues[0].queueCount = 1;
  queues[0].pQueuePriorities = priorities;
  queues[1] = queues[0];
  queues[1].queueFamilyIndex = 1;
  queues[1].queueCount = 2;
  VkDeviceCreateInfo app{};
  app.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
  app.queueCreateInfoCount = 2;
  app.pQueueCreateInfos = queues;

  SECTION("lavapipe: one family, one queue, taken by the app: nothing planned") {
    app.queueCreateInfoCount = 1;
    const VkQueueFamilyProperties lavapipe[] = {
        family(VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT | VK_QUEUE_TRANSFER_BIT, 1)};
    const sdfg::ExtraQueuePlan plan = sdfg::planExtraQueue(app, lavapipe);
    CHECK_FALSE(plan.planned);
    CHECK(plan.queueInfos.empty());
  }
  SECTION("a spare compute queue in the second family the app uses") {
    const VkQueueFamilyProperties families[] = {
        family(VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT, 1), family(VK_QUEUE_COMPUTE_BIT, 4)};
    const sdfg::ExtraQueuePlan plan = sdfg::planExtraQueue(app, families);
    REQUIRE(plan.planned);
    CHECK(plan.family == 1);
    CHECK(plan.index == 2);  // after the app's two
    REQUIRE(plan.queueInfos.size() == 2);
    CHECK(plan.queueInfos[0].queueCount == 1);  // the other family is untouched
    CHECK(plan.queueInfos[0].pQueuePriorities == priorities);
    CHECK(plan.queueInfos[1].queueCount == 3);
    REQUIRE(plan.queueInfos[1].pQueuePriorities == plan.priorities.data());
    REQUIRE(plan.priorities.size() == 3);
    CHECK(plan.priorities[0] == 1.0f);
    CHECK(plan.priorities[1] == 0.5f);
    CHECK(plan.priorities[2] == 0.5f);  // no higher than the app's lowest
    // The app's own array is not modified.
    CHECK(queues[1].queueCount == 2);
  }
  SECTION("families without compute, protected queues and bad indices are left alone") {
    const VkQueueFamilyProperties noCompute[] = {family(VK_QUEUE_GRAPHICS_BIT, 4),
                                                 family(VK_QUEUE_TRANSFER_BIT, 4)};
    CHECK_FALSE(sdfg::planExtraQueue(app, noCompute).planned);
    const VkQueueFamilyProperties spare[] = {family(VK_QUEUE_COMPUTE_BIT, 4),
                                             family(VK_QUEUE_COMPUTE_BIT, 4)};
    queues[0].flags = VK_DEVICE_QUEUE_CREATE_PROTECTED_BIT;
    const sdfg::ExtraQueuePlan plan = sdfg::planExtraQueue(app, spare);
    REQUIRE(plan.planned);
    CHECK(plan.family == 1);  // the protected entry is skipped
    queues[0].flags = 0;
    queues[0].queueFamilyIndex = 7;
    CHECK_FALSE(sdfg::planExtraQueue(app, spare).planned);
    app.queueCreateInfoCount = 0;
    CHECK_FALSE(sdfg::planExtraQueue(app, spare).planned);
  }
}
