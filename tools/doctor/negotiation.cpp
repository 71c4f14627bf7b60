#include "negotiation.h"

#include "loader_interfaces.h"
#include "system.h"

namespace sdfg::doctor {

std::string versionText(uint64_t v) {
  return std::to_string(XR_VERSION_MAJOR(v)) + "." + std::to_string(XR_VERSION_MINOR(v)) + "." +
         std::to_string(XR_VERSION_PATCH(v));
}

Negotiation negotiateWithLayer(const std::string& library, const std::string& layerName,
                               const std::string& function) {
  using namespace sdfg::layer;
  Negotiation n;
  n.ran = true;
  n.library = library;
  n.function = function;
  // The Khronos loader's offer (api_layer_interface.cpp, LoadApiLayers): every interface version
  // from 1 to its current one, every OpenXR 1.x.
  n.loaderMinInterface = 1;
  n.loaderMaxInterface = kCurrentLoaderApiLayerVersion;
  n.loaderMinApi = XR_MAKE_VERSION(1, 0, 0);
  n.loaderMaxApi = XR_MAKE_VERSION(1, 0x3ff, 0xfff);

  SharedLibrary lib = SharedLibrary::open(library, n.openError);
  n.opened = lib.isOpen();
  if (!n.opened) return n;
  using Negotiate =
      XrResult(XRAPI_PTR*)(const XrNegotiateLoaderInfo*, const char*, XrNegotiateApiLayerRequest*);
  const auto negotiate = reinterpret_cast<Negotiate>(lib.symbol(function.c_str()));
  n.hasFunction = negotiate != nullptr;
  if (!n.hasFunction) return n;

  XrNegotiateLoaderInfo info{};
  info.structType = XR_LOADER_INTERFACE_STRUCT_LOADER_INFO;
  info.structVersion = kLoaderInfoStructVersion;
  info.structSize = sizeof(info);
  info.minInterfaceVersion = n.loaderMinInterface;
  info.maxInterfaceVersion = n.loaderMaxInterface;
  info.minApiVersion = n.loaderMinApi;
  info.maxApiVersion = n.loaderMaxApi;
  XrNegotiateApiLayerRequest request{};
  request.structType = XR_LOADER_INTERFACE_STRUCT_API_LAYER_REQUEST;
  request.structVersion = kApiLayerInfoStructVersion;
  request.structSize = sizeof(request);
  n.result = negotiate(&info, layerName.c_str(), &request);
  if (XR_SUCCEEDED(n.result)) {
    n.layerInterface = request.layerInterfaceVersion;
    n.layerApi = request.layerApiVersion;
    n.returnedProcAddr = request.getInstanceProcAddr != nullptr;
  }
  return n;
}

}  // namespace sdfg::doctor
