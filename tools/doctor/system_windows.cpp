// system.h for Windows: LoadLibrary, the process environment, and the registry keys the Khronos
// loader reads (HKLM, then HKCU, \SOFTWARE\Khronos\OpenXR\1).
#ifndef WIN32_LEAN_AND_MEAN
#define WIN32_LEAN_AND_MEAN
#endif
#include <windows.h>

#include <cstdlib>

#include "system.h"

namespace sdfg::doctor {
namespace {

constexpr const char* kOpenXrKey = "SOFTWARE\\Khronos\\OpenXR\\1";

std::string lastErrorText(DWORD code) {
  char* text = nullptr;
  const DWORD n = FormatMessageA(
      FORMAT_MESSAGE_ALLOCATE_BUFFER | FORMAT_MESSAGE_FROM_SYSTEM | FORMAT_MESSAGE_IGNORE_INSERTS,
      nullptr, code, 0, reinterpret_cast<char*>(&text), 0, nullptr);
  std::string out =
      n > 0 && text != nullptr ? std::string(text, n) : "error " + std::to_string(code);
  if (text != nullptr) LocalFree(text);
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  return out;
}

// Every value of `key` under `hive`: (value name, DWORD data). The loader reads the implicit
// layers this way: the name is the manifest's path, data 0 means enabled.
void readLayerValues(HKEY hive, const char* hiveName, const std::string& key,
                     std::vector<ManifestSource>& out) {
  HKEY handle = nullptr;
  if (RegOpenKeyExA(hive, key.c_str(), 0, KEY_QUERY_VALUE, &handle) != ERROR_SUCCESS) return;
  for (DWORD index = 0;; ++index) {
    char name[1024];
    DWORD nameSize = sizeof name;
    DWORD type = 0;
    DWORD data = 0;
    DWORD dataSize = sizeof data;
    const LONG r = RegEnumValueA(handle, index, name, &nameSize, nullptr, &type,
                                 reinterpret_cast<BYTE*>(&data), &dataSize);
    if (r == ERROR_NO_MORE_ITEMS) break;
    if (r != ERROR_SUCCESS && r != ERROR_MORE_DATA) continue;
    const bool enabled = type == REG_DWORD && dataSize == sizeof data && data == 0;
    out.push_back(
        {std::string(name, nameSize), std::string(hiveName) + " registry", false, !enabled});
  }
  RegCloseKey(handle);
}

// The loader's rule (IsHighIntegrityLevel): above medium integrity (an elevated process, and
// every process under Wine) it ignores XR_RUNTIME_JSON and the HKCU layers, which a process of
// lower integrity could have set.
bool highIntegrity() {
  HANDLE token = nullptr;
  if (!OpenProcessToken(GetCurrentProcess(), TOKEN_QUERY, &token)) return false;
  alignas(TOKEN_MANDATORY_LABEL)
      BYTE buffer[SECURITY_MAX_SID_SIZE + sizeof(TOKEN_MANDATORY_LABEL)]{};
  DWORD size = 0;
  bool high = false;
  if (GetTokenInformation(token, TokenIntegrityLevel, buffer, sizeof buffer, &size)) {
    const auto* label = reinterpret_cast<const TOKEN_MANDATORY_LABEL*>(buffer);
    if (label->Label.Sid != nullptr) {
      const DWORD count = *GetSidSubAuthorityCount(label->Label.Sid);
      high = *GetSidSubAuthority(label->Label.Sid, count - 1) > SECURITY_MANDATORY_MEDIUM_RID;
    }
  }
  CloseHandle(token);
  return high;
}

}  // namespace

SharedLibrary::~SharedLibrary() {
  if (handle_ != nullptr) FreeLibrary(static_cast<HMODULE>(handle_));
}

SharedLibrary::SharedLibrary(SharedLibrary&& other) noexcept : handle_(other.handle_) {
  other.handle_ = nullptr;
}

SharedLibrary& SharedLibrary::operator=(SharedLibrary&& other) noexcept {
  if (this != &other) {
    if (handle_ != nullptr) FreeLibrary(static_cast<HMODULE>(handle_));
    handle_ = other.handle_;
    other.handle_ = nullptr;
  }
  return *this;
}

SharedLibrary SharedLibrary::open(const std::string& name, std::string& error) {
  SharedLibrary library;
  library.handle_ = LoadLibraryA(name.c_str());
  if (library.handle_ == nullptr) error = lastErrorText(GetLastError());
  return library;
}

void* SharedLibrary::symbol(const char* name) const {
  if (handle_ == nullptr) return nullptr;
  return reinterpret_cast<void*>(GetProcAddress(static_cast<HMODULE>(handle_), name));
}

std::string moduleFileOf(const void* address) {
  HMODULE module = nullptr;
  if (address == nullptr || !GetModuleHandleExA(GET_MODULE_HANDLE_EX_FLAG_FROM_ADDRESS |
                                                    GET_MODULE_HANDLE_EX_FLAG_UNCHANGED_REFCOUNT,
                                                static_cast<const char*>(address), &module))
    return {};
  char path[MAX_PATH * 4];
  const DWORD n = GetModuleFileNameA(module, path, sizeof path);
  return n > 0 && n < sizeof path ? std::string(path, n) : std::string();
}

const char* openxrLoaderName() {
  return "openxr_loader.dll";
}

const char* vulkanLoaderName() {
  return "vulkan-1.dll";
}

std::optional<std::string> environmentValue(const std::string& name) {
  // The loader reads the process environment (GetEnvironmentVariable), where a variable can be
  // set to the empty string.
  SetLastError(ERROR_SUCCESS);
  const DWORD size = GetEnvironmentVariableA(name.c_str(), nullptr, 0);
  if (size == 0) {
    if (GetLastError() == ERROR_ENVVAR_NOT_FOUND) return std::nullopt;
    return std::string();
  }
  std::string value(size, '\0');
  const DWORD n = GetEnvironmentVariableA(name.c_str(), value.data(), size);
  value.resize(n);
  return value;
}

void setEnvironment(const std::string& name, const std::string& value) {
  // Both copies: the C runtime's (std::getenv, which the layer's configuration reads) and the
  // process environment (which the loader reads). _putenv_s updates both, but would remove a
  // variable set to the empty string.
  _putenv_s(name.c_str(), value.c_str());
  SetEnvironmentVariableA(name.c_str(), value.c_str());
}

void unsetEnvironment(const std::string& name) {
  _putenv_s(name.c_str(), "");
  SetEnvironmentVariableA(name.c_str(), nullptr);
}

std::vector<std::string> environmentNamesWithPrefix(const std::string& prefix) {
  std::vector<std::string> names;
  char* block = GetEnvironmentStringsA();
  if (block == nullptr) return names;
  for (const char* entry = block; *entry != '\0';
       entry += std::char_traits<char>::length(entry) + 1) {
    const std::string text = entry;
    if (text.rfind(prefix, 0) == 0) names.push_back(text.substr(0, text.find('=')));
  }
  FreeEnvironmentStringsA(block);
  return names;
}

std::vector<ManifestSource> implicitLayerSources() {
  // HKLM first, then HKCU unless the process has high integrity (as the loader would run in it).
  std::vector<ManifestSource> sources;
  const std::string key = std::string(kOpenXrKey) + "\\ApiLayers\\Implicit";
  readLayerValues(HKEY_LOCAL_MACHINE, "HKLM", key, sources);
  if (!highIntegrity()) readLayerValues(HKEY_CURRENT_USER, "HKCU", key, sources);
  return sources;
}

RuntimeManifestLocation activeRuntimeManifest() {
  RuntimeManifestLocation found;
  const auto path = environmentValue("XR_RUNTIME_JSON");
  if (path && !path->empty() && !highIntegrity()) {
    found.path = *path;
    found.origin = "XR_RUNTIME_JSON";
    found.searched.push_back(*path);
    return found;
  }
  found.searched.push_back(std::string("HKLM\\") + kOpenXrKey + " ActiveRuntime");
  char value[MAX_PATH * 4];
  DWORD size = sizeof value;
  if (RegGetValueA(HKEY_LOCAL_MACHINE, kOpenXrKey, "ActiveRuntime", RRF_RT_REG_SZ, nullptr, value,
                   &size) == ERROR_SUCCESS) {
    found.path = value;
    found.origin = "HKLM registry, ActiveRuntime";
  }
  return found;
}

}  // namespace sdfg::doctor
