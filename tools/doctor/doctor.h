// autograsp-doctor's examination: is the SDF Autograsp layer live for the apps of this user, and
// if not, why not. It goes through the real Khronos loader as an app does (an instance with the
// layer's extension), and reads what the loader reads (the active runtime's and the implicit
// layers' manifests, their environment switches) to name the cause of what it sees. The result is
// a Report; report.h prints it for people or as JSON.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "manifests.h"
#include "negotiation.h"

namespace sdfg::doctor {

inline constexpr const char* kLayerName = "XR_APILAYER_SDFG_autograsp";

struct Options {
  std::string loader;  // the OpenXR loader to use; empty: the system's, as apps load it
};

// One extension as the loader lists it.
struct Extension {
  std::string name;
  uint32_t version = 0;
};

// An API layer as xrEnumerateApiLayerProperties lists it.
struct ApiLayer {
  std::string name;
  std::string description;
  std::string specVersion;
  uint32_t layerVersion = 0;
  bool implicit = false;  // found among the implicit manifests (the others are explicit)
};

// A layer in the chain an app gets when it enables no layer itself, app side first.
struct ChainEntry {
  std::string name;
  std::string how;  // "implicit" or "XR_ENABLE_API_LAYERS"
  std::string manifest;
};

// One setting of the layer's configuration, with where its value came from.
struct Setting {
  std::string key;
  std::string text;  // as the configuration file writes it
  enum class Kind { text, number, boolean } kind = Kind::text;
  double number = 0;
  bool boolean = false;
  std::string origin;  // "default", "file" or "environment"
};

// An entry of the configuration file or environment that the layer ignores.
struct IgnoredSetting {
  std::string where;  // "<file>:<line>" or the variable's name
  std::string key;
  std::string value;
};

struct Report {
  // The verdict. status: live, disabled, not_installed, broken_manifest, incompatible,
  // library_missing, library_unloadable, not_loaded, no_runtime, no_instance, no_loader.
  bool live = false;
  std::string status;
  std::string reason;

  std::string loaderPath;  // the OpenXR loader that was used
  std::string loaderError;

  RuntimeManifest runtimeManifest;
  std::string instanceError;  // why xrCreateInstance failed; empty when it succeeded
  std::string runtimeName;
  std::string runtimeVersion;
  std::string systemName;   // the head-mounted system's name
  std::string systemError;  // why xrGetSystem failed

  std::vector<std::string> implicitSearched;  // folders (or registry values) searched
  std::vector<LayerManifest>
      implicitLayers;                     // every implicit manifest found, in the loader's order
  std::vector<ApiLayer> availableLayers;  // xrEnumerateApiLayerProperties
  std::vector<ChainEntry> chain;

  // This layer.
  std::vector<LayerManifest> manifests;  // the implicit manifests naming it
  bool loaded = false;                   // its functions are in the instance
  std::string loadedFrom;                // the library they come from
  std::vector<Extension> layerExtensions;
  std::string disableEnvironment;
  // The library's own answer to the loader's negotiation, asked when the loader left it out.
  Negotiation negotiation;

  struct Hands {
    bool offered = false;               // XR_EXT_hand_tracking is offered to apps
    bool runtimeOffers = false;         // ... by what is below this layer
    std::optional<bool> runtimeTracks;  // the runtime's system supports hand tracking
    std::optional<bool> supported;      // what an app is told, with the layer in place
    std::string source;                 // runtime, layer, none, unknown
    std::string why;
  } hands;

  struct Vulkan {
    std::string extension;  // XR_KHR_vulkan_enable2, XR_KHR_vulkan_enable, or empty
    std::string path;       // device, device_buffers_only, cpu, none, unknown
    std::string why;
    std::string device;
    std::string deviceType;
  } vulkan;

  struct Config {
    std::string file;  // the file the layer reads
    bool fileExists = false;
    std::vector<Setting> values;
    std::vector<IgnoredSetting> ignored;
  } config;
};

Report examine(const Options& options);

}  // namespace sdfg::doctor
