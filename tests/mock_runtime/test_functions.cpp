// Test-only commands of mock_runtime_test.h that read session state, and the call gates
// (xrMockRuntimeSetScriptSDFG lives with the instance, which owns the script).
#include <cstring>

#include "entry_points.h"

namespace sdfg::mock {

XrResult mockGetStats(XrSession handle, XrMockRuntimeStatsSDFG* stats) {
  constexpr const char* cmd = "xrMockRuntimeGetStatsSDFG";
  const Session* session = lookup<Session>(handle);
  if (session == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "session is not valid");
  MOCK_VERIFY_NOT_NULL(cmd, stats);
  *stats = session->stats;
  stats->liveSpaces = uint32_t(session->spaces.size());
  stats->liveHandTrackers = uint32_t(session->handTrackers.size());
  return XR_SUCCESS;
}

XrResult mockGetDepthStats(XrSession handle, uint32_t* framesWithDepth, uint32_t* depthInfos) {
  constexpr const char* cmd = "xrMockRuntimeGetDepthStatsSDFG";
  const Session* session = lookup<Session>(handle);
  if (session == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "session is not valid");
  MOCK_VERIFY_NOT_NULL(cmd, framesWithDepth);
  MOCK_VERIFY_NOT_NULL(cmd, depthInfos);
  *framesWithDepth = session->framesWithDepth;
  *depthInfos = session->depthInfos;
  return XR_SUCCESS;
}

XrResult mockGetCapture(XrSession handle, uint32_t viewIndex, uint32_t capacityBytes,
                        uint32_t* width, uint32_t* height, uint8_t* rgba) {
  constexpr const char* cmd = "xrMockRuntimeGetCaptureSDFG";
  const Session* session = lookup<Session>(handle);
  if (session == nullptr) return fail(cmd, XR_ERROR_HANDLE_INVALID, "session is not valid");
  MOCK_VERIFY_NOT_NULL(cmd, width);
  MOCK_VERIFY_NOT_NULL(cmd, height);
  if (viewIndex >= session->captures.size())
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "viewIndex %u", viewIndex);
  const CapturedImage& image = session->captures[viewIndex];
  if (image.rgba.empty())
    return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "nothing captured for view %u", viewIndex);
  *width = image.width;
  *height = image.height;
  if (capacityBytes == 0) return XR_SUCCESS;
  if (capacityBytes < image.rgba.size())
    return fail(cmd, XR_ERROR_SIZE_INSUFFICIENT, "capacityBytes %u < %zu", capacityBytes,
                image.rgba.size());
  MOCK_VERIFY_NOT_NULL(cmd, rgba);
  std::memcpy(rgba, image.rgba.data(), image.rgba.size());
  return XR_SUCCESS;
}

XrResult mockGateCalls(XrInstance handle, const char* command, XrBool32 hold,
                       uint32_t delayMicroseconds) {
  constexpr const char* cmd = "xrMockRuntimeGateCallsSDFG";
  if (lookup<Instance>(handle) == nullptr)
    return fail(cmd, XR_ERROR_HANDLE_INVALID, "instance is not valid");
  CallGate* gate = findGate(command);
  if (gate == nullptr) return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "(command) is unknown");
  gate->set(hold == XR_TRUE, delayMicroseconds);
  return XR_SUCCESS;
}

XrResult mockGateStats(XrInstance handle, const char* command, uint32_t* waiting,
                       uint64_t* passed) {
  constexpr const char* cmd = "xrMockRuntimeGateStatsSDFG";
  if (lookup<Instance>(handle) == nullptr)
    return fail(cmd, XR_ERROR_HANDLE_INVALID, "instance is not valid");
  MOCK_VERIFY_NOT_NULL(cmd, waiting);
  MOCK_VERIFY_NOT_NULL(cmd, passed);
  const CallGate* gate = findGate(command);
  if (gate == nullptr) return fail(cmd, XR_ERROR_VALIDATION_FAILURE, "(command) is unknown");
  gate->stats(*waiting, *passed);
  return XR_SUCCESS;
}

}  // namespace sdfg::mock
