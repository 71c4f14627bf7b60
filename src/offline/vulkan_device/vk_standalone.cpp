#include "vulkan_device/vk_standalone.h"

#include <cstring>
#include <iostream>

#include <vulkan/vulkan.h>

namespace sdfg {

namespace {

VKAPI_ATTR VkBool32 VKAPI_CALL debugCallback(VkDebugUtilsMessageSeverityFlagBitsEXT,
                                             VkDebugUtilsMessageTypeFlagsEXT,
                                             const VkDebugUtilsMessengerCallbackDataEXT* data,
                                             void* user) {
  static_cast<StandaloneVulkan*>(user)->onMessage(data && data->pMessage ? data->pMessage : "?");
  return VK_FALSE;
}

bool hasLayer(const char* name) {
  uint32_t count = 0;
  if (vkEnumerateInstanceLayerProperties(&count, nullptr) != VK_SUCCESS) return false;
  std::vector<VkLayerProperties> layers(count);
  if (vkEnumerateInstanceLayerProperties(&count, layers.data()) != VK_SUCCESS) return false;
  for (const VkLayerProperties& l : layers) {
    if (std::strcmp(l.layerName, name) == 0) return true;
  }
  return false;
}

}  // namespace

void StandaloneVulkan::onMessage(const char* text) {
  messageCount_.fetch_add(1);
  if (printMessages_) std::cerr << "vulkan validation: " << text << std::endl;
  std::lock_guard<std::mutex> lock(mutex_);
  messages_.emplace_back(text);
}

std::vector<std::string> StandaloneVulkan::messages() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return messages_;
}

Result<std::unique_ptr<StandaloneVulkan>> StandaloneVulkan::create(
    const StandaloneVulkanOptions& options) {
  std::unique_ptr<StandaloneVulkan> v(new StandaloneVulkan());
  v->printMessages_ = options.printMessages;
  const char* kValidation = "VK_LAYER_KHRONOS_validation";
  if (options.validation && !hasLayer(kValidation)) {
    return makeError(Status::unsupported, "vulkan: VK_LAYER_KHRONOS_validation is not installed");
  }
  auto appInfo = vkStruct<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
  appInfo.pApplicationName = "sdfg";
  appInfo.apiVersion = VK_API_VERSION_1_1;
  auto messengerInfo = vkStruct<VkDebugUtilsMessengerCreateInfoEXT>(
      VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT);
  messengerInfo.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                                  VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  messengerInfo.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                              VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                              VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  messengerInfo.pfnUserCallback = debugCallback;
  messengerInfo.pUserData = v.get();
  const char* extension = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
  auto instInfo = vkStruct<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
  instInfo.pApplicationInfo = &appInfo;
  if (options.validation) {
    instInfo.enabledLayerCount = 1;
    instInfo.ppEnabledLayerNames = &kValidation;
    instInfo.enabledExtensionCount = 1;
    instInfo.ppEnabledExtensionNames = &extension;
    instInfo.pNext = &messengerInfo;  // also reports problems in vkCreate/DestroyInstance
  }
  VkInstance instance = VK_NULL_HANDLE;
  if (VkResult r = vkCreateInstance(&instInfo, nullptr, &instance); r != VK_SUCCESS) {
    return makeError(Status::unsupported,
                     std::string("vulkan: vkCreateInstance failed: ") + vkResultName(r));
  }
  v->device_.instance = instance;
  v->device_.getInstanceProcAddr = vkGetInstanceProcAddr;
  if (options.validation) {
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
    if (create == nullptr ||
        create(instance, &messengerInfo, nullptr, &v->messenger_) != VK_SUCCESS) {
      return makeError(Status::unsupported, "vulkan: cannot create a debug messenger");
    }
  }

  uint32_t count = 0;
  vkEnumeratePhysicalDevices(instance, &count, nullptr);
  std::vector<VkPhysicalDevice> devices(count);
  vkEnumeratePhysicalDevices(instance, &count, devices.data());
  for (VkPhysicalDevice pd : devices) {
    VkPhysicalDeviceProperties props{};
    vkGetPhysicalDeviceProperties(pd, &props);
    if (props.apiVersion < VK_API_VERSION_1_1) continue;
    uint32_t familyCount = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(pd, &familyCount, nullptr);
    std::vector<VkQueueFamilyProperties> families(familyCount);
    vkGetPhysicalDeviceQueueFamilyProperties(pd, &familyCount, families.data());
    for (uint32_t f = 0; f < familyCount; ++f) {
      if ((families[f].queueFlags & VK_QUEUE_COMPUTE_BIT) == 0) continue;
      const float priority = 1.0f;
      auto queueInfo =
          vkStruct<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
      queueInfo.queueFamilyIndex = f;
      queueInfo.queueCount = 1;
      queueInfo.pQueuePriorities = &priority;
      auto devInfo = vkStruct<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO);
      devInfo.queueCreateInfoCount = 1;
      devInfo.pQueueCreateInfos = &queueInfo;
      VkDevice device = VK_NULL_HANDLE;
      if (vkCreateDevice(pd, &devInfo, nullptr, &device) != VK_SUCCESS) break;
      v->device_.physicalDevice = pd;
      v->device_.device = device;
      v->device_.queueFamilyIndex = f;
      v->device_.queueIndex = 0;
      v->deviceName_ = props.deviceName;
      return v;
    }
  }
  return makeError(Status::unsupported, "vulkan: no device with Vulkan 1.1 and a compute queue");
}

StandaloneVulkan::~StandaloneVulkan() {
  if (device_.device != VK_NULL_HANDLE) {
    vkDeviceWaitIdle(device_.device);
    vkDestroyDevice(device_.device, nullptr);
  }
  if (messenger_ != VK_NULL_HANDLE) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(device_.instance, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(device_.instance, messenger_, nullptr);
  }
  if (device_.instance != VK_NULL_HANDLE) vkDestroyInstance(device_.instance, nullptr);
}

}  // namespace sdfg
