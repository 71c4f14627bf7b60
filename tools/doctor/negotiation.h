// Why a layer library the loader found did not end up in the instance: autograsp-doctor opens
// the library and negotiates with it as the Khronos loader does (xrNegotiateLoaderApiLayerInterface
// with loader interface version 1 and OpenXR 1.x), so that a library that cannot be loaded (a
// missing dependency, not a shared library), that is no OpenXR API layer, or that was built for
// another loader interface is named as such instead of "the loader did not load it".
#pragma once

#include <openxr/openxr.h>

#include <cstdint>
#include <string>

namespace sdfg::doctor {

struct Negotiation {
  bool ran = false;  // the library was probed (only when the layer is absent from the instance)
  std::string library;
  std::string function;  // the negotiation function's name (the manifest may rename it)
  bool opened = false;
  std::string openError;  // why the system could not load the library
  bool hasFunction = false;
  XrResult result = XR_SUCCESS;
  // What the loader side offered, as the Khronos loader offers it.
  uint32_t loaderMinInterface = 0, loaderMaxInterface = 0;
  uint64_t loaderMinApi = 0, loaderMaxApi = 0;
  // What the layer answered when it accepted.
  uint32_t layerInterface = 0;
  uint64_t layerApi = 0;
  bool returnedProcAddr = false;

  bool accepted() const {
    return opened && hasFunction && XR_SUCCEEDED(result) && returnedProcAddr;
  }
};

// An XrVersion as major.minor.patch.
std::string versionText(uint64_t version);

// Opens `library` (a path, or a bare name the system searches for) and negotiates for the layer
// `layerName` through `function`. The library is closed again before it returns; nothing else of
// it runs.
Negotiation negotiateWithLayer(const std::string& library, const std::string& layerName,
                               const std::string& function);

}  // namespace sdfg::doctor
