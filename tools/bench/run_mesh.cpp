#include "run_mesh.h"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "eval/approaching.h"
#include "eval/evaluator.h"
#include "eval/placements.h"
#include "eval/quality.h"
#include "eval/solver_physics.h"
#include "eval/strategies.h"
#include "grasp/solver.h"
#include "hand/hand_model.h"
#include "mesh/mesh.h"
#include "mesh/mesh_distance.h"
#include "sdf/sdf_grid.h"
#include "sdf_backends.h"

namespace sdfg::bench {
namespace {

// --approaching: the approaching placements (eval/approaching.h), with openInside[p] set for
// each; `stats` counts them as drawn (none is rejected for touching the mesh).
std::vector<Placement> approachingPlacements(const TriangleMesh& mesh, const ExactMeshQuery& exact,
                                             const HandModel& hand, const GridBox& box,
                                             const Options& o, std::vector<char>& openInside,
                                             PlacementStats& stats) {
  const std::vector<ApproachPlacement> drawn =
      generateApproachingPlacements(mesh, exact, hand, box, o.placements, o.seed);
  std::vector<Placement> out;
  openInside.clear();
  for (const ApproachPlacement& a : drawn) {
    out.push_back(a.placement);
    openInside.push_back(a.openInside ? 1 : 0);
  }
  stats = PlacementStats{};
  stats.attempts = (long long)drawn.size();
  stats.handIntersecting = (long long)std::count(openInside.begin(), openInside.end(), char(1));
  return out;
}

constexpr float kHandSizeDiagonal = 0.18f;  // metres: every object is scaled to this bbox diagonal
constexpr double kSolveBatchTargetUs = 50.0;  // a timed batch lasts at least this long
constexpr int kSolveRepeats = 3;              // per-solve time = min over this many batches

using ColliderPtr = std::unique_ptr<PhysicsCollider>;
// The physics strategies do not say which collider they read; their names do.
Result<ColliderPtr> makeColliderFor(std::string_view method, const TriangleMesh& mesh) {
  const auto kind = method.find("convex") != std::string_view::npos
                        ? PhysicsCollider::Kind::convexHull
                        : PhysicsCollider::Kind::triangleMesh;
  return PhysicsCollider::create(mesh, kind);
}

// `checkUs`: the exact check's share (GraspResult::exactCheckUs) of the fastest batch's solves.
template <class F>
double timeSolveUs(const GraspSolver& solver, const GraspScene& scene, GraspResult& out,
                   Status& status, F clockNow, double& checkUs) {
  auto t0 = clockNow();
  status = solver.solve(scene, out);
  const double once = std::chrono::duration<double, std::micro>(clockNow() - t0).count();
  if (status != Status::ok) return std::nan("");
  const int batch = std::clamp(int(kSolveBatchTargetUs / std::max(once, 1e-3)) + 1, 1, 10000);
  // A solve of a millisecond or more is stable on its own; one more run filters a cold cache.
  const int repeats = once >= 1000.0 ? 1 : kSolveRepeats;
  double best = once >= 1000.0 ? once : std::numeric_limits<double>::infinity();
  checkUs = out.exactCheckUs;
  GraspResult scratch;
  for (int r = 0; r < repeats; ++r) {
    t0 = clockNow();
    for (int b = 0; b < batch; ++b) (void)solver.solve(scene, scratch);
    const double us = std::chrono::duration<double, std::micro>(clockNow() - t0).count() / batch;
    if (us < best) {
      best = us;
      checkUs = scratch.exactCheckUs;
    }
  }
  return best;
}

void parallelFor(size_t count, unsigned threads, const std::function<void(size_t)>& body) {
  if (threads <= 1 || count < 2) {
    for (size_t i = 0; i < count; ++i) body(i);
    return;
  }
  std::atomic<size_t> next{0};
  std::vector<std::thread> pool;
  for (unsigned t = 0; t < threads; ++t) {
    pool.emplace_back([&] {
      for (size_t i = next++; i < count; i = next++) body(i);
    });
  }
  for (auto& th : pool) th.join();
}

}  // namespace

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const double pos = q * double(v.size() - 1);
  const size_t lo = size_t(std::floor(pos));
  const size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (v[hi] - v[lo]) * (pos - double(lo));
}

