// Test interface of the SDFG mock OpenXR runtime (tests/mock_runtime).
//
// The mock runtime is a headless OpenXR 1.0 runtime loaded by the real Khronos loader through
// XR_RUNTIME_JSON. Tests steer it in two ways, both described in docs/mock-runtime.md:
//   - environment variables, read when the instance is created (names below);
//   - test-only functions, which are no OpenXR extension: fetch them with
//     xrGetInstanceProcAddr(instance, "xrMockRuntime...SDFG", ...) like any other command.
// Include <openxr/openxr.h> before this header.
#pragma once

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

// Timeline file (text, one keyframe per line; format in docs/mock-runtime.md).
#define SDFG_MOCK_ENV_SCRIPT "SDFG_MOCK_SCRIPT"
// After this many xrEndFrame calls the runtime ends the session (VISIBLE, SYNCHRONIZED,
// STOPPING, then IDLE and EXITING after xrEndSession). Unset or 0: never.
#define SDFG_MOCK_ENV_END_AFTER_FRAMES "SDFG_MOCK_END_AFTER_FRAMES"
// "1" (default): XR_EXT_hand_tracking offered and supported; "0": offered, but the system
// reports supportsHandTracking = XR_FALSE (xrCreateHandTrackerEXT -> FEATURE_UNSUPPORTED);
// "absent": not offered at all (a runtime with controllers only).
#define SDFG_MOCK_ENV_HAND_TRACKING "SDFG_MOCK_HAND_TRACKING"
// Path of a binary PPM (P6) that receives the last image submitted for the left view, written
// when the session is destroyed. Setting it (or SDFG_MOCK_REPORT) turns on frame capture.
#define SDFG_MOCK_ENV_CAPTURE "SDFG_MOCK_CAPTURE"
// Path of a "key value" text report (frame counts, capture summary) written when the session
// is destroyed; the hello_xr client test reads it.
#define SDFG_MOCK_ENV_REPORT "SDFG_MOCK_REPORT"
// Interaction profile of the simulated controllers (default /interaction_profiles/oculus/
// touch_controller). The script directive "profile" overrides it.
#define SDFG_MOCK_ENV_PROFILE "SDFG_MOCK_PROFILE"
// One deliberate misbehaviour, so tests can prove their checks catch it:
// "skip_layout_transition": swapchain images stay in VK_IMAGE_LAYOUT_UNDEFINED (the Vulkan
// validation layer then reports the app's render pass);
// "zero_display_time": xrWaitFrame predicts a display time of 0 and xrEndFrame accepts 0, as
// Monado does in headless sessions;
// "refuse_depth_readback": xrCreateSwapchain of a depth format fails with
// XR_ERROR_FEATURE_UNSUPPORTED when usageFlags has TRANSFER_SRC or SAMPLED (the same create
// without them succeeds), as a runtime whose depth images only its compositor may read.
#define SDFG_MOCK_ENV_FAULT "SDFG_MOCK_FAULT"
// "1": log every error the runtime returns, and why, on stderr.
#define SDFG_MOCK_ENV_LOG "SDFG_MOCK_LOG"

// Counters and last values of one session, for tests to assert on.
typedef struct XrMockRuntimeStatsSDFG {
  XrSessionState state;       // last state queued for the application
  uint64_t frameIndex;        // frame the script is sampled at (= framesEnded)
  uint64_t framesWaited;      // xrWaitFrame calls that succeeded
  uint64_t framesBegun;       // xrBeginFrame calls that succeeded
  uint64_t framesEnded;       // xrEndFrame calls that succeeded
  uint64_t framesWithLayers;  // ... of which submitted at least one composition layer
  uint64_t framesCaptured;    // frames whose projection images were copied to memory
  uint32_t lastLayerCount;    // layerCount of the last successful xrEndFrame
  XrPath currentProfile;      // interaction profile in use, XR_NULL_PATH before attach
  uint64_t hapticCount[2];    // xrApplyHapticFeedback calls per hand (0 left, 1 right)
  float lastHapticAmplitude[2];
  uint64_t syncCount;                             // xrSyncActions calls that succeeded
  XrHandJointsMotionRangeEXT lastMotionRange[2];  // last requested per hand, 0 if none
  uint64_t handTrackersRefused;  // xrCreateHandTrackerEXT calls refused: no hand tracking
  uint32_t liveSpaces;           // spaces of the session not destroyed (the app's and layers')
  uint32_t liveHandTrackers;     // hand trackers of the session not destroyed
} XrMockRuntimeStatsSDFG;

