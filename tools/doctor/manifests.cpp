#include "manifests.h"

#include <openxr/openxr.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

namespace sdfg::doctor {
namespace {

namespace fs = std::filesystem;

// Reads a JSON file; on failure returns null and says why.
nlohmann::json readJson(const std::string& path, std::string& problem) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    problem = "cannot be read";
    return nullptr;
  }
  nlohmann::json json = nlohmann::json::parse(in, nullptr, false);
  if (json.is_discarded() || !json.is_object()) {
    problem = "is not a JSON object";
    return nullptr;
  }
  if (!json.contains("file_format_version") || !json["file_format_version"].is_string()) {
    problem = "has no file_format_version";
    return nullptr;
  }
  return json;
}

std::string stringField(const nlohmann::json& object, const char* key) {
  const auto it = object.find(key);
  return it != object.end() && it->is_string() ? it->get<std::string>() : std::string();
}

bool hasStringField(const nlohmann::json& object, const char* key) {
  const auto it = object.find(key);
  return it != object.end() && it->is_string();
}

// A library_path with a folder separator is a path, relative ones against the folder of the
// manifest's real file (symbolic links followed); a bare file name is left to the system's search.
void resolveLibrary(const std::string& manifest, const std::string& library, std::string& resolved,
                    bool& found) {
  resolved.clear();
  found = false;
  if (library.find('/') == std::string::npos && library.find('\\') == std::string::npos) return;
  std::error_code ec;
  fs::path path = fs::path(library);
  if (!path.is_absolute()) {
    fs::path real = fs::canonical(manifest, ec);
    if (ec) real = fs::absolute(manifest, ec);
    path = real.parent_path() / path;
  }
  fs::path normal = fs::weakly_canonical(path, ec);
  resolved = (ec ? path.lexically_normal() : normal).string();
  found = fs::exists(resolved, ec);
}

LayerManifest readLayer(const ManifestSource& source, const std::string& path) {
  LayerManifest m;
  m.path = path;
  m.origin = source.origin;
  m.disabledInRegistry = source.registryDisabled;
  const nlohmann::json json = readJson(path, m.problem);
  if (!m.problem.empty()) return m;
  const auto layer = json.find("api_layer");
  if (layer == json.end() || !layer->is_object()) {
    m.problem = "has no api_layer object";
    return m;
  }
  for (const char* key : {"name", "api_version", "library_path", "implementation_version"}) {
    if (!hasStringField(*layer, key)) {
      m.problem = std::string("lacks the string field api_layer.") + key;
      return m;
    }
  }
  m.name = stringField(*layer, "name");
  // The loader's two version checks (manifest_file.cpp): it reads file format 1.0.0 only, and
  // api_version "major.minor" up to its own major version.
  const std::string format = stringField(json, "file_format_version");
  unsigned fmt[3] = {0, 0, 0};
  if (std::sscanf(format.c_str(), "%u.%u.%u", &fmt[0], &fmt[1], &fmt[2]) != 3 || fmt[0] != 1 ||
      fmt[1] != 0 || fmt[2] != 0)
    m.incompatibility = "has file_format_version " + format +
                        ", which this loader does not read (it reads 1.0.0 only)";
  const std::string api = stringField(*layer, "api_version");
  unsigned major = 0, minor = 0;
  if (std::sscanf(api.c_str(), "%u.%u", &major, &minor) != 2 || (major == 0 && minor == 0)) {
    m.problem = "has api_version '" + api + "', not major.minor";
    return m;
  }
  if (m.incompatibility.empty() && major > XR_VERSION_MAJOR(XR_CURRENT_API_VERSION))
    m.incompatibility = "has api_version " + api + ", for OpenXR " + std::to_string(major) +
                        ", newer than this loader's OpenXR " +
                        std::to_string(XR_VERSION_MAJOR(XR_CURRENT_API_VERSION));
  if (const auto functions = layer->find("functions");
      functions != layer->end() && functions->is_object()) {
    const std::string renamed = stringField(*functions, "xrNegotiateLoaderApiLayerInterface");
    if (!renamed.empty()) m.negotiateFunction = renamed;
  }
  m.library = stringField(*layer, "library_path");
  resolveLibrary(path, m.library, m.libraryResolved, m.libraryFound);
  if (!hasStringField(*layer, "disable_environment")) {
    m.problem = "lacks disable_environment, which an implicit layer must have";
    return m;
  }
  m.disableEnvironment = stringField(*layer, "disable_environment");
  m.disabledByEnvironment = environmentValue(m.disableEnvironment).has_value();
  m.enableEnvironment = stringField(*layer, "enable_environment");
  m.missingEnableEnvironment =
      !m.enableEnvironment.empty() && !environmentValue(m.enableEnvironment).has_value();
  return m;
}

}  // namespace

std::vector<LayerManifest> findImplicitLayers(std::vector<std::string>& searched) {
  std::vector<LayerManifest> found;
  for (const ManifestSource& source : implicitLayerSources()) {
    searched.push_back(source.path);
    if (!source.folder) {
      found.push_back(readLayer(source, source.path));
      continue;
    }
    // Directory order, as the loader reads it (it does not sort either).
    std::error_code ec;
    for (fs::directory_iterator it(source.path, ec), end; !ec && it != end; it.increment(ec)) {
      const fs::path& file = it->path();
      if (file.extension() == ".json" && it->is_regular_file(ec))
        found.push_back(readLayer(source, file.string()));
    }
  }
  return found;
}

RuntimeManifest readActiveRuntimeManifest() {
  RuntimeManifest m;
  const RuntimeManifestLocation location = activeRuntimeManifest();
  m.path = location.path;
  m.origin = location.origin;
  m.searched = location.searched;
  if (m.path.empty()) {
    m.problem = "no active runtime manifest";
    return m;
  }
  const nlohmann::json json = readJson(m.path, m.problem);
  if (!m.problem.empty()) return m;
  const auto runtime = json.find("runtime");
  if (runtime == json.end() || !runtime->is_object() || !hasStringField(*runtime, "library_path")) {
    m.problem = "has no runtime.library_path";
    return m;
  }
  m.name = stringField(*runtime, "name");
  bool found = false;
  resolveLibrary(m.path, stringField(*runtime, "library_path"), m.library, found);
  if (m.library.empty()) m.library = stringField(*runtime, "library_path");
  return m;
}

}  // namespace sdfg::doctor
