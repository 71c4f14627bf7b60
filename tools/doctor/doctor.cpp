#include "doctor.h"

#include <openxr/openxr_reflection.h>

#include <cstring>
#include <memory>

#include "config_view.h"
#include "system.h"
#include "vulkan_check.h"

#ifndef SDFG_DOCTOR_DISABLE_ENV
#define SDFG_DOCTOR_DISABLE_ENV "DISABLE_XR_APILAYER_SDFG_AUTOGRASP"
#endif
#ifndef SDFG_DOCTOR_LAYER_VULKAN
#define SDFG_DOCTOR_LAYER_VULKAN 1
#endif

namespace sdfg::doctor {
namespace {

constexpr const char* kAutoGrasp = "XR_SDFG_auto_grasp";
constexpr const char* kHandTracking = "XR_EXT_hand_tracking";
constexpr const char* kVulkan2 = "XR_KHR_vulkan_enable2";
constexpr const char* kVulkan = "XR_KHR_vulkan_enable";
// A function only the layer provides: where it comes from says whether the layer is in the chain.
constexpr const char* kLayerFunction = "xrGetGraspStateSDFG";

#ifdef _WIN32
constexpr char kListSeparator = ';';
#else
constexpr char kListSeparator = ':';
#endif

const char* resultName(XrResult r) {
  switch (r) {
#define SDFG_DOCTOR_RESULT(name, value) \
  case name:                            \
    return #name;
    XR_LIST_ENUM_XrResult(SDFG_DOCTOR_RESULT)
#undef SDFG_DOCTOR_RESULT
        default : return "unknown XrResult";
  }
}

std::string failure(const char* call, XrResult r) {
  return std::string(call) + " failed: " + resultName(r);
}

std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> out;
  size_t start = 0;
  while (start <= text.size()) {
    const size_t end = std::min(text.find(kListSeparator, start), text.size());
    if (end > start) out.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  return out;
}

// The loader's global functions, from a loader opened at run time.
struct OpenXr {
  SharedLibrary library;
  PFN_xrGetInstanceProcAddr getProcAddr = nullptr;
  PFN_xrEnumerateApiLayerProperties enumerateLayers = nullptr;
  PFN_xrEnumerateInstanceExtensionProperties enumerateExtensions = nullptr;
  PFN_xrCreateInstance createInstance = nullptr;

  template <class F>
  F global(const char* name) const {
    PFN_xrVoidFunction f = nullptr;
    if (getProcAddr(XR_NULL_HANDLE, name, &f) != XR_SUCCESS) return nullptr;
    return reinterpret_cast<F>(f);
  }
};

bool openLoader(const Options& options, OpenXr& xr, Report& report) {
  const std::string name = options.loader.empty() ? openxrLoaderName() : options.loader;
  std::string error;
  xr.library = SharedLibrary::open(name, error);
  if (!xr.library.isOpen()) {
    report.loaderError = "cannot load " + name + ": " + error;
    return false;
  }
  xr.getProcAddr =
      reinterpret_cast<PFN_xrGetInstanceProcAddr>(xr.library.symbol("xrGetInstanceProcAddr"));
  if (xr.getProcAddr == nullptr) {
    report.loaderError = name + " exports no xrGetInstanceProcAddr";
    return false;
  }
  report.loaderPath = moduleFileOf(reinterpret_cast<const void*>(xr.getProcAddr));
  if (report.loaderPath.empty()) report.loaderPath = name;
  xr.enumerateLayers =
      xr.global<PFN_xrEnumerateApiLayerProperties>("xrEnumerateApiLayerProperties");
  xr.enumerateExtensions = xr.global<PFN_xrEnumerateInstanceExtensionProperties>(
      "xrEnumerateInstanceExtensionProperties");
  xr.createInstance = xr.global<PFN_xrCreateInstance>("xrCreateInstance");
  if (xr.enumerateLayers == nullptr || xr.enumerateExtensions == nullptr ||
      xr.createInstance == nullptr) {
    report.loaderError = name + " lacks a global function of OpenXR 1.0";
    return false;
  }
  return true;
}

// An XrInstance destroyed with this object.
class Instance {
 public:
  Instance(const OpenXr& xr, XrInstance handle) : xr_(xr), handle_(handle) {}
  ~Instance() {
    if (auto destroy = fn<PFN_xrDestroyInstance>("xrDestroyInstance")) destroy(handle_);
  }
  Instance(const Instance&) = delete;
  Instance& operator=(const Instance&) = delete;

