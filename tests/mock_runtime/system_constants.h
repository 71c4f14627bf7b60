// Fixed properties of the simulated headset, shared by the files that report or check them.
#pragma once

#include <openxr/openxr.h>

#include <cstdint>

namespace sdfg::mock {

inline constexpr XrSystemId kSystemId = 1;
inline constexpr uint32_t kViewCount = 2;
// Small views: lavapipe renders on the CPU and tests run on two shared cores.
inline constexpr uint32_t kViewSize = 128;
inline constexpr uint32_t kMaxImageSize = 2048;
inline constexpr uint32_t kMaxLayerCount = 16;
inline constexpr uint32_t kImagesPerSwapchain = 3;
inline constexpr float kHalfIpd = 0.032f;             // metres
inline constexpr float kHalfFov = 0.7853982f;         // 45 degrees each way
inline constexpr float kStageHeight = 1.6f;           // LOCAL origin above the STAGE floor
inline constexpr XrDuration kFramePeriod = 11111111;  // 90 Hz, in ns

}  // namespace sdfg::mock
