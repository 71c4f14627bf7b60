// What the layer tests ask of the mock runtime and of a hand tracker beside their own checks:
// the runtime's counters for a session (frames, depth submissions), and whether a tracker's hand
// is active now.
#pragma once

#include <catch2/catch.hpp>

#include "xr_harness.h"
// After the OpenXR headers (xr_harness.h), which it assumes.
#include "../mock_runtime/mock_runtime_test.h"

namespace sdfg::test {

// The mock runtime's counters for the app's session (frames, syncs, live spaces...).
inline XrMockRuntimeStatsSDFG mockStats(const App& app) {
  XrMockRuntimeStatsSDFG s{};
  auto get = app.fn<PFN_xrMockRuntimeGetStatsSDFG>("xrMockRuntimeGetStatsSDFG");
  REQUIRE(get != nullptr);
  REQUIRE(get(app.session, &s) == XR_SUCCESS);
  return s;
}

// The mock runtime's XR_KHR_composition_layer_depth counters for the app's session.
struct MockDepthStats {
  uint32_t framesWithDepth = 0;  // accepted frames with at least one depth info
  uint32_t depthInfos = 0;       // depth infos in them
};
inline MockDepthStats mockDepthStats(const App& app) {
  MockDepthStats s;
  auto get = app.fn<PFN_xrMockRuntimeGetDepthStatsSDFG>("xrMockRuntimeGetDepthStatsSDFG");
  REQUIRE(get != nullptr);
  REQUIRE(get(app.session, &s.framesWithDepth, &s.depthInfos) == XR_SUCCESS);
  return s;
}

// Whether `tracker` locates an active hand at the app's last frame time.
inline bool isActive(const App& app, XrHandTrackerEXT tracker) {
  Joints j;
  return locateJoints(app, tracker, j) == XR_SUCCESS && j.locations.isActive;
}

}  // namespace sdfg::test
