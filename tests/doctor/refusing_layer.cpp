// A stand-in for a layer library built for a newer loader-layer interface than the Khronos
// loader offers: it exports the negotiation function and refuses every offer that does not reach
// interface version 2. doctor_test.cmake's `incompatible_library` case installs it under the
// layer's name, so the loader leaves it out of the instance and autograsp-doctor has to say why.
#include <openxr/openxr.h>

#include "loader_interfaces.h"

extern "C"
#if defined(_WIN32)
    __declspec(dllexport)
#else
    __attribute__((visibility("default")))
#endif
        XrResult XRAPI_CALL
    xrNegotiateLoaderApiLayerInterface(const sdfg::layer::XrNegotiateLoaderInfo* loaderInfo,
                                       const char* /*layerName*/,
                                       sdfg::layer::XrNegotiateApiLayerRequest* /*request*/) {
  constexpr uint32_t kNeeded = 2;
  if (loaderInfo == nullptr || loaderInfo->maxInterfaceVersion < kNeeded)
    return XR_ERROR_INITIALIZATION_FAILED;
  return XR_ERROR_RUNTIME_FAILURE;  // no interface 2 exists yet: nothing to hand back
}
