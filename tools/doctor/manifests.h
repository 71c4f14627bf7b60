// The OpenXR manifests autograsp-doctor reads, with the rules the Khronos loader applies to
// them: implicit API layer manifests (name, library, disable_environment and enable_environment,
// in the loader's search order) and the active runtime's manifest.
#pragma once

#include <string>
#include <vector>

#include "system.h"

namespace sdfg::doctor {

struct LayerManifest {
  std::string path;     // the manifest file
  std::string origin;   // why the loader reads it (ManifestSource::origin)
  std::string problem;  // why the loader would skip it as malformed; empty when it is well formed
  // Why the loader would skip it as made for another loader (file_format_version other than
  // 1.0.0, api_version of a newer OpenXR major version); empty when this loader reads it.
  std::string incompatibility;
  std::string name;
  std::string library;          // library_path as written
  std::string libraryResolved;  // with a relative path resolved against the manifest's folder
  bool libraryFound = false;    // libraryResolved exists (a bare file name: left to the system)
  std::string disableEnvironment;
  bool disabledByEnvironment = false;  // disable_environment is set (to anything, even "")
  std::string enableEnvironment;       // optional: the layer is on only while this is set
  bool missingEnableEnvironment = false;
  bool disabledInRegistry = false;  // Windows: the registry value's data is not 0
  // The library's negotiation function, as the manifest's "functions" object may rename it.
  std::string negotiateFunction = "xrNegotiateLoaderApiLayerInterface";

  // Whether the loader puts it in every instance's chain.
  bool enabled() const {
    return problem.empty() && incompatibility.empty() && !disabledByEnvironment &&
           !missingEnableEnvironment && !disabledInRegistry;
  }
};

// Every implicit layer manifest the loader would read, in its order. `searched` receives the
// folders (or registry values) looked at.
std::vector<LayerManifest> findImplicitLayers(std::vector<std::string>& searched);

struct RuntimeManifest {
  std::string path;
  std::string origin;
  std::vector<std::string> searched;
  std::string problem;  // not found, unreadable, or malformed
  std::string name;     // runtime.name, optional in the format
  std::string library;  // runtime.library_path, resolved like a layer's
};
RuntimeManifest readActiveRuntimeManifest();

}  // namespace sdfg::doctor
