// Test harness of the layer tests: an OpenXR app that goes through the real Khronos loader, the
// layer under test (implicit, from the build tree), the Khronos core validation layer and the
// mock runtime, with the environment each test needs. Every App checks at teardown that core
// validation logged nothing.
#pragma once

#include <time.h>
#include <vulkan/vulkan.h>
#define XR_USE_GRAPHICS_API_VULKAN
#define XR_USE_TIMESPEC
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>

#include <openxr/XR_SDFG_auto_grasp.h>

#include <array>
#include <chrono>
#include <functional>
#include <string>
#include <thread>
#include <vector>

namespace sdfg::test {

struct XrEnv {
  bool layer = true;  // false: the layer's disable_environment variable is set
  // The layer's test build in place of the shipped library: the one with test_layer_fault
  // (layer/test_fault.h), for the cases that make the layer fail on purpose.
  bool testBuild = false;
  std::string handTracking = "1";  // SDFG_MOCK_HAND_TRACKING: "1", "0" or "absent"
  std::string script;              // mock runtime timeline (empty: none)
  // More variables. SDFG_AUTOGRASP_BUILD_TIME_LIMIT_MS is 600000 unless given here (applyEnv()).
  std::vector<std::pair<std::string, std::string>> extra;
};

// Sets the process environment for the next instance; returns the core-validation log path.
std::string applyEnv(const XrEnv& env);
// Text the core validation layer logged so far (empty when it logged nothing).
std::string validationLog();

enum class Graphics {
  headless,  // XR_MND_headless, no graphics binding (the CPU path)
  vulkan,    // XR_KHR_vulkan_enable: the app creates its VkInstance and VkDevice itself
  vulkan2,   // XR_KHR_vulkan_enable2: through xrCreateVulkanInstanceKHR / xrCreateVulkanDeviceKHR
};

struct AppOptions {
  std::vector<std::string> extensions;  // besides the graphics extension, always enabled
  bool appActions = true;               // suggest, attach and sync an app action set
  Graphics graphics = Graphics::headless;
  // Graphics::headless: chained into xrCreateSession as it is (a binding the mock runtime
  // ignores, such as D3D11's with no device: tests/windows/layer_d3d.tests.cpp).
  const void* sessionNext = nullptr;
};

// The app's Vulkan side (Graphics::vulkan*) on lavapipe, with the Khronos validation layer and a
// messenger that records every warning and error.
struct VulkanSide {
  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  VkPhysicalDevice physicalDevice = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  uint32_t family = 0;
  VkQueue queue = VK_NULL_HANDLE;
};

// A host-visible buffer of the app (the test writes meshes into it).
struct HostBuffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  void* mapped = nullptr;
};

// A host-visible, coherent memory type among `typeBits` of the app's device; UINT32_MAX if none.
uint32_t hostCoherentMemoryType(const VulkanSide& vk, uint32_t typeBits);

// Warning and error messages of the Vulkan validation layer so far (all apps of the process).
std::vector<std::string> vulkanMessages();
// Why a Vulkan app cannot run here (no loader, no device, no validation layer); empty if it can.
std::string vulkanUnavailable();

class App {
 public:
  explicit App(const AppOptions& options);
  ~App();
  App(const App&) = delete;
  App& operator=(const App&) = delete;

  bool ok() const { return ok_; }
  XrInstance instance = XR_NULL_HANDLE;
  XrSystemId system = XR_NULL_SYSTEM_ID;
  XrSession session = XR_NULL_HANDLE;
  XrSpace local = XR_NULL_HANDLE;
  XrActionSet appSet = XR_NULL_HANDLE;
  XrAction appSqueeze = XR_NULL_HANDLE;
  std::array<XrPath, 2> hands{};
  XrTime lastTime = 0;
  uint64_t framesEnded = 0;
  XrResult lastSync = XR_SUCCESS;
  std::vector<XrEventDataBuffer> events;  // every event frame() polled, in order
  // The composition layers of the frame being made, for xrEndFrame: `beforeEnd` fills it (a
  // DepthSubmitter does); frame() empties it after xrEndFrame, so no frame submits pointers into
  // an earlier frame's structs. Empty: no layers, as an app that renders nothing.
  std::vector<const XrCompositionLayerBaseHeader*> layers;
  XrResult lastEndFrame = XR_SUCCESS;  // what the last frame's xrEndFrame returned

  template <class F>
  F fn(const char* name) const {
    PFN_xrVoidFunction f = nullptr;
    if (xrGetInstanceProcAddr(instance, name, &f) != XR_SUCCESS) return nullptr;
    return reinterpret_cast<F>(f);
  }

  // One frame: events, wait, begin, sync actions, `beforeEnd` (where an app locates its hands
  // and renders: the poses of this frame), end.
  void frame(const std::function<void()>& beforeEnd = {});
  void frames(int n) {
    for (int i = 0; i < n; ++i) frame();
  }
  // Runs frames until `done()` holds, for at most `limit` of wall time; returns whether it held.
  // Tests wait for an outcome this way, never for a number of frames: how many frames a build
  // takes depends on the machine (a cold shader cache, cores busy with other work). The 1 ms
  // between frames lets lavapipe's and the layer's threads run; the layer never waits itself.
  // `beforeEnd` runs in every frame, as in frame().
  template <class Done>
  bool framesUntil(Done done, std::chrono::milliseconds limit = std::chrono::seconds(120),
                   const std::function<void()>& beforeEnd = {}) {
    const auto end = std::chrono::steady_clock::now() + limit;
    while (!done()) {
      if (std::chrono::steady_clock::now() > end) return false;
      frame(beforeEnd);
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return true;
  }
  // Replaces the mock runtime's input timeline (xrMockRuntimeSetScriptSDFG); its frame numbers
  // are xrEndFrame counts, so `framesEnded + 1` is the next frame.
  XrResult setScript(const std::string& text) const;
  // The app's own squeeze action state for a hand (to check the layer leaves it alone).
  float appSqueezeValue(int hand) const;
  void destroySession();
  // Destroys the instance now (with whatever session is left), before the Vulkan device.
  void destroyInstance();

  VulkanSide vk;  // Graphics::vulkan*: the app's device
  // A buffer on the app's device with STORAGE usage, host-visible and coherent; freed with the
  // app (after the session).
  HostBuffer createBuffer(VkDeviceSize bytes);

 private:
  void pollEvents();
  bool setUpVulkan(Graphics graphics);
  void destroyVulkan();
  std::vector<HostBuffer> buffers_;
  bool ok_ = false;
  bool running_ = false;
};

// XR_EXT_hand_tracking helpers.
struct Joints {
  XrHandJointLocationsEXT locations{XR_TYPE_HAND_JOINT_LOCATIONS_EXT};
  std::array<XrHandJointLocationEXT, XR_HAND_JOINT_COUNT_EXT> joints{};
};
XrResult locateJoints(const App& app, XrHandTrackerEXT tracker, Joints& out,
                      const void* locateNext = nullptr);

// Script lines for a controller: grip pose and squeeze value at a frame.
std::string gripLine(uint64_t frame, const char* hand, const XrPosef& pose);
std::string squeezeLine(uint64_t frame, const char* hand, float value);

}  // namespace sdfg::test
