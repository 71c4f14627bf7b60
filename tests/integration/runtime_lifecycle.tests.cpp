// The mock runtime through the real loader: discovery, instance and system, the session state
// sequence, the frame loop and the N-frame end, with the core validation layer stacked.
#include <catch2/catch.hpp>

#include <cstring>

#include "xr_test_support.h"

using sdfg::test::XrHarness;

namespace {

bool offersExtension(const char* name) {
  uint32_t count = 0;
  if (xrEnumerateInstanceExtensionProperties(nullptr, 0, &count, nullptr) != XR_SUCCESS)
    return false;
  std::vector<XrExtensionProperties> props(count, {XR_TYPE_EXTENSION_PROPERTIES});
  xrEnumerateInstanceExtensionProperties(nullptr, count, &count, props.data());
  for (const auto& p : props) {
    if (std::strcmp(p.extensionName, name) == 0) return true;
  }
  return false;
}

}  // namespace

TEST_CASE("The loader finds the mock runtime, which names itself and its system",
          "[runtime][instance]") {
  XrHarness xr;
  REQUIRE(xr.createResult() == XR_SUCCESS);
  XrInstanceProperties props{XR_TYPE_INSTANCE_PROPERTIES};
  REQUIRE(xrGetInstanceProperties(xr.instance(), &props) == XR_SUCCESS);
  CHECK(std::string(props.runtimeName) == "SDFG mock runtime");
  REQUIRE(xr.system() != XR_NULL_SYSTEM_ID);

  XrSystemProperties system{XR_TYPE_SYSTEM_PROPERTIES};
  REQUIRE(xrGetSystemProperties(xr.instance(), xr.system(), &system) == XR_SUCCESS);
  CHECK(system.trackingProperties.positionTracking == XR_TRUE);
  CHECK(system.graphicsProperties.maxLayerCount >= 1);

  SECTION("It offers stereo views with an opaque blend mode only") {
    uint32_t count = 0;
    REQUIRE(xrEnumerateViewConfigurations(xr.instance(), xr.system(), 0, &count, nullptr) ==
            XR_SUCCESS);
    REQUIRE(count == 1);
    XrViewConfigurationType type{};
    REQUIRE(xrEnumerateViewConfigurations(xr.instance(), xr.system(), 1, &count, &type) ==
            XR_SUCCESS);
    CHECK(type == XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO);
    XrViewConfigurationView views[2] = {{XR_TYPE_VIEW_CONFIGURATION_VIEW},
                                        {XR_TYPE_VIEW_CONFIGURATION_VIEW}};
    REQUIRE(xrEnumerateViewConfigurationViews(xr.instance(), xr.system(), type, 2, &count, views) ==
            XR_SUCCESS);
    CHECK(count == 2);
    CHECK(views[0].recommendedImageRectWidth > 0);
    XrEnvironmentBlendMode mode{};
    REQUIRE(xrEnumerateEnvironmentBlendModes(xr.instance(), xr.system(), type, 1, &count, &mode) ==
            XR_SUCCESS);
    CHECK(mode == XR_ENVIRONMENT_BLEND_MODE_OPAQUE);
  }
  SECTION("It offers Vulkan, headless and hand-tracking extensions") {
    CHECK(offersExtension("XR_KHR_vulkan_enable"));
    CHECK(offersExtension("XR_KHR_vulkan_enable2"));
    CHECK(offersExtension(XR_MND_HEADLESS_EXTENSION_NAME));
    CHECK(offersExtension(XR_EXT_HAND_TRACKING_EXTENSION_NAME));
  }
  SECTION("Its ToString functions name results and structure types") {
    char buffer[XR_MAX_STRUCTURE_NAME_SIZE] = {};
    REQUIRE(xrResultToString(xr.instance(), XR_ERROR_SESSION_NOT_RUNNING, buffer) == XR_SUCCESS);
    CHECK(std::string(buffer) == "XR_ERROR_SESSION_NOT_RUNNING");
    REQUIRE(xrStructureTypeToString(xr.instance(), XR_TYPE_FRAME_STATE, buffer) == XR_SUCCESS);
    CHECK(std::string(buffer) == "XR_TYPE_FRAME_STATE");
  }
  SECTION("Paths round-trip through xrStringToPath and xrPathToString") {
    const XrPath p = xr.path("/user/hand/left/input/squeeze/value");
    REQUIRE(p != XR_NULL_PATH);
    CHECK(xr.path("/user/hand/left/input/squeeze/value") == p);
    char text[XR_MAX_PATH_LENGTH] = {};
    uint32_t n = 0;
    REQUIRE(xrPathToString(xr.instance(), p, sizeof text, &n, text) == XR_SUCCESS);
    CHECK(std::string(text) == "/user/hand/left/input/squeeze/value");
    CHECK(n == std::strlen(text) + 1);
  }
  CHECK(xr.validationMessages().empty());
}

