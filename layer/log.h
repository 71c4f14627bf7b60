// Logging of the layer: a level, a rate limit per message site, and two sinks. When the app
// enabled XR_EXT_debug_utils, messages go down the chain through xrSubmitDebugUtilsMessageEXT
// (so they reach the app's messengers); otherwise to stderr prefixed "[sdfg_autograsp]".
// Thread-safe: calls may come from the app's render and main threads at once.
#pragma once

#include <openxr/openxr.h>

namespace sdfg::layer {

enum class LogLevel { none = 0, error, warn, info, debug };

// "none", "error", "warn", "info", "debug"; anything else keeps `fallback`.
LogLevel parseLogLevel(const char* text, LogLevel fallback);
void setLogLevel(LogLevel level);
bool logEnabled(LogLevel level);

// Routes messages to the debug-utils sink of `instance` (null pfn: back to stderr).
void setDebugUtilsSink(XrInstance instance, PFN_xrSubmitDebugUtilsMessageEXT submit);
void clearDebugUtilsSink(XrInstance instance);

// Formats follow C99 (gnu_printf): MinGW's GCC would check plain "printf" against Microsoft's
// older rules (no %zu), while the layer formats with the C99 vsnprintf on every system.
// Logs "cmd: message". A site (identified by `fmt`) logs its first 10 messages, then every
// 1000th, so a per-frame warning cannot flood the log.
void logMessage(LogLevel level, const char* cmd, const char* fmt, ...)
    __attribute__((format(gnu_printf, 3, 4)));

// Logs at error level and returns `result`: every error path is one return line.
XrResult logError(XrResult result, const char* cmd, const char* fmt, ...)
    __attribute__((format(gnu_printf, 3, 4)));

}  // namespace sdfg::layer

#define SDFG_LOG_WARN(cmd, ...) \
  ::sdfg::layer::logMessage(::sdfg::layer::LogLevel::warn, cmd, __VA_ARGS__)
#define SDFG_LOG_INFO(cmd, ...) \
  ::sdfg::layer::logMessage(::sdfg::layer::LogLevel::info, cmd, __VA_ARGS__)
#define SDFG_LOG_DEBUG(cmd, ...) \
  ::sdfg::layer::logMessage(::sdfg::layer::LogLevel::debug, cmd, __VA_ARGS__)
