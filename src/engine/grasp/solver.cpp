#include "grasp/solver.h"

#include <cmath>

#include "grasp/solver_ours.h"
#include "grasp/solver_paper.h"
#include "mesh/mesh_distance.h"

namespace sdfg {

namespace {

struct SolverEntry {
  const char* name;
  std::unique_ptr<GraspSolver> (*make)();
};

template <class T>
std::unique_ptr<GraspSolver> makeSolver() {
  return std::make_unique<T>();
}

// The strategies that run inside an app (they read the grab-box SDF). Adding one is one line
// here. "ours" first: it is the default. The physics baselines live in eval/strategies.h: they
// need a physics engine the layer does not carry.
constexpr SolverEntry kSolvers[] = {
    {"ours", &makeSolver<OursSolver>},
    {"paper", &makeSolver<PaperSolver>},
};

bool inUnitStep(float v) {
  return std::isfinite(v) && v > 0.0f && v <= 1.0f;
}

}  // namespace

std::optional<Error> validateSolverOptions(const SolverOptions& options) {
  if (!inUnitStep(options.da)) {
    return makeError(
        Status::invalid_argument,
        "solver options: da = " + std::to_string(options.da) + " must be finite and in (0, 1]");
  }
  if (!inUnitStep(options.refineStep)) {
    return makeError(Status::invalid_argument,
                     "solver options: refineStep = " + std::to_string(options.refineStep) +
                         " must be finite and in (0, 1]");
  }
  if (!std::isfinite(options.threshold)) {
    return makeError(Status::invalid_argument,
                     "solver options: threshold must be finite (negative: the tip radius)");
  }
  if (!(options.approachRange > 0.0f) || !(options.approachMaxAngle > 0.0f) ||
      !std::isfinite(options.approachMaxAngle)) {
    return makeError(Status::invalid_argument,
                     "solver options: approachRange must be > 0 (infinity: any distance) and "
                     "approachMaxAngle finite and > 0");
  }
  if (!(options.clearanceBound >= 0.0f) || !std::isfinite(options.clearanceBound) ||
      !(options.clearanceMargin >= 0.0f) || !(options.clearanceMargin <= 0.01f)) {
    return makeError(Status::invalid_argument,
                     "solver options: clearanceBound must be finite and >= 0, clearanceMargin "
                     "in [0, 0.01]");
  }
  return std::nullopt;
}

std::vector<std::string> solverNames() {
  std::vector<std::string> names;
  for (const SolverEntry& entry : kSolvers) names.emplace_back(entry.name);
  return names;
}

Result<std::unique_ptr<GraspSolver>> createSolver(std::string_view name) {
  for (const SolverEntry& entry : kSolvers) {
    if (name == entry.name) return entry.make();
  }
  std::string known;
  for (const SolverEntry& entry : kSolvers) {
    if (!known.empty()) known += ", ";
    known += entry.name;
  }
  return makeError(Status::invalid_argument,
                   "solver: unknown strategy \"" + std::string(name) + "\"; known: " + known);
}

MeshExactSource::MeshExactSource(const MeshDistance& mesh, const Pose& objectFromHand)
    : mesh_(&mesh), objectFromHand_(objectFromHand), handFromObject_(objectFromHand.inverse()) {}

void MeshExactSource::sample(std::span<const glm::vec3> handPoints,
                             std::span<const float> maxDistances,
                             std::span<ExactSample> out) const {
  if (handPoints.size() != maxDistances.size() || handPoints.size() != out.size()) return;
  for (size_t i = 0; i < handPoints.size(); ++i) {
    glm::vec3 closest(0.0f);
    ExactSample& o = out[i];
    const uint32_t hint = o.feature;
    o = ExactSample{};
    o.distance = mesh_->localSignedDistanceNear(objectFromHand_.transformPoint(handPoints[i]),
                                                maxDistances[i], hint, &closest, &o.feature);
    if (std::isfinite(o.distance)) {
      o.closest = handFromObject_.transformPoint(closest);
      o.member = 0;
    }
  }
}

}  // namespace sdfg
