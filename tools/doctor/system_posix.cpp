// system.h for Linux: dlopen, the process environment, and the Khronos loader's XDG search.
#include <dlfcn.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "system.h"

extern char** environ;

namespace sdfg::doctor {
namespace {

std::vector<std::string> splitColons(const std::string& text) {
  std::vector<std::string> parts;
  std::stringstream in(text);
  for (std::string part; std::getline(in, part, ':');)
    if (!part.empty()) parts.push_back(part);
  return parts;
}

std::string envOr(const char* name, const std::string& fallback) {
  const char* value = std::getenv(name);
  return value != nullptr && value[0] != '\0' ? value : fallback;
}

std::string home() {
  return envOr("HOME", "");
}

// The architecture part of active_runtime.<arch>.json, as the Khronos loader names it.
const char* archAbi() {
#if defined(__x86_64__)
  return "x86_64";
#elif defined(__aarch64__)
  return "aarch64";
#elif defined(__i386__)
  return "i686";
#elif defined(__arm__)
  return "armv7a-vfp";
#else
  return "";
#endif
}

}  // namespace

SharedLibrary::~SharedLibrary() {
  if (handle_ != nullptr) dlclose(handle_);
}

SharedLibrary::SharedLibrary(SharedLibrary&& other) noexcept : handle_(other.handle_) {
  other.handle_ = nullptr;
}

SharedLibrary& SharedLibrary::operator=(SharedLibrary&& other) noexcept {
  if (this != &other) {
    if (handle_ != nullptr) dlclose(handle_);
    handle_ = other.handle_;
    other.handle_ = nullptr;
  }
  return *this;
}

SharedLibrary SharedLibrary::open(const std::string& name, std::string& error) {
  SharedLibrary library;
  // RTLD_LOCAL: the loader's symbols stay out of the global scope, as in an app that dlopens it.
  library.handle_ = dlopen(name.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (library.handle_ == nullptr) {
    const char* why = dlerror();
    error = why != nullptr ? why : "dlopen failed";
  }
  return library;
}

void* SharedLibrary::symbol(const char* name) const {
  return handle_ != nullptr ? dlsym(handle_, name) : nullptr;
}

std::string moduleFileOf(const void* address) {
  Dl_info info{};
  if (address == nullptr || dladdr(address, &info) == 0 || info.dli_fname == nullptr) return {};
  return info.dli_fname;
}

const char* openxrLoaderName() {
  return "libopenxr_loader.so.1";
}

const char* vulkanLoaderName() {
  return "libvulkan.so.1";
}

std::optional<std::string> environmentValue(const std::string& name) {
  const char* value = std::getenv(name.c_str());
  if (value == nullptr) return std::nullopt;
  return std::string(value);
}

void setEnvironment(const std::string& name, const std::string& value) {
  setenv(name.c_str(), value.c_str(), 1);
}

void unsetEnvironment(const std::string& name) {
  unsetenv(name.c_str());
}

std::vector<std::string> environmentNamesWithPrefix(const std::string& prefix) {
  std::vector<std::string> names;
  for (char** entry = environ; entry != nullptr && *entry != nullptr; ++entry) {
    const std::string text = *entry;
    if (text.rfind(prefix, 0) == 0) names.push_back(text.substr(0, text.find('=')));
  }
  return names;
}

std::vector<ManifestSource> implicitLayerSources() {
  // The Khronos loader's order (manifest_file.cpp, ReadDataFilesInSearchPaths): the XDG config
  // folders, the compiled-in /etc, the XDG data folders, then the user's data folder.
  const std::string tail = "/openxr/1/api_layers/implicit.d";
  std::vector<ManifestSource> sources;
  const auto add = [&](const std::string& base, const std::string& origin) {
    sources.push_back({base + tail, origin, true, false});
  };
  if (const char* dirs = std::getenv("XDG_CONFIG_DIRS"); dirs != nullptr && dirs[0] != '\0') {
    for (const std::string& dir : splitColons(dirs)) add(dir, "$XDG_CONFIG_DIRS");
  } else {
    add("/etc/xdg", "default of $XDG_CONFIG_DIRS");
  }
  add("/etc", "the loader's system folder");
  if (const char* dirs = std::getenv("XDG_DATA_DIRS"); dirs != nullptr && dirs[0] != '\0') {
    for (const std::string& dir : splitColons(dirs)) add(dir, "$XDG_DATA_DIRS");
  } else {
    for (const std::string& dir : splitColons("/usr/local/share:/usr/share"))
      add(dir, "default of $XDG_DATA_DIRS");
  }
  if (const char* dir = std::getenv("XDG_DATA_HOME"); dir != nullptr && dir[0] != '\0') {
    add(dir, "$XDG_DATA_HOME");
  } else if (!home().empty()) {
    add(home() + "/.local/share", "default of $XDG_DATA_HOME");
  }
  return sources;
}

RuntimeManifestLocation activeRuntimeManifest() {
  RuntimeManifestLocation found;
  if (const char* path = std::getenv("XR_RUNTIME_JSON"); path != nullptr && path[0] != '\0') {
    found.path = path;
    found.origin = "XR_RUNTIME_JSON";
    found.searched.push_back(path);
    return found;
  }
  // FindXDGConfigFile: $XDG_CONFIG_HOME (default ~/.config), each of $XDG_CONFIG_DIRS (default
  // /etc/xdg), then /etc; in each, newer loaders take active_runtime.<arch>.json before
  // active_runtime.json.
  std::vector<std::pair<std::string, std::string>> folders;
  const std::string configHome =
      envOr("XDG_CONFIG_HOME", home().empty() ? "" : home() + "/.config");
  if (!configHome.empty()) folders.emplace_back(configHome, "$XDG_CONFIG_HOME");
  for (const std::string& dir : splitColons(envOr("XDG_CONFIG_DIRS", "/etc/xdg")))
    folders.emplace_back(dir, "$XDG_CONFIG_DIRS");
  folders.emplace_back("/etc", "the loader's system folder");
  for (const auto& [folder, origin] : folders) {
    std::vector<std::string> names;
    if (archAbi()[0] != '\0') names.push_back(std::string("active_runtime.") + archAbi() + ".json");
    names.push_back("active_runtime.json");
    for (const std::string& name : names) {
      const std::string path = folder + "/openxr/1/" + name;
      found.searched.push_back(path);
      std::error_code ec;
      if (std::filesystem::exists(path, ec)) {
        found.path = path;
        found.origin = origin;
        return found;
      }
    }
  }
  return found;
}

}  // namespace sdfg::doctor
