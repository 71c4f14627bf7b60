#include "log.h"
#include "platform.h"

#include <atomic>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <string>
#include <unordered_map>

namespace sdfg::layer {
namespace {

std::atomic<int> gLevel{int(LogLevel::warn)};

struct Sinks {
  std::mutex mutex;
  XrInstance instance = XR_NULL_HANDLE;
  PFN_xrSubmitDebugUtilsMessageEXT submit = nullptr;
  std::unordered_map<const void*, uint64_t> counts;  // per message site (format string)
};

Sinks& sinks() {
  static Sinks s;
  return s;
}

void emit(LogLevel level, const char* cmd, const char* fmt, va_list args) {
  if (!logEnabled(level)) return;
  char text[1024];
  std::vsnprintf(text, sizeof text, fmt, args);
  Sinks& s = sinks();
  std::unique_lock lock(s.mutex);
  const uint64_t n = ++s.counts[fmt];
  if (n > 10 && n % 1000 != 0) return;
  const char* suffix = n == 10 ? " (further messages of this kind are rate-limited)" : "";
  if (s.submit != nullptr) {
    XrDebugUtilsMessengerCallbackDataEXT data{XR_TYPE_DEBUG_UTILS_MESSENGER_CALLBACK_DATA_EXT};
    std::string message = std::string(text) + suffix;
    data.messageId = "XR_APILAYER_SDFG_autograsp";
    data.functionName = cmd;
    data.message = message.c_str();
    XrDebugUtilsMessageSeverityFlagsEXT severity =
        level == LogLevel::error  ? XR_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT
        : level == LogLevel::warn ? XR_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT
        : level == LogLevel::info ? XR_DEBUG_UTILS_MESSAGE_SEVERITY_INFO_BIT_EXT
                                  : XR_DEBUG_UTILS_MESSAGE_SEVERITY_VERBOSE_BIT_EXT;
    const XrInstance instance = s.instance;
    const PFN_xrSubmitDebugUtilsMessageEXT submit = s.submit;
    lock.unlock();
    submit(instance, severity, XR_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT, &data);
    return;
  }
  static const char* const names[] = {"", "error", "warning", "info", "debug"};
  const std::string line =
      std::string("[sdfg_autograsp] ") + names[int(level)] + ": " + cmd + ": " + text + suffix;
  platform::writeLogLine(line.c_str());
}

}  // namespace

LogLevel parseLogLevel(const char* text, LogLevel fallback) {
  if (text == nullptr) return fallback;
  static const struct {
    const char* name;
    LogLevel level;
  } table[] = {{"none", LogLevel::none},    {"error", LogLevel::error}, {"warn", LogLevel::warn},
               {"warning", LogLevel::warn}, {"info", LogLevel::info},   {"debug", LogLevel::debug}};
  for (const auto& e : table) {
    if (std::strcmp(text, e.name) == 0) return e.level;
  }
  return fallback;
}

void setLogLevel(LogLevel level) {
  gLevel = int(level);
}
bool logEnabled(LogLevel level) {
  return level != LogLevel::none && int(level) <= gLevel;
}

void setDebugUtilsSink(XrInstance instance, PFN_xrSubmitDebugUtilsMessageEXT submit) {
  std::lock_guard lock(sinks().mutex);
  sinks().instance = instance;
  sinks().submit = submit;
}

void clearDebugUtilsSink(XrInstance instance) {
  std::lock_guard lock(sinks().mutex);
  if (sinks().instance == instance) {
    sinks().instance = XR_NULL_HANDLE;
    sinks().submit = nullptr;
  }
}

void logMessage(LogLevel level, const char* cmd, const char* fmt, ...) {
  va_list args;
  va_start(args, fmt);
  emit(level, cmd, fmt, args);
  va_end(args);
}

XrResult logError(XrResult result, const char* cmd, const char* fmt, ...) {
  va_list args;
  va_start(args, fmt);
  emit(LogLevel::error, cmd, fmt, args);
  va_end(args);
  return result;
}

}  // namespace sdfg::layer
