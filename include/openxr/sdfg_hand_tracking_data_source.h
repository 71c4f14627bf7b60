// XR_EXT_hand_tracking_data_source (OpenXR 1.0.28, extension 429), declared here for the older
// OpenXR headers the layer builds against (Debian 12's 1.0.20 lacks it). Values and layouts are
// the registry's; with headers that have the extension this file declares nothing.
// Include <openxr/openxr.h> first.
#ifndef SDFG_HAND_TRACKING_DATA_SOURCE_H_
#define SDFG_HAND_TRACKING_DATA_SOURCE_H_ 1

#ifndef XR_EXT_hand_tracking_data_source

#ifdef __cplusplus
extern "C" {
#endif

#define XR_EXT_hand_tracking_data_source 1
#define XR_EXT_hand_tracking_data_source_SPEC_VERSION 1
#define XR_EXT_HAND_TRACKING_DATA_SOURCE_EXTENSION_NAME "XR_EXT_hand_tracking_data_source"
#define XR_TYPE_HAND_TRACKING_DATA_SOURCE_INFO_EXT ((XrStructureType)1000428000)
#define XR_TYPE_HAND_TRACKING_DATA_SOURCE_STATE_EXT ((XrStructureType)1000428001)

typedef enum XrHandTrackingDataSourceEXT {
  XR_HAND_TRACKING_DATA_SOURCE_UNOBSTRUCTED_EXT = 1,
  XR_HAND_TRACKING_DATA_SOURCE_CONTROLLER_EXT = 2,
  XR_HAND_TRACKING_DATA_SOURCE_MAX_ENUM_EXT = 0x7FFFFFFF
} XrHandTrackingDataSourceEXT;

// Chained on XrHandTrackerCreateInfoEXT: the sources the app accepts.
typedef struct XrHandTrackingDataSourceInfoEXT {
  XrStructureType type;
  const void* XR_MAY_ALIAS next;
  uint32_t requestedDataSourceCount;
  XrHandTrackingDataSourceEXT* requestedDataSources;
} XrHandTrackingDataSourceInfoEXT;

// Chained on XrHandJointLocationsEXT: where the located joints came from.
typedef struct XrHandTrackingDataSourceStateEXT {
  XrStructureType type;
  void* XR_MAY_ALIAS next;
  XrBool32 isActive;
  XrHandTrackingDataSourceEXT dataSource;
} XrHandTrackingDataSourceStateEXT;

#ifdef __cplusplus
}
#endif

#endif  // XR_EXT_hand_tracking_data_source

#endif  // SDFG_HAND_TRACKING_DATA_SOURCE_H_
