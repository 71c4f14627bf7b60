// OpenXR headers as the layer includes them: Vulkan types first (openxr_platform.h needs them),
// then the platform header and the layer's own extension.
#pragma once

#include <time.h>
#include <vulkan/vulkan.h>

#define XR_USE_GRAPHICS_API_VULKAN
#define XR_USE_TIMESPEC
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>

#include <openxr/XR_SDFG_auto_grasp.h>
#include <openxr/sdfg_hand_tracking_data_source.h>
