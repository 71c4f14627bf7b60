// System: one head-mounted display, stereo, opaque blend, small views (lavapipe renders on the
// CPU), and the hand-tracking capability the environment chose.
#include <cstdio>

#include "entry_points.h"
#include "system_constants.h"

namespace sdfg::mock {
namespace {

// Common checks of every system query: a live instance and the system id xrGetSystem gave.
XrResult verifySystem(const char* cmd, XrInstance handle, XrSystemId systemId, Instance** out) {
  Instance* instance = lookup<Instance>(handle);
  if (instance == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "instance is not valid");
  if (systemId != kSystemId || !instance->systemFetched)
    return fail(cmd, XR_ERROR_SYSTEM_INVALID, "systemId %llu", (unsigned long long)systemId);
  if (out != nullptr) *out = instance;
  return XR_SUCCESS;
}

XrResult verifyViewConfiguration(const char* cmd, XrViewConfigurationType type) {
  if (type == XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO) return XR_SUCCESS;
  if (type == XR_VIEW_CONFIGURATION_TYPE_PRIMARY_MONO ||
      type == XR_VIEW_CONFIGURATION_TYPE_PRIMARY_QUAD_VARJO ||
      type == XR_VIEW_CONFIGURATION_TYPE_SECONDARY_MONO_FIRST_PERSON_OBSERVER_MSFT)
    return fail(cmd, XR_ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED, "only PRIMARY_STEREO");
  return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "viewConfigurationType %d", int(type));
}

}  // namespace

XrResult getSystem(XrInstance handle, const XrSystemGetInfo* info, XrSystemId* systemId) {
  constexpr const char* cmd = "xrGetSystem";
  Instance* instance = lookup<Instance>(handle);
  if (instance == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "instance is not valid");
  MOCK_VERIFY_TYPE(cmd, info, XR_TYPE_SYSTEM_GET_INFO);
  MOCK_VERIFY_NOT_NULL(cmd, systemId);
  // Every other value, known or not, is a form factor this runtime lacks (the CTS passes
  // XR_FORM_FACTOR_MAX_ENUM and expects XR_ERROR_FORM_FACTOR_UNSUPPORTED).
  if (info->formFactor != XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY)
    return fail(cmd, XR_ERROR_FORM_FACTOR_UNSUPPORTED, "formFactor %d; only HEAD_MOUNTED_DISPLAY",
                int(info->formFactor));
  instance->systemFetched = true;
  *systemId = kSystemId;
  return XR_SUCCESS;
}

XrResult getSystemProperties(XrInstance handle, XrSystemId systemId, XrSystemProperties* props) {
  constexpr const char* cmd = "xrGetSystemProperties";
  Instance* instance = nullptr;
  if (XrResult r = verifySystem(cmd, handle, systemId, &instance); r != XR_SUCCESS) return r;
  MOCK_VERIFY_TYPE(cmd, props, XR_TYPE_SYSTEM_PROPERTIES);
  props->systemId = kSystemId;
  props->vendorId = 0x5DF6;
  std::snprintf(props->systemName, sizeof props->systemName, "SDFG mock HMD");
  props->graphicsProperties.maxSwapchainImageWidth = kMaxImageSize;
  props->graphicsProperties.maxSwapchainImageHeight = kMaxImageSize;
  props->graphicsProperties.maxLayerCount = kMaxLayerCount;
  props->trackingProperties.orientationTracking = XR_TRUE;
  props->trackingProperties.positionTracking = XR_TRUE;
  for (auto* p = static_cast<XrBaseOutStructure*>(props->next); p != nullptr; p = p->next) {
    if (p->type == XR_TYPE_SYSTEM_HAND_TRACKING_PROPERTIES_EXT && instance->extHandTracking) {
      reinterpret_cast<XrSystemHandTrackingPropertiesEXT*>(p)->supportsHandTracking =
          instance->handTracking == HandTrackingMode::supported ? XR_TRUE : XR_FALSE;
    }
  }
  return XR_SUCCESS;
}

XrResult enumerateViewConfigurations(XrInstance handle, XrSystemId systemId, uint32_t capacity,
                                     uint32_t* countOutput, XrViewConfigurationType* types) {
  constexpr const char* cmd = "xrEnumerateViewConfigurations";
  if (XrResult r = verifySystem(cmd, handle, systemId, nullptr); r != XR_SUCCESS) return r;
  const XrViewConfigurationType stereo = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
  return twoCall(cmd, capacity, countOutput, types, &stereo, 1);
}

XrResult getViewConfigurationProperties(XrInstance handle, XrSystemId systemId,
                                        XrViewConfigurationType type,
                                        XrViewConfigurationProperties* props) {
  constexpr const char* cmd = "xrGetViewConfigurationProperties";
  if (XrResult r = verifySystem(cmd, handle, systemId, nullptr); r != XR_SUCCESS) return r;
  if (XrResult r = verifyViewConfiguration(cmd, type); r != XR_SUCCESS) return r;
  MOCK_VERIFY_TYPE(cmd, props, XR_TYPE_VIEW_CONFIGURATION_PROPERTIES);
  props->viewConfigurationType = type;
  props->fovMutable = XR_FALSE;
  return XR_SUCCESS;
}

XrResult enumerateViewConfigurationViews(XrInstance handle, XrSystemId systemId,
                                         XrViewConfigurationType type, uint32_t capacity,
                                         uint32_t* countOutput, XrViewConfigurationView* views) {
  constexpr const char* cmd = "xrEnumerateViewConfigurationViews";
  if (XrResult r = verifySystem(cmd, handle, systemId, nullptr); r != XR_SUCCESS) return r;
  if (XrResult r = verifyViewConfiguration(cmd, type); r != XR_SUCCESS) return r;
  MOCK_VERIFY_NOT_NULL(cmd, countOutput);
  *countOutput = kViewCount;
  if (capacity == 0) return XR_SUCCESS;
  if (capacity < kViewCount) return fail(cmd, XR_ERROR_SIZE_INSUFFICIENT, "capacity %u", capacity);
  MOCK_VERIFY_NOT_NULL(cmd, views);
  for (uint32_t i = 0; i < kViewCount; ++i) {
    if (views[i].type != XR_TYPE_VIEW_CONFIGURATION_VIEW)
      return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "(views[%u].type) is wrong", i);
    views[i].recommendedImageRectWidth = kViewSize;
    views[i].maxImageRectWidth = kMaxImageSize;
    views[i].recommendedImageRectHeight = kViewSize;
    views[i].maxImageRectHeight = kMaxImageSize;
    views[i].recommendedSwapchainSampleCount = 1;
    views[i].maxSwapchainSampleCount = 1;
  }
  return XR_SUCCESS;
}

XrResult enumerateEnvironmentBlendModes(XrInstance handle, XrSystemId systemId,
                                        XrViewConfigurationType type, uint32_t capacity,
                                        uint32_t* countOutput, XrEnvironmentBlendMode* modes) {
  constexpr const char* cmd = "xrEnumerateEnvironmentBlendModes";
  if (XrResult r = verifySystem(cmd, handle, systemId, nullptr); r != XR_SUCCESS) return r;
  if (XrResult r = verifyViewConfiguration(cmd, type); r != XR_SUCCESS) return r;
  const XrEnvironmentBlendMode opaque = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
  return twoCall(cmd, capacity, countOutput, modes, &opaque, 1);
}

}  // namespace sdfg::mock