  XrInstance get() const { return handle_; }
  template <class F>
  F fn(const char* name) const {
    PFN_xrVoidFunction f = nullptr;
    if (xr_.getProcAddr(handle_, name, &f) != XR_SUCCESS) return nullptr;
    return reinterpret_cast<F>(f);
  }

 private:
  const OpenXr& xr_;
  XrInstance handle_;
};

std::unique_ptr<Instance> createInstance(const OpenXr& xr, const std::vector<std::string>& exts,
                                         XrResult& result) {
  std::vector<const char*> names;
  for (const std::string& e : exts) names.push_back(e.c_str());
  XrInstanceCreateInfo info{XR_TYPE_INSTANCE_CREATE_INFO};
  std::strncpy(info.applicationInfo.applicationName, "autograsp-doctor",
               XR_MAX_APPLICATION_NAME_SIZE - 1);
  info.applicationInfo.applicationVersion = 1;
  info.applicationInfo.apiVersion = XR_MAKE_VERSION(1, 0, 0);
  info.enabledExtensionCount = uint32_t(names.size());
  info.enabledExtensionNames = names.data();
  XrInstance handle = XR_NULL_HANDLE;
  result = xr.createInstance(&info, &handle);
  if (XR_FAILED(result)) return nullptr;
  return std::make_unique<Instance>(xr, handle);
}

std::vector<Extension> listExtensions(const OpenXr& xr, const char* layer, std::string& error) {
  uint32_t count = 0;
  if (XrResult r = xr.enumerateExtensions(layer, 0, &count, nullptr); XR_FAILED(r)) {
    error = failure("xrEnumerateInstanceExtensionProperties", r);
    return {};
  }
  std::vector<XrExtensionProperties> props(count, {XR_TYPE_EXTENSION_PROPERTIES});
  if (XrResult r = xr.enumerateExtensions(layer, count, &count, props.data()); XR_FAILED(r)) {
    error = failure("xrEnumerateInstanceExtensionProperties", r);
    return {};
  }
  std::vector<Extension> out;
  for (uint32_t i = 0; i < count; ++i)
    out.push_back({props[i].extensionName, props[i].extensionVersion});
  return out;
}

// xrEnumerateApiLayerProperties, each marked implicit when an enabled implicit manifest names it.
std::vector<ApiLayer> listLayers(const OpenXr& xr, const std::vector<LayerManifest>& implicit) {
  std::vector<ApiLayer> out;
  uint32_t count = 0;
  if (XR_FAILED(xr.enumerateLayers(0, &count, nullptr))) return out;
  std::vector<XrApiLayerProperties> props(count, {XR_TYPE_API_LAYER_PROPERTIES});
  if (XR_FAILED(xr.enumerateLayers(count, &count, props.data()))) return out;
  for (uint32_t i = 0; i < count; ++i) {
    ApiLayer l{props[i].layerName, props[i].description, versionText(props[i].specVersion),
               props[i].layerVersion, false};
    for (const LayerManifest& m : implicit) l.implicit |= m.enabled() && m.name == l.name;
    out.push_back(l);
  }
  return out;
}

bool has(const std::vector<Extension>& list, const char* name) {
  for (const Extension& e : list)
    if (e.name == name) return true;
  return false;
}

// Sets variables for a scope and puts back what was there before.
class EnvironmentOverride {
 public:
  EnvironmentOverride() = default;
  EnvironmentOverride(const EnvironmentOverride&) = delete;
  EnvironmentOverride& operator=(const EnvironmentOverride&) = delete;
  ~EnvironmentOverride() {
    for (auto it = saved_.rbegin(); it != saved_.rend(); ++it) {
      if (it->second)
        setEnvironment(it->first, *it->second);
      else
        unsetEnvironment(it->first);
    }
  }
  void set(const std::string& name, const std::optional<std::string>& value) {
    saved_.emplace_back(name, environmentValue(name));
    if (value)
      setEnvironment(name, *value);
    else
      unsetEnvironment(name);
  }

