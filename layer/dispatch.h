// The next layer's functions that this layer calls, fetched once per instance through the next
// xrGetInstanceProcAddr. A null entry means the chain below does not offer that command (for
// instance hand tracking on a runtime without it).
#pragma once

#include "xr_includes.h"

namespace sdfg::layer {

#define SDFG_NEXT_COMMANDS(X)            \
  X(xrDestroyInstance)                   \
  X(xrGetSystem)                         \
  X(xrPollEvent)                         \
  X(xrGetSystemProperties)               \
  X(xrCreateSession)                     \
  X(xrDestroySession)                    \
  X(xrWaitFrame)                         \
  X(xrBeginFrame)                        \
  X(xrEndFrame)                          \
  X(xrCreateSwapchain)                   \
  X(xrDestroySwapchain)                  \
  X(xrEnumerateSwapchainImages)          \
  X(xrAcquireSwapchainImage)             \
  X(xrReleaseSwapchainImage)             \
  X(xrCreateVulkanInstanceKHR)           \
  X(xrCreateVulkanDeviceKHR)             \
  X(xrCreateReferenceSpace)              \
  X(xrCreateActionSpace)                 \
  X(xrLocateSpace)                       \
  X(xrDestroySpace)                      \
  X(xrStringToPath)                      \
  X(xrCreateActionSet)                   \
  X(xrDestroyActionSet)                  \
  X(xrCreateAction)                      \
  X(xrSuggestInteractionProfileBindings) \
  X(xrAttachSessionActionSets)           \
  X(xrSyncActions)                       \
  X(xrGetActionStateFloat)               \
  X(xrCreateHandTrackerEXT)              \
  X(xrDestroyHandTrackerEXT)             \
  X(xrLocateHandJointsEXT)               \
  X(xrConvertTimespecTimeToTimeKHR)      \
  X(xrSubmitDebugUtilsMessageEXT)

struct NextDispatch {
#define SDFG_MEMBER(name) PFN_##name name = nullptr;
  SDFG_NEXT_COMMANDS(SDFG_MEMBER)
#undef SDFG_MEMBER

  // Fills every entry from `gipa`; commands the chain does not offer stay null.
  void load(PFN_xrGetInstanceProcAddr gipa, XrInstance instance) {
#define SDFG_LOAD(name)                                                                  \
  if (gipa(instance, #name, reinterpret_cast<PFN_xrVoidFunction*>(&name)) != XR_SUCCESS) \
    name = nullptr;
    SDFG_NEXT_COMMANDS(SDFG_LOAD)
#undef SDFG_LOAD
  }
};

}  // namespace sdfg::layer
