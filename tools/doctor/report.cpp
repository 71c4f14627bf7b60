#include "report.h"

#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>

namespace sdfg::doctor {
namespace {

using Json = nlohmann::ordered_json;

Json optionalBool(const std::optional<bool>& v) {
  return v ? Json(*v) : Json(nullptr);
}

Json textOrNull(const std::string& s) {
  return s.empty() ? Json(nullptr) : Json(s);
}

Json manifestJson(const LayerManifest& m) {
  return Json{{"path", m.path},
              {"origin", m.origin},
              {"problem", textOrNull(m.problem)},
              {"incompatibility", textOrNull(m.incompatibility)},
              {"name", textOrNull(m.name)},
              {"library_path", textOrNull(m.library)},
              {"library", textOrNull(m.libraryResolved)},
              {"library_found", m.libraryResolved.empty() ? Json(nullptr) : Json(m.libraryFound)},
              {"disable_environment", textOrNull(m.disableEnvironment)},
              {"disabled_by_environment", m.disabledByEnvironment},
              {"enable_environment", textOrNull(m.enableEnvironment)},
              {"missing_enable_environment", m.missingEnableEnvironment},
              {"disabled_in_registry", m.disabledInRegistry},
              {"enabled", m.enabled()}};
}

// The library's answer to the loader's negotiation; null when it was not asked.
Json negotiationJson(const Negotiation& n) {
  if (!n.ran) return nullptr;
  return Json{{"library", n.library},
              {"function", n.function},
              {"opened", n.opened},
              {"open_error", textOrNull(n.openError)},
              {"has_function", n.hasFunction},
              {"accepted", n.accepted()},
              {"loader_interface", {n.loaderMinInterface, n.loaderMaxInterface}},
              {"loader_api", {versionText(n.loaderMinApi), versionText(n.loaderMaxApi)}},
              {"layer_interface", n.accepted() ? Json(n.layerInterface) : Json(nullptr)},
              {"layer_api", n.accepted() ? Json(versionText(n.layerApi)) : Json(nullptr)}};
}

const char* vulkanPathText(const std::string& path) {
  if (path == "device") return "grab-box SDFs on the app's Vulkan device";
  if (path == "device_buffers_only") return "grab-box SDFs partly on the app's Vulkan device";
  if (path == "cpu") return "grab-box SDFs on the CPU";
  if (path == "none") return "none";
  return "unknown";
}

const char* handsText(const std::string& source) {
  if (source == "runtime") return "tracked by the runtime";
  if (source == "layer") return "synthesized by the layer";
  if (source == "none") return "none";
  return "unknown";
}

const char* yesNo(const std::optional<bool>& v) {
  return !v ? "unknown" : *v ? "yes" : "no";
}

// "label" padded to the column the values start at.
std::string label(const std::string& text) {
  constexpr size_t kColumn = 17;
  return text.size() >= kColumn ? text + " " : text + std::string(kColumn - text.size(), ' ');
}

}  // namespace

std::string reportText(const Report& report) {
  std::ostringstream out;
  out << "autograsp-doctor: " << kLayerName << (report.live ? " is live" : " is NOT live") << "\n";
  out << "  " << report.reason << "\n\n";

  out << label("OpenXR loader")
      << (report.loaderPath.empty() ? report.loaderError : report.loaderPath) << "\n";
  if (report.loaderPath.empty()) return out.str();

  const RuntimeManifest& rm = report.runtimeManifest;
  out << label("Active runtime");
  if (!report.runtimeName.empty())
    out << report.runtimeName << " " << report.runtimeVersion << "\n";
  else if (!rm.problem.empty())
    out << "none: " << rm.problem << "\n";
  else
    out << "unknown: " << report.instanceError << "\n";
  if (!rm.path.empty()) {
    out << label("  manifest") << rm.path << " (" << rm.origin << ")";
    if (!rm.problem.empty()) out << ": " << rm.problem;
    out << "\n";
  } else {
    out << label("  manifest") << "none found; searched:";
    for (const std::string& s : rm.searched) out << " " << s;
    out << "\n";
  }
  if (!report.runtimeName.empty()) {
    out << label("System")
        << (report.systemError.empty() ? report.systemName + " (head-mounted display)"
                                       : report.systemError)
        << "\n";
  }

  out << "\nAPI layers an app gets when it enables none, app side first:\n";
  if (report.chain.empty()) out << "  (none)\n";
  for (size_t i = 0; i < report.chain.size(); ++i) {
    const ChainEntry& e = report.chain[i];
    out << "  " << i + 1 << ". " << e.name << "  (" << e.how
        << (e.manifest.empty() ? "" : ", " + e.manifest) << ")\n";
  }
  out << "  then the layers the app enables, then the runtime\n";
  out << "API layers available (xrEnumerateApiLayerProperties):\n";
  if (report.availableLayers.empty()) out << "  (none)\n";
  for (const ApiLayer& l : report.availableLayers)
    out << "  " << l.name << "  (" << (l.implicit ? "implicit" : "explicit") << ", API "
        << l.specVersion << ", version " << l.layerVersion << ")\n";

  out << "\n" << label("This layer") << kLayerName << ": " << report.status;
  if (report.loaded) out << ", loaded from " << report.loadedFrom;
  out << "\n";
  if (report.manifests.empty())
    out << label("  manifest") << "none in the implicit layer folders\n";
  for (const LayerManifest& m : report.manifests) {
    out << label("  manifest") << m.path << " (" << m.origin << ")";
    if (!m.problem.empty()) out << ": " << m.problem;
    if (!m.incompatibility.empty()) out << ": " << m.incompatibility;
    out << "\n";
    if (!m.libraryResolved.empty())
      out << label("  library") << m.libraryResolved << (m.libraryFound ? "" : " (MISSING)")
          << "\n";
    else if (!m.library.empty())
      out << label("  library") << m.library << " (found by the system's library search)\n";
  }
  if (const Negotiation& n = report.negotiation; n.ran) {
    out << label("  negotiation");
    if (!n.opened)
      out << "the library cannot be loaded: " << n.openError << "\n";
    else if (!n.hasFunction)
      out << "the library exports no " << n.function << "\n";
    else if (!n.accepted())
      out << "refused: loader interface " << n.loaderMinInterface << "-" << n.loaderMaxInterface
          << ", OpenXR " << versionText(n.loaderMinApi) << "-" << versionText(n.loaderMaxApi)
          << "\n";
    else
      out << "accepted: loader interface " << n.layerInterface << ", OpenXR "
          << versionText(n.layerApi) << "\n";
  }
  out << label("  switch") << report.disableEnvironment;
  bool disabled = false;
  for (const LayerManifest& m : report.manifests) disabled |= m.disabledByEnvironment;
  out << (disabled ? " is set: the layer is off" : " is not set") << "\n";
  if (!report.layerExtensions.empty()) {
    out << label("  extensions");
    for (size_t i = 0; i < report.layerExtensions.size(); ++i)
      out << (i ? ", " : "") << report.layerExtensions[i].name << " v"
          << report.layerExtensions[i].version;
    out << "\n";
  }

  const Report::Hands& h = report.hands;
  out << "\n" << label("Hands") << handsText(h.source) << ": " << h.why << "\n";
  out << label("  ") << "XR_EXT_hand_tracking offered: " << (h.offered ? "yes" : "no")
      << "; below the layer: " << (h.runtimeOffers ? "yes" : "no")
      << "; runtime's system tracks hands: " << yesNo(h.runtimeTracks)
      << "; apps are told supportsHandTracking: " << yesNo(h.supported) << "\n";

  const Report::Vulkan& v = report.vulkan;
  out << label("Vulkan session") << vulkanPathText(v.path) << ": " << v.why << "\n";
  if (!v.extension.empty()) out << label("  ") << "through " << v.extension << "\n";

  const Report::Config& c = report.config;
  out << "\n"
      << label("Configuration") << (c.file.empty() ? "(no user folder)" : c.file)
      << (c.fileExists ? "" : " (absent: built-in defaults and SDFG_AUTOGRASP_* variables)")
      << "\n";
  for (const Setting& s : c.values) {
    out << "  " << s.key << " = " << s.text;
    if (s.origin != "default") out << "  (" << s.origin << ")";
    out << "\n";
  }
  for (const IgnoredSetting& i : c.ignored)
    out << "  ignored by the layer: " << i.where << ": '" << i.key << " = " << i.value
        << "' (unknown key or bad value)\n";
  return out.str();
}

std::string reportJson(const Report& report) {
  Json json;
  json["live"] = report.live;
  json["status"] = report.status;
  json["reason"] = report.reason;
  json["loader"] = {{"path", textOrNull(report.loaderPath)},
                    {"error", textOrNull(report.loaderError)}};
  const RuntimeManifest& rm = report.runtimeManifest;
  json["runtime"] = {{"name", textOrNull(report.runtimeName)},
                     {"version", textOrNull(report.runtimeVersion)},
                     {"manifest", textOrNull(rm.path)},
                     {"manifest_origin", textOrNull(rm.origin)},
                     {"manifest_problem", textOrNull(rm.problem)},
                     {"manifest_name", textOrNull(rm.name)},
                     {"library", textOrNull(rm.library)},
                     {"searched", rm.searched},
                     {"instance_error", textOrNull(report.instanceError)}};
  json["system"] = {{"name", textOrNull(report.systemName)},
                    {"error", textOrNull(report.systemError)}};

  Json chain = Json::array();
  for (const ChainEntry& e : report.chain)
    chain.push_back({{"name", e.name}, {"how", e.how}, {"manifest", textOrNull(e.manifest)}});
  Json available = Json::array();
  for (const ApiLayer& l : report.availableLayers)
    available.push_back({{"name", l.name},
                         {"description", l.description},
                         {"spec_version", l.specVersion},
                         {"layer_version", l.layerVersion},
                         {"implicit", l.implicit}});
  Json implicit = Json::array();
  for (const LayerManifest& m : report.implicitLayers) implicit.push_back(manifestJson(m));
  json["api_layers"] = {{"chain", chain},
                        {"available", available},
                        {"implicit_manifests", implicit},
                        {"implicit_searched", report.implicitSearched}};

  Json manifests = Json::array();
  for (const LayerManifest& m : report.manifests) manifests.push_back(manifestJson(m));
  Json extensions = Json::array();
  for (const Extension& e : report.layerExtensions)
    extensions.push_back({{"name", e.name}, {"version", e.version}});
  bool disabled = false;
  for (const LayerManifest& m : report.manifests) disabled |= m.disabledByEnvironment;
  json["layer"] = {{"name", kLayerName},
                   {"loaded", report.loaded},
                   {"library", textOrNull(report.loadedFrom)},
                   {"disable_environment", report.disableEnvironment},
                   {"disabled_by_environment", disabled},
                   {"manifests", manifests},
                   {"negotiation", negotiationJson(report.negotiation)},
                   {"extensions", extensions}};

  const Report::Hands& h = report.hands;
  json["hands"] = {{"source", h.source},
                   {"why", h.why},
                   {"offered", h.offered},
                   {"runtime_offers", h.runtimeOffers},
                   {"runtime_tracks", optionalBool(h.runtimeTracks)},
                   {"supported", optionalBool(h.supported)}};
  const Report::Vulkan& v = report.vulkan;
  json["vulkan"] = {{"path", v.path},
                    {"why", v.why},
                    {"extension", textOrNull(v.extension)},
                    {"device", textOrNull(v.device)},
                    {"device_type", textOrNull(v.deviceType)}};

  const Report::Config& c = report.config;
  Json values = Json::object();
  for (const Setting& s : c.values) {
    // Whole numbers (resolution, build_time_limit_ms) as integers, as the file writes them.
    const bool whole = s.number == std::floor(s.number) && std::fabs(s.number) < 1e15;
    Json value = s.kind == Setting::Kind::number
                     ? (whole ? Json(int64_t(s.number)) : Json(s.number))
                 : s.kind == Setting::Kind::boolean ? Json(s.boolean)
                                                    : Json(s.text);
    values[s.key] = {{"value", value}, {"origin", s.origin}};
  }
  Json ignored = Json::array();
  for (const IgnoredSetting& i : c.ignored)
    ignored.push_back({{"where", i.where}, {"key", i.key}, {"value", i.value}});
  json["config"] = {{"file", textOrNull(c.file)},
                    {"file_exists", c.fileExists},
                    {"values", values},
                    {"ignored", ignored}};
  return json.dump(2) + "\n";
}

}  // namespace sdfg::doctor
