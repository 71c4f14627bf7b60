// Every grasp strategy the benchmark, the demo and the tests compare: the app's own ("ours",
// "paper", from grasp/solver.h) and the physics baselines ("physics-convex", "physics-mesh"),
// which need Bullet and so never ship in the layer.
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "base/status.h"
#include "grasp/solver.h"

namespace sdfg {

// Names accepted by createAnySolver(), in the order the benchmark lists them: solverNames()
// first, then the physics baselines.
std::vector<std::string> allSolverNames();

// Creates any strategy by name; an unknown name is an invalid_argument error listing the known
// ones.
Result<std::unique_ptr<GraspSolver>> createAnySolver(std::string_view name);

}  // namespace sdfg
