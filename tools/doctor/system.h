// What autograsp-doctor asks of the operating system: shared libraries opened at run time (the
// OpenXR and Vulkan loaders, so that a machine without either gets a diagnosis instead of a
// program that does not start), the process environment, and the places the Khronos loader
// looks for implicit API layers and the active runtime. system_posix.cpp serves Linux,
// system_windows.cpp Windows (the registry); nothing else in the tool asks which system it is on.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace sdfg::doctor {

// A shared library opened by name or path, closed with the object.
class SharedLibrary {
 public:
  SharedLibrary() = default;
  ~SharedLibrary();
  SharedLibrary(const SharedLibrary&) = delete;
  SharedLibrary& operator=(const SharedLibrary&) = delete;
  SharedLibrary(SharedLibrary&& other) noexcept;
  SharedLibrary& operator=(SharedLibrary&& other) noexcept;

  // Opens `name` (a file name the system searches for, or a path); on failure `error` says why.
  static SharedLibrary open(const std::string& name, std::string& error);
  bool isOpen() const { return handle_ != nullptr; }
  void* symbol(const char* name) const;

 private:
  void* handle_ = nullptr;
};

// The file of the library (or program) whose code holds `address`; empty when none does.
std::string moduleFileOf(const void* address);

// File names of the loaders as applications load them.
const char* openxrLoaderName();
const char* vulkanLoaderName();

// The environment. A variable set to the empty string counts as set, as the loader counts it.
std::optional<std::string> environmentValue(const std::string& name);
void setEnvironment(const std::string& name, const std::string& value);
void unsetEnvironment(const std::string& name);
// Names of the variables that start with `prefix`.
std::vector<std::string> environmentNamesWithPrefix(const std::string& prefix);

// A place the loader takes implicit layer manifests from, in the loader's order: a folder (whose
// .json files count) or, on Windows, one registry value naming a manifest.
struct ManifestSource {
  std::string path;    // folder, or manifest file for a registry value
  std::string origin;  // why the loader looks there, e.g. "$XDG_DATA_HOME", "HKLM registry"
  bool folder = true;
  bool registryDisabled = false;  // Windows: the value's data is not 0, so the loader skips it
};
std::vector<ManifestSource> implicitLayerSources();

// The active runtime's manifest as the loader finds it: XR_RUNTIME_JSON, else the system's
// standard place (active_runtime.json under the XDG config folders and /etc on Linux, the
// registry's ActiveRuntime on Windows). `path` is empty when none is found; `searched` lists where
// the loader would have looked.
struct RuntimeManifestLocation {
  std::string path;
  std::string origin;
  std::vector<std::string> searched;
};
RuntimeManifestLocation activeRuntimeManifest();

}  // namespace sdfg::doctor
