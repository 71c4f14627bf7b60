// What the layer needs from the operating system, in one place: the per-user configuration
// folder, the app's Vulkan loader, and where log lines go (the one export is chosen by
// exports.map on Linux, exports.def on Windows).
// platform_posix.cpp serves Linux, platform_windows.cpp Windows; no other file of the layer or
// the engine asks which system it runs on.
#pragma once

#include <string>

namespace sdfg::layer::platform {

// The folder that holds the layer's sdfg-autograsp/config: $XDG_CONFIG_HOME (absolute), else
// ~/.config on Linux; %APPDATA% (the roaming profile, where Windows apps keep settings) on
// Windows. Empty when the environment names none.
std::string userConfigDir();

// vkGetInstanceProcAddr of the Vulkan loader the app already has loaded, without loading one:
// the layer must call into the app's copy, never a second one. Null when none is loaded.
void* loadedVulkanGetInstanceProcAddr();

// One finished log line (no newline) for people: stderr, and on Windows also the debugger's
// output (OutputDebugString), where Windows developers look first since a VR app seldom has a
// console.
void writeLogLine(const char* line);

}  // namespace sdfg::layer::platform
