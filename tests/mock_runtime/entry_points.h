// Every OpenXR command the mock runtime implements, by the file that implements it. The names
// carry no "xr" prefix on purpose: a runtime defining symbols called xrCreateSession could bind
// to the loader's exported copies (ELF interposition). dispatch.cpp maps the OpenXR names to
// these through xrGetInstanceProcAddr, behind one lock and one exception guard.
#pragma once

#include "runtime.h"

namespace sdfg::mock {

// instance.cpp
XrResult enumerateInstanceExtensionProperties(const char* layerName, uint32_t capacity,
                                              uint32_t* countOutput, XrExtensionProperties* props);
XrResult enumerateApiLayerProperties(uint32_t capacity, uint32_t* countOutput,
                                     XrApiLayerProperties* props);
XrResult createInstance(const XrInstanceCreateInfo* info, XrInstance* instance);
XrResult destroyInstance(XrInstance instance);
XrResult getInstanceProperties(XrInstance instance, XrInstanceProperties* props);
XrResult pollEvent(XrInstance instance, XrEventDataBuffer* event);
XrResult resultToString(XrInstance instance, XrResult value,
                        char buffer[XR_MAX_RESULT_STRING_SIZE]);
XrResult structureTypeToString(XrInstance instance, XrStructureType value,
                               char buffer[XR_MAX_STRUCTURE_NAME_SIZE]);
XrResult stringToPath(XrInstance instance, const char* pathString, XrPath* path);
XrResult pathToString(XrInstance instance, XrPath path, uint32_t capacity, uint32_t* countOutput,
                      char* buffer);
XrResult convertTimespecTimeToTime(XrInstance instance, const struct timespec* timespecTime,
                                   XrTime* time);
XrResult convertTimeToTimespecTime(XrInstance instance, XrTime time, struct timespec* timespecTime);

// system.cpp
XrResult getSystem(XrInstance instance, const XrSystemGetInfo* info, XrSystemId* systemId);
XrResult getSystemProperties(XrInstance instance, XrSystemId systemId, XrSystemProperties* props);
XrResult enumerateViewConfigurations(XrInstance instance, XrSystemId systemId, uint32_t capacity,
                                     uint32_t* countOutput, XrViewConfigurationType* types);
XrResult getViewConfigurationProperties(XrInstance instance, XrSystemId systemId,
                                        XrViewConfigurationType type,
                                        XrViewConfigurationProperties* props);
XrResult enumerateViewConfigurationViews(XrInstance instance, XrSystemId systemId,
                                         XrViewConfigurationType type, uint32_t capacity,
                                         uint32_t* countOutput, XrViewConfigurationView* views);
XrResult enumerateEnvironmentBlendModes(XrInstance instance, XrSystemId systemId,
                                        XrViewConfigurationType type, uint32_t capacity,
                                        uint32_t* countOutput, XrEnvironmentBlendMode* modes);

// session.cpp
XrResult createSession(XrInstance instance, const XrSessionCreateInfo* info, XrSession* session);
XrResult destroySessionEntry(XrSession session);
XrResult beginSession(XrSession session, const XrSessionBeginInfo* info);
XrResult endSession(XrSession session);
XrResult requestExitSession(XrSession session);

// frame.cpp
XrResult waitFrame(XrSession session, const XrFrameWaitInfo* info, XrFrameState* state);
XrResult beginFrame(XrSession session, const XrFrameBeginInfo* info);
XrResult endFrame(XrSession session, const XrFrameEndInfo* info);

// spaces.cpp
XrResult enumerateReferenceSpaces(XrSession session, uint32_t capacity, uint32_t* countOutput,
                                  XrReferenceSpaceType* spaces);
XrResult createReferenceSpace(XrSession session, const XrReferenceSpaceCreateInfo* info,
                              XrSpace* space);
XrResult getReferenceSpaceBoundsRect(XrSession session, XrReferenceSpaceType type,
                                     XrExtent2Df* bounds);
XrResult createActionSpace(XrSession session, const XrActionSpaceCreateInfo* info, XrSpace* space);
XrResult locateSpace(XrSpace space, XrSpace baseSpace, XrTime time, XrSpaceLocation* location);
XrResult destroySpace(XrSpace space);
XrResult locateViews(XrSession session, const XrViewLocateInfo* info, XrViewState* viewState,
                     uint32_t capacity, uint32_t* countOutput, XrView* views);

// actions.cpp
XrResult createActionSet(XrInstance instance, const XrActionSetCreateInfo* info,
                         XrActionSet* actionSet);
XrResult destroyActionSet(XrActionSet actionSet);
XrResult createAction(XrActionSet actionSet, const XrActionCreateInfo* info, XrAction* action);
XrResult destroyAction(XrAction action);
XrResult suggestInteractionProfileBindings(XrInstance instance,
                                           const XrInteractionProfileSuggestedBinding* suggested);
XrResult attachSessionActionSets(XrSession session, const XrSessionActionSetsAttachInfo* info);
XrResult getCurrentInteractionProfile(XrSession session, XrPath topLevelUserPath,
                                      XrInteractionProfileState* profile);
XrResult syncActions(XrSession session, const XrActionsSyncInfo* info);
XrResult getActionStateBoolean(XrSession session, const XrActionStateGetInfo* info,
                               XrActionStateBoolean* state);
XrResult getActionStateFloat(XrSession session, const XrActionStateGetInfo* info,
                             XrActionStateFloat* state);
XrResult getActionStateVector2f(XrSession session, const XrActionStateGetInfo* info,
                                XrActionStateVector2f* state);
XrResult getActionStatePose(XrSession session, const XrActionStateGetInfo* info,
                            XrActionStatePose* state);
XrResult enumerateBoundSourcesForAction(XrSession session,
                                        const XrBoundSourcesForActionEnumerateInfo* info,
                                        uint32_t capacity, uint32_t* countOutput, XrPath* sources);
XrResult getInputSourceLocalizedName(XrSession session,
                                     const XrInputSourceLocalizedNameGetInfo* info,
                                     uint32_t capacity, uint32_t* countOutput, char* buffer);
XrResult applyHapticFeedback(XrSession session, const XrHapticActionInfo* info,
                             const XrHapticBaseHeader* feedback);
XrResult stopHapticFeedback(XrSession session, const XrHapticActionInfo* info);

// swapchain.cpp
XrResult enumerateSwapchainFormats(XrSession session, uint32_t capacity, uint32_t* countOutput,
                                   int64_t* formats);
XrResult createSwapchain(XrSession session, const XrSwapchainCreateInfo* info,
                         XrSwapchain* swapchain);
XrResult destroySwapchainEntry(XrSwapchain swapchain);
XrResult enumerateSwapchainImages(XrSwapchain swapchain, uint32_t capacity, uint32_t* countOutput,
                                  XrSwapchainImageBaseHeader* images);
XrResult acquireSwapchainImage(XrSwapchain swapchain, const XrSwapchainImageAcquireInfo* info,
                               uint32_t* index);
XrResult waitSwapchainImage(XrSwapchain swapchain, const XrSwapchainImageWaitInfo* info);
XrResult releaseSwapchainImage(XrSwapchain swapchain, const XrSwapchainImageReleaseInfo* info);

// vulkan.cpp (XR_KHR_vulkan_enable, XR_KHR_vulkan_enable2)
XrResult getVulkanGraphicsRequirements(XrInstance instance, XrSystemId systemId,
                                       XrGraphicsRequirementsVulkanKHR* requirements);
XrResult getVulkanInstanceExtensions(XrInstance instance, XrSystemId systemId, uint32_t capacity,
                                     uint32_t* countOutput, char* buffer);
XrResult getVulkanDeviceExtensions(XrInstance instance, XrSystemId systemId, uint32_t capacity,
                                   uint32_t* countOutput, char* buffer);
XrResult getVulkanGraphicsDevice(XrInstance instance, XrSystemId systemId, VkInstance vkInstance,
                                 VkPhysicalDevice* physicalDevice);
XrResult createVulkanInstance(XrInstance instance, const XrVulkanInstanceCreateInfoKHR* info,
                              VkInstance* vkInstance, VkResult* vkResult);
XrResult createVulkanDevice(XrInstance instance, const XrVulkanDeviceCreateInfoKHR* info,
                            VkDevice* vkDevice, VkResult* vkResult);
XrResult getVulkanGraphicsDevice2(XrInstance instance, const XrVulkanGraphicsDeviceGetInfoKHR* info,
                                  VkPhysicalDevice* physicalDevice);

// hand_tracking.cpp (XR_EXT_hand_tracking)
XrResult createHandTracker(XrSession session, const XrHandTrackerCreateInfoEXT* info,
                           XrHandTrackerEXT* tracker);
XrResult destroyHandTracker(XrHandTrackerEXT tracker);
XrResult locateHandJoints(XrHandTrackerEXT tracker, const XrHandJointsLocateInfoEXT* info,
                          XrHandJointLocationsEXT* locations);

// test_functions.cpp and instance.cpp (mock_runtime_test.h)
XrResult mockSetScript(XrInstance instance, const char* scriptText);
XrResult mockGetStats(XrSession session, XrMockRuntimeStatsSDFG* stats);
XrResult mockGetDepthStats(XrSession session, uint32_t* framesWithDepth, uint32_t* depthInfos);
XrResult mockGateCalls(XrInstance instance, const char* command, XrBool32 hold,
                       uint32_t delayMicroseconds);
XrResult mockGateStats(XrInstance instance, const char* command, uint32_t* waiting,
                       uint64_t* passed);
XrResult mockGetCapture(XrSession session, uint32_t viewIndex, uint32_t capacityBytes,
                        uint32_t* width, uint32_t* height, uint8_t* rgba);

}  // namespace sdfg::mock
