// The layer's configuration as the layer itself reads it (layer/config.cpp, compiled into the
// tool: the same file, the same environment variables, the same rules), with where each value in
// force came from and which entries the layer ignores.
#pragma once

#include "config.h"
#include "doctor.h"

namespace sdfg::doctor {

// Loads the configuration the layer would load in this environment. `inForce` receives it.
Report::Config describeConfig(layer::Config& inForce);

// The origin ("default", "file", "environment") of `key` in `config`; "default" when absent.
std::string originOf(const Report::Config& config, const std::string& key);

}  // namespace sdfg::doctor
