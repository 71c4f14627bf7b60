#include "xr_test_support.h"

#include <openxr/openxr_reflection.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>

namespace sdfg::test {

void useMockRuntime() {
  setenv("XR_RUNTIME_JSON", SDFG_MOCK_RUNTIME_JSON, 1);
  setenv("VK_ICD_FILENAMES", "/usr/share/vulkan/icd.d/lvp_icd.x86_64.json", 1);
  setenv("VK_DRIVER_FILES", "/usr/share/vulkan/icd.d/lvp_icd.x86_64.json", 1);
  for (const char* name :
       {SDFG_MOCK_ENV_SCRIPT, SDFG_MOCK_ENV_END_AFTER_FRAMES, SDFG_MOCK_ENV_HAND_TRACKING,
        SDFG_MOCK_ENV_CAPTURE, SDFG_MOCK_ENV_REPORT, SDFG_MOCK_ENV_PROFILE, SDFG_MOCK_ENV_FAULT,
        "XR_ENABLE_API_LAYERS", "XR_API_LAYER_PATH"})
    unsetenv(name);
}

std::string resultName(XrResult r) {
  switch (r) {
#define SDFG_RESULT_NAME(n, v) \
  case n:                      \
    return #n;
    XR_LIST_ENUM_XrResult(SDFG_RESULT_NAME)
#undef SDFG_RESULT_NAME
            default : return "XrResult(" +
                      std::to_string(int(r)) + ")";
  }
}

XrHarness::XrHarness(const InstanceOptions& options) {
  useMockRuntime();
  for (const auto& [name, value] : options.env) setenv(name.c_str(), value.c_str(), 1);
  if (options.coreValidation) {
    static int counter = 0;
    validationFile_ = "/tmp/sdfg-core-validation-" + std::to_string(getpid()) + "-" +
                      std::to_string(counter++) + ".txt";
    std::remove(validationFile_.c_str());
    setenv("XR_ENABLE_API_LAYERS", "XR_APILAYER_LUNARG_core_validation", 1);
    setenv("XR_CORE_VALIDATION_FILE_NAME", validationFile_.c_str(), 1);
  }
  std::vector<const char*> names;
  for (const auto& e : options.extensions) names.push_back(e.c_str());
  XrInstanceCreateInfo info{XR_TYPE_INSTANCE_CREATE_INFO};
  std::snprintf(info.applicationInfo.applicationName, XR_MAX_APPLICATION_NAME_SIZE,
                "sdfg-runtime-tests");
  info.applicationInfo.apiVersion = XR_MAKE_VERSION(1, 0, 20);
  info.enabledExtensionCount = uint32_t(names.size());
  info.enabledExtensionNames = names.data();
  createResult_ = xrCreateInstance(&info, &instance_);
  unsetenv("XR_ENABLE_API_LAYERS");
  if (createResult_ != XR_SUCCESS) return;
  XrSystemGetInfo systemInfo{XR_TYPE_SYSTEM_GET_INFO};
  systemInfo.formFactor = XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY;
  if (xrGetSystem(instance_, &systemInfo, &system_) != XR_SUCCESS) system_ = XR_NULL_SYSTEM_ID;
}

XrHarness::~XrHarness() {
  destroy();
  if (!validationFile_.empty()) std::remove(validationFile_.c_str());
}

void XrHarness::destroy() {
  if (instance_ != XR_NULL_HANDLE) xrDestroyInstance(instance_);
  instance_ = XR_NULL_HANDLE;
}

std::vector<std::string> XrHarness::validationMessages() const {
  std::vector<std::string> lines;
  if (validationFile_.empty()) return lines;
  std::ifstream in(validationFile_);
  for (std::string line; std::getline(in, line);) {
    if (line.find("VALID_") != std::string::npos) lines.push_back(line);
  }
  return lines;
}

XrResult XrHarness::setScript(const std::string& text) const {
  auto set = proc<PFN_xrMockRuntimeSetScriptSDFG>("xrMockRuntimeSetScriptSDFG");
  return set == nullptr ? XR_ERROR_FUNCTION_UNSUPPORTED : set(instance_, text.c_str());
}

XrMockRuntimeStatsSDFG XrHarness::stats(XrSession session) const {
  XrMockRuntimeStatsSDFG s{};
  if (auto get = proc<PFN_xrMockRuntimeGetStatsSDFG>("xrMockRuntimeGetStatsSDFG")) get(session, &s);
  return s;
}

XrPath XrHarness::path(const char* s) const {
  XrPath p = XR_NULL_PATH;
  xrStringToPath(instance_, s, &p);
  return p;
}

std::vector<XrSessionState> XrHarness::pollStates() const {
  std::vector<XrSessionState> states;
  for (;;) {
    XrEventDataBuffer event{XR_TYPE_EVENT_DATA_BUFFER};
    if (xrPollEvent(instance_, &event) != XR_SUCCESS) break;
    if (event.type == XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED)
      states.push_back(reinterpret_cast<XrEventDataSessionStateChanged&>(event).state);
  }
  return states;
}

std::optional<XrSession> XrHarness::createHeadlessSession() const {
  XrSessionCreateInfo info{XR_TYPE_SESSION_CREATE_INFO};
  info.systemId = system_;
  XrSession session = XR_NULL_HANDLE;
  if (xrCreateSession(instance_, &info, &session) != XR_SUCCESS) return std::nullopt;
  return session;
}

XrResult XrHarness::begin(XrSession session) const {
  XrSessionBeginInfo info{XR_TYPE_SESSION_BEGIN_INFO};
  info.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
  return xrBeginSession(session, &info);
}

XrResult XrHarness::frame(XrSession session, XrFrameState* stateOut) const {
  XrFrameState state{XR_TYPE_FRAME_STATE};
  XrResult r = xrWaitFrame(session, nullptr, &state);
  if (r != XR_SUCCESS) return r;
  if (stateOut != nullptr) *stateOut = state;
  if ((r = xrBeginFrame(session, nullptr)) != XR_SUCCESS) return r;
  XrFrameEndInfo end{XR_TYPE_FRAME_END_INFO};
  end.displayTime = state.predictedDisplayTime;
  end.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
  return xrEndFrame(session, &end);
}

}  // namespace sdfg::test