// Replaces the instance's timeline (and its directives) with `scriptText`, a NUL-terminated
// string in the timeline file format. Errors: XR_ERROR_VALIDATION_FAILURE when the text does
// not parse (the old timeline stays), XR_ERROR_HANDLE_INVALID for a bad instance.
typedef XrResult(XRAPI_PTR* PFN_xrMockRuntimeSetScriptSDFG)(XrInstance instance,
                                                            const char* scriptText);

// Fills `stats` (caller-owned) for `session`.
typedef XrResult(XRAPI_PTR* PFN_xrMockRuntimeGetStatsSDFG)(XrSession session,
                                                           XrMockRuntimeStatsSDFG* stats);

// XR_KHR_composition_layer_depth in `session`, counted in xrEndFrame calls that succeeded and
// only when the app enabled the extension (otherwise depth infos are ignored): the frames with
// at least one XrCompositionLayerDepthInfoKHR chained on a projection view, and how many such
// infos there were in all. Each one was checked (a depth swapchain of the session with a
// released image, rect inside it, 0 <= minDepth < maxDepth <= 1, nearZ != farZ, both >= 0 and
// not NaN; either may be +infinity). Errors: XR_ERROR_HANDLE_INVALID, XR_ERROR_VALIDATION_FAILURE
// (a null pointer).
typedef XrResult(XRAPI_PTR* PFN_xrMockRuntimeGetDepthStatsSDFG)(XrSession session,
                                                                uint32_t* framesWithDepth,
                                                                uint32_t* depthInfos);

// Copies the last captured image of projection view `viewIndex` (0 left, 1 right) as tightly
// packed RGBA8 rows, top row first, into `rgba` (caller-owned, `capacityBytes` bytes). Two-call
// idiom: with capacityBytes 0 only width and height are written. Capture must be on (script
// directive "capture 1", or the environment variables above).
// Errors: XR_ERROR_SIZE_INSUFFICIENT when capacityBytes < width * height * 4 (and not 0);
// XR_ERROR_VALIDATION_FAILURE when nothing was captured for that view.
typedef XrResult(XRAPI_PTR* PFN_xrMockRuntimeGetCaptureSDFG)(XrSession session, uint32_t viewIndex,
                                                             uint32_t capacityBytes,
                                                             uint32_t* width, uint32_t* height,
                                                             uint8_t* rgba);

// Gates one command of the runtime (`command`, e.g. "xrGetActionStateFloat"), for tests of
// callers with several threads. A gated call waits before it takes the runtime's lock, so the
// other commands go on meanwhile: with `hold` XR_TRUE every call of the command waits until a
// later call with `hold` XR_FALSE opens the gate; `delayMicroseconds` makes every call sleep that
// long first (0: none). Process-wide, until changed. Errors: XR_ERROR_VALIDATION_FAILURE (null or
// unknown command), XR_ERROR_HANDLE_INVALID (instance).
typedef XrResult(XRAPI_PTR* PFN_xrMockRuntimeGateCallsSDFG)(XrInstance instance,
                                                            const char* command, XrBool32 hold,
                                                            uint32_t delayMicroseconds);

// How many calls of `command` wait at its gate right now, and how many passed it since the
// process started. Same errors as above.
typedef XrResult(XRAPI_PTR* PFN_xrMockRuntimeGateStatsSDFG)(XrInstance instance,
                                                            const char* command, uint32_t* waiting,
                                                            uint64_t* passed);

#ifdef __cplusplus
}
#endif