std::optional<fs::path> sharedMeshesDir() {
  std::vector<fs::path> candidates;
  if (const char* env = std::getenv("SDFG_SHARED_MESHES")) candidates.emplace_back(env);
#ifdef SDFG_SOURCE_DIR
  candidates.emplace_back(fs::path(SDFG_SOURCE_DIR) / ".." / "shared" / "meshes");
#endif
  candidates.emplace_back(fs::current_path() / ".." / "shared" / "meshes");
  for (const auto& c : candidates) {
    std::error_code ec;
    if (fs::is_directory(c, ec)) return fs::weakly_canonical(c, ec);
  }
  return std::nullopt;
}

// Every *.obj / *.ply of the folder, sorted; a stem present in both formats (the dragon) is kept
// once, as .ply (the original the .obj was converted from).
std::vector<fs::path> defaultMeshFiles(const fs::path& dir) {
  std::map<std::string, fs::path> byStem;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (!entry.is_regular_file(ec)) continue;
    std::string ext = entry.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return std::tolower(c); });
    if (ext != ".obj" && ext != ".ply") continue;
    const std::string stem = entry.path().stem().string();
    auto it = byStem.find(stem);
    if (it == byStem.end() || ext == ".ply") byStem[stem] = entry.path();
  }
  std::vector<fs::path> out;
  for (auto& [stem, path] : byStem) out.push_back(path);
  return out;
}

