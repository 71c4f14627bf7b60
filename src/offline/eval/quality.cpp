#include "eval/quality.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <optional>
#include <thread>
#include <vector>

#include <glm/geometric.hpp>

#include "eval/evaluator.h"
#include "eval/percentile.h"
#include "eval/placements.h"
#include "mesh/mesh_distance.h"
#include "sdf/sdf_cpu.h"

namespace sdfg {

namespace {

struct Graded {
  GraspMetrics metrics;
  std::optional<Error> error;
};

}  // namespace

TriangleMesh normalizedLike(const TriangleMesh& mesh, const TriangleMesh& reference,
                            float diagonal) {
  return normalizedToDiagonal(mesh, diagonal, computeBounds(reference.positions));
}

Result<QualityFigures> measureQuality(const TriangleMesh& given, const QualityRun& run) {
  if (auto error = validateMesh(given.positions, given.indices)) {
    return makeError(error->code, error->message);
  }
  if (run.placements <= 0 || run.threads == 0) {
    return makeError(Status::invalid_argument, "quality: placements and threads must be positive");
  }
  if (run.reference) {
    if (auto error = validateMesh(run.reference->positions, run.reference->indices)) {
      return makeError(error->code, "quality: reference: " + error->message);
    }
  }
  // `solved` is what the strategy reads (its field and exact check), `mesh` what it is measured
  // against (placements, grading): the same mesh unless a reference is given.
  const TriangleMesh mesh =
      normalizedToDiagonal(run.reference ? *run.reference : given, kBenchObjectDiagonal);
  const TriangleMesh solved =
      run.reference ? normalizedLike(given, *run.reference, kBenchObjectDiagonal) : mesh;
  auto distance = MeshDistance::create(solved);
  if (!distance) return distance.error();
  auto exact = ExactMeshQuery::create(mesh);
  if (!exact) return exact.error();
  const HandModel hand = HandModel::defaultAdult(Hand::right);

  // One solver per thread: solve() is const, but nothing promises a strategy is reentrant.
  std::vector<std::unique_ptr<GraspSolver>> solvers;
  for (unsigned t = 0; t < run.threads; ++t) {
    auto solver = createSolver(run.method);
    if (!solver) return solver.error();
    if (!(*solver)->needsField()) {
      return makeError(Status::invalid_argument, "quality: " + run.method +
                                                     " does not read the SDF (physics strategies "
                                                     "are measured by autograsp-bench)");
    }
    if (Status s = (*solver)->prepare(hand, run.box, run.options); s != Status::ok) {
      return makeError(s, "quality: " + std::string((*solver)->prepareError()));
    }
    solvers.push_back(std::move(*solver));
  }

  const std::vector<Placement> placements =
      generatePlacements(mesh, **exact, hand, run.box, run.placements, run.seed);
  if (placements.size() < size_t(run.placements)) {
    return makeError(Status::invalid_argument,
                     "quality: only " + std::to_string(placements.size()) + " of " +
                         std::to_string(run.placements) + " placements have room for an open hand");
  }

  std::vector<Graded> graded(placements.size());
  std::atomic<size_t> next{0};
  auto work = [&](unsigned t) {
    CpuSdfBuilder builder(1);
    SdfGrid grid(run.box);
    GraspResult result;
    for (size_t p = next++; p < placements.size(); p = next++) {
      const Pose& objectFromHand = placements[p].objectFromHand;
      if (Status s = builder.build(**distance, objectFromHand, run.box, grid); s != Status::ok) {
        graded[p].error = makeError(s, "SDF build failed on placement " + std::to_string(p));
        continue;
      }
      const MeshExactSource exactSource(**distance, objectFromHand);
      GraspScene scene;
      scene.field = &grid;
      scene.objectFromHand = objectFromHand;
      scene.exact = run.exactCheck ? &exactSource : nullptr;
      if (Status s = solvers[t]->solve(scene, result); s != Status::ok) {
        graded[p].error = makeError(s, run.method + ": solve failed on placement " +
                                           std::to_string(p) + " (" + toString(s) + ")");
        continue;
      }
      graded[p].metrics = evaluateGrasp(**exact, hand, objectFromHand, result);
    }
  };
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < run.threads; ++t) pool.emplace_back(work, t);
  work(0);
  for (std::thread& th : pool) th.join();

  QualityTally tally;
  for (size_t p = 0; p < graded.size(); ++p) {
    if (graded[p].error) return *graded[p].error;
    tally.add(int(p), graded[p].metrics);
  }
  return tally.figures();
}

void QualityTally::add(int placement, const GraspMetrics& m) {
  ++sums_.grasps;
  penetrations_.push_back(m.penetrationMm);
  if (m.penetrationMm > sums_.penetrationMaxMm || sums_.deepestPlacement < 0) {
    sums_.penetrationMaxMm = m.penetrationMm;
    sums_.deepestPlacement = placement;
  }
  sums_.earlyStops += m.earlyStops;
  if (m.earlyStops > 0 && sums_.earlyStopPlacement < 0) sums_.earlyStopPlacement = placement;
  sums_.passThroughs += m.passThroughs;
  touching_ += m.contacts;
  for (const FingerMetrics& f : m.fingers) {
    if (f.contact) residuals_.push_back(f.contactResidualMm);
  }
}

QualityFigures QualityTally::figures() const {
  QualityFigures out = sums_;
  out.fingersInContact = int(residuals_.size());
  out.contactResidualMedianMm = percentile(residuals_, 0.5);
  out.contactResidualP95Mm = percentile(residuals_, 0.95);
  out.penetrationP99Mm = percentile(penetrations_, 0.99);
  out.contactsPerGrasp = out.grasps > 0 ? double(touching_) / out.grasps : 0.0;
  return out;
}

}  // namespace sdfg
