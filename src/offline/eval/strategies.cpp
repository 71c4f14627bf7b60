#include "eval/strategies.h"

#include "eval/solver_physics.h"

namespace sdfg {
namespace {

struct PhysicsEntry {
  const char* name;
  PhysicsCollider::Kind kind;
};

constexpr PhysicsEntry kPhysics[] = {
    {"physics-convex", PhysicsCollider::Kind::convexHull},
    {"physics-mesh", PhysicsCollider::Kind::triangleMesh},
};

}  // namespace

std::vector<std::string> allSolverNames() {
  std::vector<std::string> names = solverNames();
  for (const PhysicsEntry& entry : kPhysics) names.emplace_back(entry.name);
  return names;
}

Result<std::unique_ptr<GraspSolver>> createAnySolver(std::string_view name) {
  for (const PhysicsEntry& entry : kPhysics) {
    if (name == entry.name)
      return std::unique_ptr<GraspSolver>(std::make_unique<PhysicsSolver>(entry.kind));
  }
  if (auto made = createSolver(name); made.ok()) return made;
  std::string known;
  for (const std::string& n : allSolverNames()) {
    if (!known.empty()) known += ", ";
    known += n;
  }
  return makeError(Status::invalid_argument,
                   "solver: unknown strategy \"" + std::string(name) + "\"; known: " + known);
}

}  // namespace sdfg
