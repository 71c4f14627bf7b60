// Test-only failures of the layer (config key test_layer_fault): an exception thrown at a named
// point after the runtime succeeded, standing in for what can really fail there (a map insert
// out of memory, a worker thread that cannot start), so tests can check that the layer gives
// back what the runtime made and returns the error.
//
// Only the layer's test build has them (test_fault.cpp compiled with SDFG_LAYER_TEST_FAULTS=1,
// layer/CMakeLists.txt). An implicit layer runs inside every OpenXR app, so the shipped library
// must not fail xrCreateInstance because a variable says so: there the key is unknown (a config
// file that names it gets the usual warning) and throwIfTestFault does nothing.
#pragma once

#include <string>

#include "config.h"

namespace sdfg::layer {

// The key's name in the test build; nullptr in the shipped one.
const char* testFaultKey();
// In the test build, when `key` is test_layer_fault: sets `ok` to whether `value` is a fault
// point (or none), applies it to `config` if so, and returns true. Otherwise returns false.
bool applyTestFaultKey(Config& config, const std::string& key, const std::string& value, bool& ok);

// Throws when `config` names `point` (after_create_instance, after_create_session,
// after_create_space, after_create_tracker).
void throwIfTestFault(const Config& config, const char* point);
// As the call sites have it: with the instance whose config it reads (a template so that this
// header, which config.cpp includes, needs no state.h).
template <class Instance>
void throwIfTestFault(const Instance& instance, const char* point) {
  throwIfTestFault(instance.config, point);
}

}  // namespace sdfg::layer
