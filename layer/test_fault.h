// Test-only failures of the layer (config key test_layer_fault): an exception thrown at a named
// point after the runtime succeeded, standing in for what can really fail there (a map insert
// out of memory, a worker thread that cannot start), so tests can check that the layer gives
// back what the runtime made and returns the error.
#pragma once

#include <stdexcept>
#include <string>

#include "state.h"

namespace sdfg::layer {

// Throws when the instance's config names `point` (after_create_instance, after_create_session,
// after_create_space, after_create_tracker).
inline void throwIfTestFault(const InstanceState& instance, const char* point) {
  if (instance.config.testLayerFault == point)
    throw std::runtime_error(std::string("test_layer_fault: ") + point);
}

}  // namespace sdfg::layer