 private:
  std::vector<std::pair<std::string, std::optional<std::string>>> saved_;
};

struct SystemView {
  XrSystemId id = XR_NULL_SYSTEM_ID;
  std::string error;
  std::string name;
  std::optional<bool> hands;  // set when XR_EXT_hand_tracking was enabled
};

SystemView headMountedSystem(const Instance& instance, bool handTracking) {
  SystemView view;
  auto getSystem = instance.fn<PFN_xrGetSystem>("xrGetSystem");
  auto getProps = instance.fn<PFN_xrGetSystemProperties>("xrGetSystemProperties");
  if (getSystem == nullptr || getProps == nullptr) {
    view.error = "no xrGetSystem";
    return view;
  }
  XrSystemGetInfo info{XR_TYPE_SYSTEM_GET_INFO};
  info.formFactor = XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY;
  if (XrResult r = getSystem(instance.get(), &info, &view.id); XR_FAILED(r)) {
    view.error = failure("xrGetSystem (head-mounted display)", r);
    view.id = XR_NULL_SYSTEM_ID;
    return view;
  }
  XrSystemHandTrackingPropertiesEXT hands{XR_TYPE_SYSTEM_HAND_TRACKING_PROPERTIES_EXT};
  XrSystemProperties props{XR_TYPE_SYSTEM_PROPERTIES};
  if (handTracking) props.next = &hands;
  if (XrResult r = getProps(instance.get(), view.id, &props); XR_FAILED(r)) {
    view.error = failure("xrGetSystemProperties", r);
    return view;
  }
  view.name = props.systemName;
  if (handTracking) view.hands = hands.supportsHandTracking == XR_TRUE;
  return view;
}

// The manifest of the layer the loader takes: the first it reads that enables it.
const LayerManifest* firstEnabled(const std::vector<LayerManifest>& manifests) {
  for (const LayerManifest& m : manifests)
    if (m.enabled()) return &m;
  return nullptr;
}

// Why the layer is not in the instance: the first of what the manifests, the environment and the
// instance's creation show wrong, in the order a user has to mend them.
void explainAbsence(Report& report) {
  const auto set = [&](const char* status, std::string reason) {
    report.status = status;
    report.reason = std::move(reason);
  };
  if (report.manifests.empty()) {
    std::string where;
    for (const std::string& s : report.implicitSearched) where += (where.empty() ? "" : ", ") + s;
    set("not_installed", std::string("no implicit API layer manifest names ") + kLayerName +
                             " (searched: " + where + ")");
    return;
  }
  const LayerManifest* usable = firstEnabled(report.manifests);
  if (usable == nullptr) {
    const LayerManifest& m = report.manifests.front();
    if (!m.problem.empty())
      set("broken_manifest", m.path + " " + m.problem + ", so the loader skips it");
    else if (!m.incompatibility.empty())
      set("incompatible", m.path + " " + m.incompatibility +
                              ", so the loader skips it: install the layer built for this loader");
    else if (m.disabledByEnvironment)
      set("disabled",
          m.disableEnvironment + " is set (its manifest's disable_environment): unset it");
    else if (m.missingEnableEnvironment)
      set("disabled", "its manifest's enable_environment " + m.enableEnvironment + " is not set");
    else
      set("disabled", "its registry value " + m.path + " is not 0 (the loader skips it)");
    return;
  }
  if (!usable->libraryResolved.empty() && !usable->libraryFound) {
    set("library_missing",
        usable->path + " names " + usable->libraryResolved + ", which does not exist");
    return;
  }
  const Negotiation& n = report.negotiation;
  if (n.ran && !n.opened) {
    set("library_unloadable",
        n.library + " cannot be loaded (" + n.openError + "), so the loader skips it");
    return;
  }
  if (n.ran && !n.hasFunction) {
    set("incompatible", n.library + " exports no " + n.function +
                            ": it is no OpenXR API layer library, so the loader skips it");
    return;
  }
  if (n.ran && !n.accepted()) {
    set("incompatible",
        n.library + " refuses the loader's negotiation (loader interface " +
            std::to_string(n.loaderMinInterface) + "-" + std::to_string(n.loaderMaxInterface) +
            ", OpenXR " + versionText(n.loaderMinApi) + "-" + versionText(n.loaderMaxApi) + ": " +
            (XR_FAILED(n.result) ? resultName(n.result) : "no xrGetInstanceProcAddr") +
            "): it was built for another loader interface; install the layer built for this "
            "loader");
    return;
  }
  if (!report.instanceError.empty()) {
    const bool noRuntime = !report.runtimeManifest.problem.empty() ||
                           report.instanceError.find("RUNTIME_UNAVAILABLE") != std::string::npos;
    set(noRuntime ? "no_runtime" : "no_instance",
        (noRuntime && !report.runtimeManifest.problem.empty()
             ? "no OpenXR runtime: " + report.runtimeManifest.problem +
                   (report.runtimeManifest.path.empty() ? ""
                                                        : " (" + report.runtimeManifest.path + ")")
             : report.instanceError) +
            "; the layer cannot be checked without an instance");
    return;
  }
  set("not_loaded",
      std::string("its manifest is enabled, but the instance has no ") + kLayerFunction +
          " of the layer (the loader did not load it" +
          (n.ran ? ", though its library negotiates loader interface " +
                       std::to_string(n.layerInterface) + " and OpenXR " + versionText(n.layerApi)
                 : std::string()) +
          ")");
}

void decideHands(Report& report, const std::optional<bool>& runtimeTracks,
                 const std::optional<bool>& supported, bool synthesis) {
  Report::Hands& h = report.hands;
  h.runtimeTracks = runtimeTracks;
  h.supported = supported;
  if (!h.offered) {
    h.source = "none";
    h.why = std::string("neither the runtime nor a layer offers ") + kHandTracking;
  } else if (!supported.has_value()) {
    h.source = "unknown";
    h.why = "no head-mounted system to ask";
  } else if (runtimeTracks.value_or(false)) {
    h.source = "runtime";
    h.why = report.live ? "the runtime tracks hands; the layer closes them onto what they grab"
                        : "the runtime tracks hands";
  } else if (*supported && report.live) {
    h.source = "layer";
    h.why = std::string("from the controllers' grip pose and squeeze, as ") +
            (h.runtimeOffers ? "the runtime's system reports no hand tracking"
                             : "the runtime offers no " + std::string(kHandTracking));
  } else {
    h.source = "none";
    h.why = !report.live
                ? "the runtime has no hands and the layer, which would synthesize them, is "
                  "not live"
            : !synthesis ? "the runtime has no hands and synthesis = off"
                         : "the system reports no hand tracking";
  }
}

void decideVulkan(Report& report, const layer::Config& config, const Instance* instance,
                  XrSystemId system, const OpenXr& xr) {
  Report::Vulkan& v = report.vulkan;
  if (!report.live) {
    v.path = "none";
    v.why = "the layer is not live";
    return;
  }
  if (v.extension.empty()) {
    v.path = "none";
    v.why = std::string("the runtime offers neither ") + kVulkan2 + " nor " + kVulkan +
            ": no Vulkan sessions (other sessions build on the CPU)";
    return;
  }
  const std::string gpuOrigin = originOf(report.config, "gpu");
  if (config.gpu == layer::Config::Gpu::off) {
    v.path = "cpu";
    v.why = "gpu = off (" + gpuOrigin + ")";
    return;
  }
  if (!SDFG_DOCTOR_LAYER_VULKAN) {
    v.path = "cpu";
    v.why = "this build of the layer has no Vulkan backend";
    return;
  }
  if (instance == nullptr || system == XR_NULL_SYSTEM_ID) {
    v.path = "unknown";
    v.why = "no head-mounted system to ask for its Vulkan device";
    return;
  }
  const RuntimeVulkanDevice device =
      runtimeVulkanDevice(instance->get(), system, xr.getProcAddr, v.extension == kVulkan2);
  if (!device.error.empty()) {
    v.path = "unknown";
    v.why = "the runtime's Vulkan device is unknown: " + device.error;
    return;
  }
  v.device = device.name;
  v.deviceType = deviceTypeName(device.type);
  const std::string on = "'" + v.device + "' (" + v.deviceType + ")";
  if (config.gpu == layer::Config::Gpu::on) {
    v.path = "device";
    v.why = "every target on " + on + ": gpu = on (" + gpuOrigin + ")";
  } else if (device.type == VK_PHYSICAL_DEVICE_TYPE_CPU) {
    v.path = "device_buffers_only";
    v.why = "targets given as arrays on the CPU, targets in the app's Vulkan buffers on " + on +
            ": with gpu = auto, array targets stay off a CPU implementation of Vulkan, which is "
            "slower than the CPU builder";
  } else {
    v.path = "device";
    v.why = "every target on " + on;
  }
}

}  // namespace

Report examine(const Options& options) {
  Report report;
  layer::Config config;
  report.config = describeConfig(config);
  report.runtimeManifest = readActiveRuntimeManifest();
  report.implicitLayers = findImplicitLayers(report.implicitSearched);
  for (const LayerManifest& m : report.implicitLayers) {
    const bool ours = m.problem.empty()
                          ? m.name == kLayerName
                          : m.path.find("XrApiLayer_sdfg_autograsp") != std::string::npos;
    if (ours) report.manifests.push_back(m);
  }
  report.disableEnvironment = SDFG_DOCTOR_DISABLE_ENV;
  for (const LayerManifest& m : report.manifests)
    if (!m.disableEnvironment.empty()) report.disableEnvironment = m.disableEnvironment;

  // The chain an app that enables no layer gets: the enabled implicit layers in the loader's
  // order, then XR_ENABLE_API_LAYERS.
  for (const LayerManifest& m : report.implicitLayers)
    if (m.enabled()) report.chain.push_back({m.name, "implicit", m.path});
  const std::string enabledByEnvironment = environmentValue("XR_ENABLE_API_LAYERS").value_or("");
  for (const std::string& name : splitList(enabledByEnvironment)) {
    bool present = false;
    for (const ChainEntry& e : report.chain) present |= e.name == name;
    if (!present) report.chain.push_back({name, "XR_ENABLE_API_LAYERS", ""});
  }
  bool inChain = false;
  for (const ChainEntry& e : report.chain) inChain |= e.name == kLayerName;

  OpenXr xr;
  if (!openLoader(options, xr, report)) {
    report.status = "no_loader";
    report.reason = "no OpenXR loader: " + report.loaderError;
    return report;
  }

  report.availableLayers = listLayers(xr, report.implicitLayers);
  bool available = false;
  for (const ApiLayer& l : report.availableLayers) available |= l.name == kLayerName;
  // Failures leave the lists empty; xrCreateInstance below says why.
  std::string ignored;
  if (available) report.layerExtensions = listExtensions(xr, kLayerName, ignored);
  const std::vector<Extension> all = listExtensions(xr, nullptr, ignored);

  // What is below the layer: the same enumeration with the layer switched off as a user would
  // switch it off, so its own XR_EXT_hand_tracking does not count as the runtime's.
  std::vector<Extension> below = all;
  std::optional<bool> runtimeTracks;
  if (inChain) {
    EnvironmentOverride without;
    without.set(report.disableEnvironment, "1");
    if (!enabledByEnvironment.empty()) {
      std::string rest;
      for (const std::string& name : splitList(enabledByEnvironment))
        if (name != kLayerName) rest += (rest.empty() ? "" : std::string(1, kListSeparator)) + name;
      without.set("XR_ENABLE_API_LAYERS", rest);
    }
    below = listExtensions(xr, nullptr, ignored);
    if (has(below, kHandTracking)) {
      XrResult r = XR_SUCCESS;
      if (auto runtimeOnly = createInstance(xr, {kHandTracking}, r))
        runtimeTracks = headMountedSystem(*runtimeOnly, true).hands;
    }
  }
  report.hands.offered = has(all, kHandTracking);
  report.hands.runtimeOffers = has(below, kHandTracking);
  // A runtime that does not offer the extension tracks no hands an app can read.
  if (!report.hands.runtimeOffers) runtimeTracks = false;

  std::vector<std::string> enable;
  if (has(all, kAutoGrasp)) enable.push_back(kAutoGrasp);
  if (report.hands.offered) enable.push_back(kHandTracking);
  if (has(all, kVulkan2))
    report.vulkan.extension = kVulkan2;
  else if (has(all, kVulkan))
    report.vulkan.extension = kVulkan;
  if (!report.vulkan.extension.empty()) enable.push_back(report.vulkan.extension);

  XrResult r = XR_SUCCESS;
  std::unique_ptr<Instance> instance = createInstance(xr, enable, r);
  SystemView system;
  if (instance == nullptr) {
    report.instanceError = failure("xrCreateInstance", r);
  } else {
    auto getProps = instance->fn<PFN_xrGetInstanceProperties>("xrGetInstanceProperties");
    XrInstanceProperties props{XR_TYPE_INSTANCE_PROPERTIES};
    if (getProps != nullptr && XR_SUCCEEDED(getProps(instance->get(), &props))) {
      report.runtimeName = props.runtimeName;
      report.runtimeVersion = versionText(props.runtimeVersion);
    }
    if (has(all, kAutoGrasp)) {
      PFN_xrVoidFunction f = nullptr;
      if (xr.getProcAddr(instance->get(), kLayerFunction, &f) == XR_SUCCESS && f != nullptr) {
        report.loaded = true;
        report.loadedFrom = moduleFileOf(reinterpret_cast<const void*>(f));
      }
    }
    system = headMountedSystem(*instance, report.hands.offered);
    report.systemName = system.name;
    report.systemError = system.error;
    if (!inChain && report.hands.runtimeOffers) runtimeTracks = system.hands;
  }

  // Left out by the loader although a manifest enables it: ask the library what the loader got.
  // Asked also when xrCreateInstance failed: a loader that loads no layer at all fails the call
  // with the layer's own error.
  if (const LayerManifest* m = firstEnabled(report.manifests);
      !report.loaded && m != nullptr && (m->libraryResolved.empty() || m->libraryFound))
    report.negotiation =
        negotiateWithLayer(m->libraryResolved.empty() ? m->library : m->libraryResolved, kLayerName,
                           m->negotiateFunction);

  if (report.loaded) {
    report.live = true;
    report.status = "live";
    report.reason = std::string(kLayerName) + " is in every app's instance" +
                    (report.loadedFrom.empty() ? "" : " (" + report.loadedFrom + ")");
  } else {
    explainAbsence(report);
  }
  decideHands(report, runtimeTracks, system.error.empty() ? system.hands : std::nullopt,
              config.synthesis);
  decideVulkan(report, config, instance.get(), system.id, xr);
  return report;
}

}  // namespace sdfg::doctor
