// The one translation unit of the layer built twice (layer/CMakeLists.txt): with
// SDFG_LAYER_TEST_FAULTS=1 into the layer's test build, without it into the shipped library, which
// then holds neither the fault points nor the key's name (tests/layer/check_exports.sh checks).
#include "test_fault.h"

#include <stdexcept>

namespace sdfg::layer {

#if defined(SDFG_LAYER_TEST_FAULTS) && SDFG_LAYER_TEST_FAULTS

const char* testFaultKey() {
  return "test_layer_fault";
}

bool applyTestFaultKey(Config& config, const std::string& key, const std::string& value, bool& ok) {
  if (key != testFaultKey()) return false;
  ok = value == "none" || value == "after_create_instance" || value == "after_create_session" ||
       value == "after_create_space" || value == "after_create_tracker";
  if (ok) config.testLayerFault = value;
  return true;
}

void throwIfTestFault(const Config& config, const char* point) {
  if (config.testLayerFault == point)
    throw std::runtime_error(std::string("test_layer_fault: ") + point);
}

#else

const char* testFaultKey() {
  return nullptr;
}

bool applyTestFaultKey(Config&, const std::string&, const std::string&, bool&) {
  return false;
}

void throwIfTestFault(const Config&, const char*) {}

#endif

}  // namespace sdfg::layer