// Returns the rows of this mesh, or an error naming what failed: one row per physics method, one
// per SDF method and builder (every builder builds the field of every placement; the SDF methods
// solve on each in turn).
Result<std::vector<Row>> runMesh(const std::string& name, const TriangleMesh& original,
                                 const Options& o, const HandModel& hand, const GridBox& box,
                                 const std::vector<tools::TimedSdfBuilder*>& builders,
                                 unsigned threads, const Progress& progress,
                                 PhaseSeconds& phaseSeconds, const TriangleMesh* reference) {
  if (auto error = validateMesh(original.positions, original.indices)) {
    return makeError(error->code, error->message);
  }
  if (reference) {
    if (auto error = validateMesh(reference->positions, reference->indices)) {
      return makeError(error->code, "reference: " + error->message);
    }
  }
  // `mesh` is what grasps are measured against (placements, grading), `solvedMesh` what the
  // strategies read: the same unless a variant is solved on.
  const TriangleMesh mesh =
      normalizedToDiagonal(reference ? *reference : original, kHandSizeDiagonal);
  const TriangleMesh solvedMesh =
      reference ? normalizedLike(original, *reference, kHandSizeDiagonal) : mesh;
  auto distance = MeshDistance::create(solvedMesh);
  if (!distance) return distance.error();
  auto exact = ExactMeshQuery::create(mesh);
  if (!exact) return exact.error();

  struct Method {
    std::string name;
    std::unique_ptr<GraspSolver> solver;
    ColliderPtr collider;
  };
  std::vector<Method> methods;
  bool anyField = false;
  SolverOptions solverOptions;
  solverOptions.da = o.da;
  solverOptions.clearance = o.clearHand;
  for (const std::string& m : o.methods) {
    auto solver = createAnySolver(m);
    if (!solver) return solver.error();
    if (Status s = (*solver)->prepare(hand, box, solverOptions); s != Status::ok) {
      return makeError(s, m + ": prepare failed: " + std::string((*solver)->prepareError()));
    }
    Method method{m, std::move(*solver), nullptr};
    if (method.solver->needsCollider()) {
      auto collider = makeColliderFor(m, solvedMesh);
      if (!collider) return makeError(collider.error().code, m + ": " + collider.error().message);
      method.collider = std::move(*collider);
    }
    anyField = anyField || method.solver->needsField();
    methods.push_back(std::move(method));
  }
  anyField = anyField && !builders.empty();
  for (tools::TimedSdfBuilder* b : builders) {
    // The mesh as MeshDistance welded it, as the layer's GrabBoxSdf hands it to the GPU: a
    // variant's split vertices would hide the topology the GPU's pseudo-normals read.
    if (Status s = b->prepare((*distance)->mesh(), **distance); s != Status::ok) {
      return makeError(s, b->name() + " SDF builder: cannot take the mesh");
    }
  }

  auto now = [] { return std::chrono::steady_clock::now(); };
  const auto startedAt = now();
  PlacementStats placementStats;
  // --approaching: the open hand may already be inside; openInside[p] says so.
  std::vector<char> openInside;
  const std::vector<Placement> placements =
      o.approaching
          ? approachingPlacements(mesh, **exact, hand, box, o, openInside, placementStats)
          : generatePlacements(mesh, **exact, hand, box, o.placements, o.seed, &placementStats);
  std::fprintf(stderr,
               "%s: %zu placements from %lld attempts (%lld outside the box, %lld with the open "
               "hand touching the mesh)\n",
               name.c_str(), placements.size(), placementStats.attempts, placementStats.outsideBox,
               placementStats.handIntersecting);
  if (placements.size() < size_t(o.placements)) {
    std::fprintf(stderr, "%s: only %zu of %d placements found room for an open hand\n",
                 name.c_str(), placements.size(), o.placements);
  }

  // One row per method and field: rowMethod[r] is its method, rowBuilder[r] its builder (or -1).
  std::vector<Row> rows;
  std::vector<size_t> rowMethod;
  std::vector<int> rowBuilder;
  for (size_t m = 0; m < methods.size(); ++m) {
    Row row;
    row.mesh = name;
    row.triangles = mesh.triangleCount();
    row.method = methods[m].name;
    row.usesField = methods[m].solver->needsField();
    if (!row.usesField) {
      rows.push_back(row);
      rowMethod.push_back(m);
      rowBuilder.push_back(-1);
    }
    for (size_t b = 0; row.usesField && b < builders.size(); ++b) {
      row.backend = builders[b]->name();
      rows.push_back(row);
      rowMethod.push_back(m);
      rowBuilder.push_back(int(b));
    }
  }
  // results[r][p]; solved[r][p] says whether the solve succeeded.
  std::vector<std::vector<GraspResult>> results(rows.size(),
                                                std::vector<GraspResult>(placements.size()));
  std::vector<std::vector<char>> solved(rows.size(), std::vector<char>(placements.size(), 0));
  std::optional<Error> firstFailure;

  std::vector<SdfGrid> grids(builders.size(), SdfGrid(box));
  for (size_t p = 0; p < placements.size(); ++p) {
    progress.show(name, "solve", p, placements.size());
    const Placement& placement = placements[p];
    std::vector<double> buildMs(builders.size(), std::nan(""));
    for (size_t b = 0; anyField && b < builders.size(); ++b) {
      const auto t0 = now();
      const Status s = builders[b]->build(placement.objectFromHand, box, grids[b]);
      buildMs[b] = std::chrono::duration<double, std::milli>(now() - t0).count();
      if (s != Status::ok) {
        return makeError(s, builders[b]->name() + " SDF build failed on placement " +
                                std::to_string(p) + " (" + toString(s) + ")");
      }
    }
    const MeshExactSource exactSource(**distance, placement.objectFromHand);
    for (size_t r = 0; r < rows.size(); ++r) {
      const Method& method = methods[rowMethod[r]];
      GraspScene scene;
      scene.objectFromHand = placement.objectFromHand;
      scene.collider = method.collider.get();
      // "ours" checks its stops on the exact distance of the same mesh the SDF is built from
      // (unless --exact-check off): a variant's, as a game would give it.
      scene.exact = o.exactCheck ? &exactSource : nullptr;
      if (rowBuilder[r] >= 0) {
        scene.field = &grids[size_t(rowBuilder[r])];
        rows[r].sdfBuildMs.push_back(buildMs[size_t(rowBuilder[r])]);
      }
      Status s = Status::ok;
      double checkUs = 0.0;
      const double us = timeSolveUs(*method.solver, scene, results[r][p], s, now, checkUs);
      if (s != Status::ok) {
        rows[r].failedSolves++;
        if (!firstFailure) {
          firstFailure = makeError(s, method.name + ": solve failed on placement " +
                                          std::to_string(p) + " (" + toString(s) + ")");
        }
        continue;
      }
      solved[r][p] = 1;
      rows[r].solveUs.push_back(us);
      if (results[r][p].exactSamples > 0 || !rows[r].checkUs.empty()) {
        rows[r].checkUs.push_back(checkUs);
        rows[r].exactSamples += results[r][p].exactSamples;
      }
    }
  }

  const auto solvedAt = now();
  std::vector<GraspMetrics> metrics(rows.size() * placements.size());
  std::vector<float> handPenetration(o.approaching ? metrics.size() : 0, 0.0f);
  std::atomic<size_t> graded{0};
  parallelFor(metrics.size(), threads, [&](size_t i) {
    const size_t m = i / placements.size(), p = i % placements.size();
    if (solved[m][p]) {
      metrics[i] = evaluateGrasp(**exact, hand, placements[p].objectFromHand, results[m][p]);
      if (o.approaching) {
        handPenetration[i] =
            graspPenetrationMm(**exact, hand, placements[p].objectFromHand, results[m][p]);
      }
    }
    const size_t g = ++graded;
    if (g % 16 == 0) progress.show(name, "grade", g, metrics.size());
  });
  progress.done();
  phaseSeconds.solve = std::chrono::duration<double>(solvedAt - startedAt).count();
  phaseSeconds.grade = std::chrono::duration<double>(now() - solvedAt).count();

  // The thin-plate set: only the placements where "paper" went through the plate.
  std::vector<char> selected(placements.size(), 1);
  if (o.thinPlateSet) {
    // "paper" on the first backend's field decides.
    size_t paper = 0;
    while (paper < rows.size() && rows[paper].method != "paper") ++paper;
    size_t count = 0;
    for (size_t p = 0; p < placements.size(); ++p) {
      selected[p] = paper < rows.size() && solved[paper][p] &&
                    metrics[paper * placements.size() + p].passThroughs > 0;
      count += selected[p] ? 1 : 0;
    }
    std::fprintf(stderr, "%s: %zu of %zu placements where paper passes through\n", name.c_str(),
                 count, placements.size());
    for (Row& row : rows) row.mesh = name + "/paper-skips";
  }
  for (size_t m = 0; m < rows.size(); ++m) {
    Row& row = rows[m];
    for (size_t p = 0; p < placements.size(); ++p) {
      if (!solved[m][p] || !selected[p]) continue;
      const GraspMetrics& g = metrics[m * placements.size() + p];
      row.grasps++;
      row.penetrationMm.push_back(g.penetrationMm);
      row.earlyStops += g.earlyStops;
      row.contacts += g.contacts;
      row.passThroughs += g.passThroughs;
      if (o.approaching) {
        row.handPenetrationMm.push_back(handPenetration[m * placements.size() + p]);
        row.handMovedMm.push_back(results[m][p].handMoved * 1000.0);
        row.openInside.push_back(openInside[p]);
        row.graspContacts.push_back(g.contacts);
        row.pastBound.push_back(results[m][p].clearanceExceeded ? 1 : 0);
      }
      for (int f = 0; f < kFingerCount; ++f) {
        const FingerMetrics& fm = g.fingers[f];
        if (!fm.contact) continue;
        row.tipResidualMm.push_back(fm.tipResidualMm);
        row.contactResidualMm.push_back(fm.contactResidualMm);
        row.contactFingers[f]++;
        row.tipContactFingers[f] += fm.tipIsContact ? 1 : 0;
      }
    }
  }
  if (firstFailure) {
    std::fprintf(stderr, "%s: %s\n", name.c_str(), firstFailure->message.c_str());
  }
  return rows;
}

}  // namespace sdfg::bench
