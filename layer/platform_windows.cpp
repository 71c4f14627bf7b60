// platform.h for Windows.
#include "platform.h"

#ifndef WIN32_LEAN_AND_MEAN
#define WIN32_LEAN_AND_MEAN
#endif
#include <windows.h>

#include <cstdio>
#include <cstdlib>

namespace sdfg::layer::platform {

std::string userConfigDir() {
  // %APPDATA% is set in every interactive session; an absolute XDG_CONFIG_HOME still wins, for
  // people (and tests) who keep one configuration across systems.
  if (const char* xdg = std::getenv("XDG_CONFIG_HOME"); xdg != nullptr && xdg[0] != '\0')
    return xdg;
  if (const char* appdata = std::getenv("APPDATA"); appdata != nullptr && appdata[0] != '\0')
    return appdata;
  return {};
}

void* loadedVulkanGetInstanceProcAddr() {
  // GetModuleHandle only finds a DLL the process loaded already; it never loads one.
  HMODULE vulkan = GetModuleHandleA("vulkan-1.dll");
  if (vulkan == nullptr) return nullptr;
  return reinterpret_cast<void*>(GetProcAddress(vulkan, "vkGetInstanceProcAddr"));
}

void writeLogLine(const char* line) {
  std::fprintf(stderr, "%s\n", line);
  std::string text = std::string(line) + "\n";
  OutputDebugStringA(text.c_str());
}

}  // namespace sdfg::layer::platform
