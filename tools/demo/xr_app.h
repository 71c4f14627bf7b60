// The demo's OpenXR side: an app with a Vulkan2 session that enables XR_SDFG_auto_grasp and
// XR_EXT_hand_tracking, registers grasp targets, drives the right controller through the mock
// runtime's timeline, and reads back the joints and the grasp state the layer produces.
//
// Everything goes through the real Khronos loader; the app never calls the layer or the runtime
// directly except for the mock runtime's test-only scripting function (fetched like any
// command), which a real runtime does not have.
#pragma once

#include <vulkan/vulkan.h>
#define XR_USE_GRAPHICS_API_VULKAN
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>

#include <openxr/XR_SDFG_auto_grasp.h>

#include <array>
#include <string>
#include <vector>

namespace sdfg::demo {

// Points the loader at the build tree's mock runtime and the layer's explicit manifest, each only
// when the user has not set the variable (so the demo also runs on another runtime). Sets
// SDFG_MOCK_HAND_TRACKING=absent with the mock, so the layer synthesizes the controller's hand.
// Returns a line saying what was chosen.
std::string prepareEnvironment();

struct HandJoints {
  std::array<XrPosef, XR_HAND_JOINT_COUNT_EXT> poses{};  // LOCAL space
  std::array<float, XR_HAND_JOINT_COUNT_EXT> radii{};
};

// One grasp as the app saw it.
struct GraspReading {
  bool grasped = false;   // the layer reported isGrasping on the target
  HandJoints joints;      // xrLocateHandJointsEXT after the grasp was applied
  HandJoints openJoints;  // the same hand before the squeeze (where the hand was placed)
  XrGraspStateSDFG state{XR_TYPE_GRASP_STATE_SDFG};
  // The hand's offset off the controller pose when `joints` were read (blended in fully): how
  // far the layer moved the open hand out of the object before closing it.
  XrGraspHandOffsetSDFG offset{XR_TYPE_GRASP_HAND_OFFSET_SDFG};
  int frames = 0;  // frames from the squeeze to the reported grasp
  double milliseconds = 0.0;
  std::string error;  // why it failed, when it did
};

class XrApp {
 public:
  XrApp() = default;
  ~XrApp();
  XrApp(const XrApp&) = delete;
  XrApp& operator=(const XrApp&) = delete;

  // Instance, system, Vulkan instance and device through XR_KHR_vulkan_enable2, session, LOCAL
  // space, an app action set, a right hand tracker. False with `error` set on failure.
  bool init(std::string& error);

  // Registers a mesh (metres, target frame) at `pose` in LOCAL. False with `error` on refusal.
  bool createTarget(const std::vector<XrVector3f>& vertices, const std::vector<uint32_t>& indices,
                    const XrPosef& pose, XrGraspTargetSDFG& out, std::string& error);
  void destroyTarget(XrGraspTargetSDFG target);

  // Places the right controller at `grip`, sets the solver, squeezes, runs frames until the layer
  // reports a grasp of `target`, reads joints and state, then releases and waits for the hand to
  // open again.
  GraspReading grasp(XrGraspTargetSDFG target, const XrPosef& grip, XrGraspSolverSDFG solver,
                     uint32_t resolution);

  // The Vulkan objects the session was created with (the renderer draws on the same device).
  VkInstance vkInstance() const { return vkInstance_; }
  VkPhysicalDevice vkPhysicalDevice() const { return vkPhysical_; }
  VkDevice vkDevice() const { return vkDevice_; }
  uint32_t queueFamily() const { return queueFamily_; }
  VkQueue queue() const { return queue_; }
  std::string runtimeName() const { return runtimeName_; }
  std::string deviceName() const { return deviceName_; }

 private:
  template <class F>
  F fn(const char* name) const {
    PFN_xrVoidFunction f = nullptr;
    if (xrGetInstanceProcAddr(instance_, name, &f) != XR_SUCCESS) return nullptr;
    return reinterpret_cast<F>(f);
  }
  bool createVulkan(std::string& error);
  void pollEvents();
  void frame();
  bool locate(HandJoints& out);
  // locate() frame after frame until the hand is active, at most 5 s: as an app hides a hand
  // the layer reports not tracked (the outer hand shows none where a hand that just appeared may
  // be inside a target, until its worker's answer: docs/layer.md, "The outer hand").
  bool locateActive(HandJoints& out);
  // `build`, when given, receives where the SDF was built (chained XrGraspBuildInfoSDFG);
  // `offset` the hand's offset off the controller pose (chained XrGraspHandOffsetSDFG).
  bool graspState(XrGraspStateSDFG& out, XrGraspBuildInfoSDFG* build = nullptr,
                  XrGraspHandOffsetSDFG* offset = nullptr);
  bool script(const std::string& text);

  XrInstance instance_ = XR_NULL_HANDLE;
  XrSystemId system_ = XR_NULL_SYSTEM_ID;
  XrSession session_ = XR_NULL_HANDLE;
  XrSpace local_ = XR_NULL_HANDLE;
  XrActionSet appSet_ = XR_NULL_HANDLE;  // the app's own set: the layer reads input on its sync
  XrAction grab_ = XR_NULL_HANDLE;
  XrHandTrackerEXT tracker_ = XR_NULL_HANDLE;
  bool running_ = false;
  XrTime lastTime_ = 0;
  uint64_t framesEnded_ = 0;
  std::string runtimeName_;
  std::string deviceName_;

  VkInstance vkInstance_ = VK_NULL_HANDLE;
  VkPhysicalDevice vkPhysical_ = VK_NULL_HANDLE;
  VkDevice vkDevice_ = VK_NULL_HANDLE;
  uint32_t queueFamily_ = 0;
  VkQueue queue_ = VK_NULL_HANDLE;

  PFN_xrCreateGraspTargetSDFG createTarget_ = nullptr;
  PFN_xrDestroyGraspTargetSDFG destroyTarget_ = nullptr;
  PFN_xrGetGraspStateSDFG getState_ = nullptr;
  PFN_xrSetGraspOptionsSDFG setOptions_ = nullptr;
  PFN_xrLocateHandJointsEXT locateJoints_ = nullptr;
  PFN_xrDestroyHandTrackerEXT destroyTracker_ = nullptr;
  using SetScript = XrResult(XRAPI_PTR*)(XrInstance, const char*);
  SetScript setScript_ = nullptr;
};

}  // namespace sdfg::demo
