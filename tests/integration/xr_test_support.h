// Helpers for tests that drive the mock runtime through the real Khronos loader: environment
// set-up, an instance with optional core validation stacked, the runtime's test-only
// functions, and a headless session driven through its state sequence.
#pragma once

#include <openxr/openxr.h>

#include <cstdlib>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "mock_runtime_test.h"

namespace sdfg::test {

// Sets an environment variable for the lifetime of the object, then restores the old value.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    if (value != nullptr)
      setenv(name, value, 1);
    else
      unsetenv(name);
  }
  ~ScopedEnv() {
    if (old_)
      setenv(name_.c_str(), old_->c_str(), 1);
    else
      unsetenv(name_.c_str());
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  std::string name_;
  std::optional<std::string> old_;
};

// Points the loader at the mock runtime and clears every SDFG_MOCK_* knob, so each test starts
// from the runtime's defaults. Call before creating an instance.
void useMockRuntime();

struct InstanceOptions {
  std::vector<std::string> extensions = {XR_MND_HEADLESS_EXTENSION_NAME};
  bool coreValidation = true;  // stack XR_APILAYER_LUNARG_core_validation
  // SDFG_MOCK_* variables to set (after clearing them all) before the instance is created.
  std::vector<std::pair<std::string, std::string>> env;
};

// An XrInstance on the mock runtime, destroyed with the object. With core validation on, its
// messages go to a fresh file that validationMessages() reads.
class XrHarness {
 public:
  explicit XrHarness(const InstanceOptions& options = {});
  ~XrHarness();
  XrHarness(const XrHarness&) = delete;
  XrHarness& operator=(const XrHarness&) = delete;

  XrResult createResult() const { return createResult_; }
  XrInstance instance() const { return instance_; }
  XrSystemId system() const { return system_; }

  // Lines the core validation layer logged ("VALID_..."), empty when none.
  std::vector<std::string> validationMessages() const;

  template <class PFN>
  PFN proc(const char* name) const {
    PFN_xrVoidFunction f = nullptr;
    if (xrGetInstanceProcAddr(instance_, name, &f) != XR_SUCCESS) return nullptr;
    return reinterpret_cast<PFN>(f);
  }

  XrResult setScript(const std::string& text) const;
  XrMockRuntimeStatsSDFG stats(XrSession session) const;
  XrPath path(const char* s) const;

  // Creates a headless session and polls IDLE and READY; nullopt on failure.
  std::optional<XrSession> createHeadlessSession() const;
  // Every state-change event queued now, in order.
  std::vector<XrSessionState> pollStates() const;
  // Begins `session` (must be READY) with the stereo configuration.
  XrResult begin(XrSession session) const;
  // One wait/begin/end with no layers; returns the first failing result.
  XrResult frame(XrSession session, XrFrameState* state = nullptr) const;
  // Destroys the instance early (for tests of what happens after).
  void destroy();

 private:
  XrResult createResult_ = XR_ERROR_RUNTIME_FAILURE;
  XrInstance instance_ = XR_NULL_HANDLE;
  XrSystemId system_ = XR_NULL_SYSTEM_ID;
  std::string validationFile_;
};

// Readable name of a result, for failure messages (no instance needed).
std::string resultName(XrResult r);

}  // namespace sdfg::test
