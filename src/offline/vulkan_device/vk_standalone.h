// A Vulkan instance and device of our own, for the tests, benchmarks and tools that run the GPU
// SDF backend without an OpenXR app (the layer never uses this: it borrows the app's device).
// Links the system Vulkan loader; optionally enables the Khronos validation layer and counts
// every warning and error it reports.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "base/status.h"
#include "vulkan/vk_context.h"

namespace sdfg {

struct StandaloneVulkanOptions {
  bool validation = false;    // enable VK_LAYER_KHRONOS_validation + a debug messenger
  bool printMessages = true;  // echo validation messages to stderr
};

class StandaloneVulkan {
 public:
  // Picks the first physical device with Vulkan 1.1 and a compute queue (set VK_ICD_FILENAMES /
  // VK_DRIVER_FILES to choose a driver, e.g. Mesa's lavapipe). Errors: unsupported when there is
  // no loader, no such device, or validation was asked for and the layer is not installed.
  static Result<std::unique_ptr<StandaloneVulkan>> create(const StandaloneVulkanOptions& options);
  ~StandaloneVulkan();
  StandaloneVulkan(const StandaloneVulkan&) = delete;
  StandaloneVulkan& operator=(const StandaloneVulkan&) = delete;

  // What an app would hand the layer (the queue is family `queueFamilyIndex`, index 0).
  const VulkanDevice& device() const { return device_; }
  const std::string& deviceName() const { return deviceName_; }

  // Validation warnings and errors reported so far, and their text.
  uint32_t messageCount() const { return messageCount_.load(); }
  std::vector<std::string> messages() const;

  // Called by the debug messenger; public only for the C callback.
  void onMessage(const char* text);

 private:
  StandaloneVulkan() = default;
  VulkanDevice device_;
  std::string deviceName_;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  bool printMessages_ = true;
  std::atomic<uint32_t> messageCount_{0};
  mutable std::mutex mutex_;
  std::vector<std::string> messages_;
};

}  // namespace sdfg
