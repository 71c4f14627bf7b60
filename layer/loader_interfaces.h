// The loader-layer ABI (interface version 1), declared here because Debian's OpenXR 1.0.20
// headers do not ship it (loader_interfaces.h is not installed; openxr_loader_negotiation.h came
// with SDK 1.0.33). Layouts follow KhronosGroup/OpenXR-SDK-Source src/common/loader_interfaces.h
// @ release-1.0.20; the static_asserts pin the x86_64 sizes and offsets.
#pragma once

#include <openxr/openxr.h>

#include <cstddef>

namespace sdfg::layer {

enum XrLoaderInterfaceStructs : int32_t {
  XR_LOADER_INTERFACE_STRUCT_UNINTIALIZED = 0,
  XR_LOADER_INTERFACE_STRUCT_LOADER_INFO = 1,
  XR_LOADER_INTERFACE_STRUCT_API_LAYER_REQUEST = 2,
  XR_LOADER_INTERFACE_STRUCT_RUNTIME_REQUEST = 3,
  XR_LOADER_INTERFACE_STRUCT_API_LAYER_CREATE_INFO = 4,
  XR_LOADER_INTERFACE_STRUCT_API_LAYER_NEXT_INFO = 5,
};

inline constexpr uint32_t kLoaderInfoStructVersion = 1;
inline constexpr uint32_t kApiLayerInfoStructVersion = 1;
inline constexpr uint32_t kApiLayerNextInfoStructVersion = 1;
inline constexpr uint32_t kApiLayerCreateInfoStructVersion = 1;
inline constexpr uint32_t kCurrentLoaderApiLayerVersion = 1;
inline constexpr size_t kMaxApiLayerNameSize = 256;
inline constexpr size_t kApiLayerMaxSettingsPathSize = 512;

struct XrApiLayerCreateInfo;
using PFN_xrCreateApiLayerInstance = XrResult(XRAPI_PTR*)(const XrInstanceCreateInfo* info,
                                                          const XrApiLayerCreateInfo* apiLayerInfo,
                                                          XrInstance* instance);

struct XrNegotiateLoaderInfo {
  XrLoaderInterfaceStructs structType;  // LOADER_INFO
  uint32_t structVersion;
  size_t structSize;
  uint32_t minInterfaceVersion;
  uint32_t maxInterfaceVersion;
  XrVersion minApiVersion;
  XrVersion maxApiVersion;
};

struct XrNegotiateApiLayerRequest {
  XrLoaderInterfaceStructs structType;  // API_LAYER_REQUEST
  uint32_t structVersion;
  size_t structSize;
  uint32_t layerInterfaceVersion;                       // out
  XrVersion layerApiVersion;                            // out
  PFN_xrGetInstanceProcAddr getInstanceProcAddr;        // out
  PFN_xrCreateApiLayerInstance createApiLayerInstance;  // out
};

struct XrApiLayerNextInfo {
  XrLoaderInterfaceStructs structType;  // API_LAYER_NEXT_INFO
  uint32_t structVersion;
  size_t structSize;
  char layerName[kMaxApiLayerNameSize];
  PFN_xrGetInstanceProcAddr nextGetInstanceProcAddr;
  PFN_xrCreateApiLayerInstance nextCreateApiLayerInstance;
  XrApiLayerNextInfo* next;
};

struct XrApiLayerCreateInfo {
  XrLoaderInterfaceStructs structType;  // API_LAYER_CREATE_INFO
  uint32_t structVersion;
  size_t structSize;
  void* loaderInstance;  // unused by the loader (null)
  char settings_file_location[kApiLayerMaxSettingsPathSize];
  XrApiLayerNextInfo* nextInfo;
};

static_assert(sizeof(XrNegotiateLoaderInfo) == 40);
static_assert(sizeof(XrNegotiateApiLayerRequest) == 48);
static_assert(offsetof(XrNegotiateApiLayerRequest, getInstanceProcAddr) == 32);
static_assert(sizeof(XrApiLayerNextInfo) == 296);
static_assert(offsetof(XrApiLayerNextInfo, nextGetInstanceProcAddr) == 272);
static_assert(sizeof(XrApiLayerCreateInfo) == 544);
static_assert(offsetof(XrApiLayerCreateInfo, nextInfo) == 536);

}  // namespace sdfg::layer