TEST_CASE("A session goes IDLE, READY, then SYNCHRONIZED, VISIBLE, FOCUSED at the first frame",
          "[runtime][session]") {
  XrHarness xr;
  REQUIRE(xr.createResult() == XR_SUCCESS);
  const auto session = xr.createHeadlessSession();
  REQUIRE(session);
  CHECK(xr.pollStates() ==
        std::vector<XrSessionState>{XR_SESSION_STATE_IDLE, XR_SESSION_STATE_READY});
  REQUIRE(xr.begin(*session) == XR_SUCCESS);
  CHECK(xr.pollStates().empty());

  XrFrameState first{XR_TYPE_FRAME_STATE};
  REQUIRE(xr.frame(*session, &first) == XR_SUCCESS);
  CHECK(first.shouldRender == XR_TRUE);
  CHECK(first.predictedDisplayPeriod > 0);
  CHECK(xr.pollStates() == std::vector<XrSessionState>{XR_SESSION_STATE_SYNCHRONIZED,
                                                       XR_SESSION_STATE_VISIBLE,
                                                       XR_SESSION_STATE_FOCUSED});

  SECTION("Predicted display times strictly increase") {
    XrTime last = first.predictedDisplayTime;
    for (int i = 0; i < 5; ++i) {
      XrFrameState s{XR_TYPE_FRAME_STATE};
      REQUIRE(xr.frame(*session, &s) == XR_SUCCESS);
      CHECK(s.predictedDisplayTime > last);
      last = s.predictedDisplayTime;
    }
    CHECK(xr.stats(*session).framesEnded == 6);
  }
  SECTION("xrRequestExitSession leads to STOPPING, and xrEndSession to IDLE and EXITING") {
    REQUIRE(xrRequestExitSession(*session) == XR_SUCCESS);
    CHECK(xr.pollStates() == std::vector<XrSessionState>{XR_SESSION_STATE_VISIBLE,
                                                         XR_SESSION_STATE_SYNCHRONIZED,
                                                         XR_SESSION_STATE_STOPPING});
    REQUIRE(xrEndSession(*session) == XR_SUCCESS);
    CHECK(xr.pollStates() ==
          std::vector<XrSessionState>{XR_SESSION_STATE_IDLE, XR_SESSION_STATE_EXITING});
  }
  SECTION("Destroying a running session without xrEndSession is safe") {
    CHECK(xrDestroySession(*session) == XR_SUCCESS);
    CHECK(xr.pollStates().empty());
  }
  CHECK(xr.validationMessages().empty());
}

TEST_CASE("The runtime ends the session after the number of frames it is asked for",
          "[runtime][session]") {
  const uint64_t n = GENERATE(1, 7);
  const bool viaEnvironment = GENERATE(false, true);
  CAPTURE(n, viaEnvironment);
  sdfg::test::InstanceOptions options;
  if (viaEnvironment) options.env = {{SDFG_MOCK_ENV_END_AFTER_FRAMES, std::to_string(n)}};
  XrHarness xr(options);
  REQUIRE(xr.createResult() == XR_SUCCESS);
  if (!viaEnvironment)
    REQUIRE(xr.setScript("end_after_frames " + std::to_string(n) + "\n") == XR_SUCCESS);
  auto session = xr.createHeadlessSession();
  REQUIRE(session);
  xr.pollStates();
  REQUIRE(xr.begin(*session) == XR_SUCCESS);

  uint64_t frames = 0;
  std::vector<XrSessionState> states;
  while (frames < 100 && (states.empty() || states.back() != XR_SESSION_STATE_STOPPING)) {
    REQUIRE(xr.frame(*session) == XR_SUCCESS);
    ++frames;
    for (XrSessionState s : xr.pollStates()) states.push_back(s);
  }
  CHECK(frames == n);
  CHECK(xr.stats(*session).framesEnded == n);
  REQUIRE(states.size() >= 3);
  const std::vector<XrSessionState> tail(states.end() - 3, states.end());
  CHECK(tail == std::vector<XrSessionState>{XR_SESSION_STATE_VISIBLE, XR_SESSION_STATE_SYNCHRONIZED,
                                            XR_SESSION_STATE_STOPPING});
  // A stopping session renders no more: xrEndSession is the next step.
  XrFrameState state{XR_TYPE_FRAME_STATE};
  REQUIRE(xrWaitFrame(*session, nullptr, &state) == XR_SUCCESS);
  CHECK(state.shouldRender == XR_FALSE);
  REQUIRE(xrBeginFrame(*session, nullptr) == XR_SUCCESS);
  XrFrameEndInfo end{XR_TYPE_FRAME_END_INFO};
  end.displayTime = state.predictedDisplayTime;
  end.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
  REQUIRE(xrEndFrame(*session, &end) == XR_SUCCESS);
  REQUIRE(xrEndSession(*session) == XR_SUCCESS);
  CHECK(xr.pollStates() ==
        std::vector<XrSessionState>{XR_SESSION_STATE_IDLE, XR_SESSION_STATE_EXITING});
  CHECK(xr.validationMessages().empty());
}

TEST_CASE("The runtime never hands out a handle value twice, so a destroyed one stays invalid",
          "[runtime][session]") {
  // Without core validation: it would refuse the stale handle itself, and the point here is
  // that the runtime does.
  sdfg::test::InstanceOptions options;
  options.coreValidation = false;
  XrHarness xr(options);
  REQUIRE(xr.createResult() == XR_SUCCESS);
  auto getStats = xr.proc<PFN_xrMockRuntimeGetStatsSDFG>("xrMockRuntimeGetStatsSDFG");
  REQUIRE(getStats != nullptr);
  std::vector<XrSession> seen;
  for (int i = 0; i < 8; ++i) {
    const auto session = xr.createHeadlessSession();
    REQUIRE(session);
    for (XrSession old : seen) {
      CHECK(*session != old);
      // The destroyed session's handle names nothing, not the new session.
      XrMockRuntimeStatsSDFG stats{};
      CHECK(getStats(old, &stats) == XR_ERROR_HANDLE_INVALID);
    }
    seen.push_back(*session);
    REQUIRE(xrDestroySession(*session) == XR_SUCCESS);
  }
}
