// platform.h for Linux (and other POSIX systems).
#include "platform.h"

#include <dlfcn.h>

#include <cstdio>
#include <cstdlib>

namespace sdfg::layer::platform {

std::string userConfigDir() {
  if (const char* xdg = std::getenv("XDG_CONFIG_HOME"); xdg != nullptr && xdg[0] == '/') return xdg;
  if (const char* home = std::getenv("HOME"); home != nullptr && home[0] != '\0')
    return std::string(home) + "/.config";
  return {};
}

void* loadedVulkanGetInstanceProcAddr() {
  // The loader the app linked (or dlopened globally) is in the global scope.
  if (void* f = dlsym(RTLD_DEFAULT, "vkGetInstanceProcAddr")) return f;
  // Loaded with RTLD_LOCAL: found by name; RTLD_NOLOAD never loads a new copy.
  if (void* lib = dlopen("libvulkan.so.1", RTLD_NOW | RTLD_NOLOAD)) {
    void* f = dlsym(lib, "vkGetInstanceProcAddr");
    dlclose(lib);  // drops only the reference RTLD_NOLOAD took; the app's stays
    return f;
  }
  return nullptr;
}

void writeLogLine(const char* line) {
  std::fprintf(stderr, "%s\n", line);
}

}  // namespace sdfg::layer::platform
