// Every command the layer intercepts, named SdfgXr<Command> (never xr<Command>: a layer that
// defines the loader's names can bind to the loader's copies through ELF interposition).
#pragma once

#include "state.h"
#include "xr_includes.h"

namespace sdfg::layer {

// session.cpp
XrResult XRAPI_CALL SdfgXrGetSystemProperties(XrInstance, XrSystemId, XrSystemProperties*);
XrResult XRAPI_CALL SdfgXrCreateSession(XrInstance, const XrSessionCreateInfo*, XrSession*);
XrResult XRAPI_CALL SdfgXrDestroySession(XrSession);
XrResult XRAPI_CALL SdfgXrWaitFrame(XrSession, const XrFrameWaitInfo*, XrFrameState*);
XrResult XRAPI_CALL SdfgXrCreateReferenceSpace(XrSession, const XrReferenceSpaceCreateInfo*,
                                               XrSpace*);
XrResult XRAPI_CALL SdfgXrCreateActionSpace(XrSession, const XrActionSpaceCreateInfo*, XrSpace*);
XrResult XRAPI_CALL SdfgXrDestroySpace(XrSpace);

// vulkan.cpp
XrResult XRAPI_CALL SdfgXrBeginFrame(XrSession, const XrFrameBeginInfo*);
XrResult XRAPI_CALL SdfgXrEndFrame(XrSession, const XrFrameEndInfo*);
XrResult XRAPI_CALL SdfgXrCreateSwapchain(XrSession, const XrSwapchainCreateInfo*, XrSwapchain*);
XrResult XRAPI_CALL SdfgXrDestroySwapchain(XrSwapchain);
XrResult XRAPI_CALL SdfgXrEnumerateSwapchainImages(XrSwapchain, uint32_t, uint32_t*,
                                                   XrSwapchainImageBaseHeader*);
XrResult XRAPI_CALL SdfgXrAcquireSwapchainImage(XrSwapchain, const XrSwapchainImageAcquireInfo*,
                                                uint32_t*);
XrResult XRAPI_CALL SdfgXrReleaseSwapchainImage(XrSwapchain, const XrSwapchainImageReleaseInfo*);
XrResult XRAPI_CALL SdfgXrCreateVulkanInstanceKHR(XrInstance, const XrVulkanInstanceCreateInfoKHR*,
                                                  VkInstance*, VkResult*);
XrResult XRAPI_CALL SdfgXrCreateVulkanDeviceKHR(XrInstance, const XrVulkanDeviceCreateInfoKHR*,
                                                VkDevice*, VkResult*);

// input.cpp
XrResult XRAPI_CALL
SdfgXrSuggestInteractionProfileBindings(XrInstance, const XrInteractionProfileSuggestedBinding*);
XrResult XRAPI_CALL SdfgXrAttachSessionActionSets(XrSession, const XrSessionActionSetsAttachInfo*);
XrResult XRAPI_CALL SdfgXrSyncActions(XrSession, const XrActionsSyncInfo*);

// hands.cpp
XrResult XRAPI_CALL SdfgXrCreateHandTrackerEXT(XrSession, const XrHandTrackerCreateInfoEXT*,
                                               XrHandTrackerEXT*);
XrResult XRAPI_CALL SdfgXrDestroyHandTrackerEXT(XrHandTrackerEXT);
XrResult XRAPI_CALL SdfgXrLocateHandJointsEXT(XrHandTrackerEXT, const XrHandJointsLocateInfoEXT*,
                                              XrHandJointLocationsEXT*);

// extension.cpp (XR_SDFG_auto_grasp)
XrResult XRAPI_CALL SdfgXrCreateGraspTargetSDFG(XrSession, const XrGraspTargetCreateInfoSDFG*,
                                                XrGraspTargetSDFG*);
XrResult XRAPI_CALL SdfgXrDestroyGraspTargetSDFG(XrGraspTargetSDFG);
XrResult XRAPI_CALL SdfgXrUpdateGraspTargetVerticesSDFG(XrGraspTargetSDFG, const void*);
XrResult XRAPI_CALL SdfgXrSetGraspTargetPlacementSDFG(XrGraspTargetSDFG,
                                                      const XrGraspTargetPlacementSDFG*);
XrResult XRAPI_CALL SdfgXrGetGraspStateSDFG(XrSession, const XrGraspStateGetInfoSDFG*,
                                            XrGraspStateSDFG*);
XrResult XRAPI_CALL SdfgXrSetGraspOptionsSDFG(XrSession, const XrGraspOptionsSDFG*);

// grasp_output.cpp: fills the version 2 structs chained on an XrGraspStateSDFG (contacts, held
// pose) for a hand; `held` as isGrasping. The caller holds session.mutex.
void writeGraspStateV2(const SessionState& session, Hand hand, bool held, XrGraspStateSDFG* state);

// events.cpp: xrPollEvent with the layer's grasp events, and the event of a hand whose grasp
// changed since it was `wasGrasping` `wasTarget` (`destroyed`: its target is being destroyed).
// The caller holds session.mutex.
XrResult XRAPI_CALL SdfgXrPollEvent(XrInstance, XrEventDataBuffer*);
void noteGraspChange(SessionState& session, Hand hand, bool wasGrasping, uint64_t wasTarget,
                     bool destroyed = false);

// target_settings.cpp: xrSetGraspTargetSettingsSDFG; the check of a settings struct (null: none
// given, fine) and its application to a new target (the caller holds session.mutex).
XrResult XRAPI_CALL SdfgXrSetGraspTargetSettingsSDFG(XrGraspTargetSDFG,
                                                     const XrGraspTargetSettingsSDFG*);
XrResult verifyTargetSettings(const char* cmd, const XrGraspTargetSettingsSDFG* settings);
void applyTargetSettings(SessionState& session, uint64_t target,
                         const XrGraspTargetSettingsSDFG* settings);

// target_scene.cpp (version 3, scenes). The caller holds session.mutex for the ones that take a
// SessionState: a target's placement in a space (the engine's, and the space's count of targets,
// which the per-frame gather locates), its role, an analytic shape's check, the touches output.
void placeTarget(SessionState& session, TargetState& target, XrSpace space, const XrPosef& pose);
void unplaceTarget(SessionState& session, TargetState& target);
XrResult verifyTargetRole(const char* cmd, const XrGraspTargetRoleInfoSDFG* role);
void applyTargetRole(SessionState& session, uint64_t target, const XrGraspTargetRoleInfoSDFG* role);
XrResult readShape(const char* cmd, const XrGraspTargetShapeSDFG* shape, AnalyticShape& out);
void writeTouches(const HandGrasp& grasp, XrGraspTouchesSDFG& out);

// target_state.cpp (version 3): xrGetGraspTargetStateSDFG.
XrResult XRAPI_CALL SdfgXrGetGraspTargetStateSDFG(XrGraspTargetSDFG, XrGraspTargetStateSDFG*);

// input.cpp: creates the layer's action set and actions on a new instance.
void createLayerActions(InstanceState& instance);

}  // namespace sdfg::layer
