// autograsp-bench: speed and quality of every grasp strategy on the same seeded placements.
//
// Per mesh: load, scale to hand size (18 cm bounding-box diagonal), draw the placements once, then
// for each placement build the grab-box SDF on the CPU (timed) and solve it with every method
// (timed over repeated batches), and grade each grasp against the exact surface of the mesh
// (evaluator.h). Prints the paper's Table 1 layout (methods x meshes, solve time), a quality
// table and side-by-side ratios; --json writes every figure for docs to quote.
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "eval/evaluator.h"
#include "eval/placements.h"
#include "eval/solver_physics.h"
#include "eval/strategies.h"
#include "grasp/solver.h"
#include "hand/hand_model.h"
#include "io/mesh_io.h"
#include "io/shapes.h"
#include "mesh/mesh.h"
#include "mesh/mesh_distance.h"
#include "report.h"
#include "sdf/sdf_grid.h"
#include "sdf_backends.h"

namespace fs = std::filesystem;
using namespace sdfg;

namespace {

constexpr float kHandSizeDiagonal = 0.18f;  // metres: every object is scaled to this bbox diagonal
constexpr double kSolveBatchTargetUs = 50.0;  // a timed batch lasts at least this long
constexpr int kSolveRepeats = 3;              // per-solve time = min over this many batches
// Exit code of a run that completed without a backend it was asked for (no Vulkan device).
constexpr int kExitBackendUnavailable = 3;

const char* kUsage =
    "usage: autograsp-bench [options]\n"
    "  --mesh FILE        mesh to test (OBJ or PLY); repeatable. Default: the embedded objects\n"
    "                     and every *.obj / *.ply in ../shared/meshes\n"
    "  --embedded         also test the embedded objects when --mesh is given\n"
    "  --embedded-only    only the embedded objects (mug, torus, thin plate)\n"
    "  --placements N     hand placements per mesh (default 1000)\n"
    "  --seed S           seed of the placements (default 1)\n"
    "  --methods LIST     comma-separated strategies (default: all)\n"
    "  --da X             curl step of the solvers, in (0, 1] (default 0.1)\n"
    "  --resolution N     SDF grid nodes per axis, 2..128 (default 16)\n"
    "  --exact-check on|off  on (default): \"ours\" checks and corrects its stops on the exact\n"
    "                     mesh distance (GraspScene::exact); off: on the SDF alone\n"
    "  --threads N        worker threads for SDF builds and grading (default: all cores)\n"
    "  --sdf-backend LIST comma-separated SDF builders: cpu, vulkan (default cpu); each SDF\n"
    "                     method gets one row per backend, solving on that backend's field.\n"
    "                     vulkan: a device of its own (VK_ICD_FILENAMES picks the driver)\n"
    "  --sdf-far-band M   cpu builder far-field mode: nodes at least M metres from the surface\n"
    "                     may hold certified lower bounds (CpuSdfOptions::exactBand; default 0,\n"
    "                     exact everywhere)\n"
    "  --thin-plate-set   only the embedded thin plate, graded on the placements where\n"
    "                     \"paper\" (added if missing; --da must be 0.1) passes through it\n"
    "  --json FILE        write the results as JSON\n"
    "  --report DIR       also write DIR/benchmarks.md with tables and plots (gnuplot) of this\n"
    "                     run, DIR/img/bench/*.png and DIR/bench-data/; implies --scaling\n"
    "  --scaling          also time the SDF builds against triangles and resolution, the\n"
    "                     --sdf-backend list side by side (default: cpu and vulkan)\n"
    "  --scaling-quick    --scaling on small tori only (tests)\n"
    "  --scaling-json FILE also write the sweep's figures as JSON; implies --scaling\n"
    "  --scaling-from FILE the sweep's figures from a JSON --scaling-json wrote, instead of\n"
    "                     sweeping again\n"
    "  --report-from FILE with --report: write the report from a JSON an earlier run wrote\n"
    "                     (with --json) instead of running the meshes again\n"
    "  --help             this text\n"
    "exit codes: 0 done; 1 a mesh, solve or output failed; 2 bad option; 3 done, but a\n"
    "requested SDF backend (vulkan) had no device: its rows and columns are left out\n";

struct Options {
  std::vector<std::string> meshes;
  bool embedded = false;
  bool embeddedOnly = false;
  bool thinPlateSet = false;
  int placements = 1000;
  uint64_t seed = 1;
  std::vector<std::string> methods;
  float da = 0.1f;
  int resolution = 16;
  unsigned threads = 0;
  float sdfFarBand = 0.0f;  // CpuSdfOptions::exactBand of the cpu builder
  bool exactCheck = true;   // pass GraspScene::exact ("ours" checks its stops on the mesh)
  std::vector<std::string> sdfBackends = {tools::kCpuBackend};
  bool sdfBackendsGiven = false;  // else --scaling compares cpu and vulkan
  std::string json;
  std::string report;
  std::string scalingJson;  // the sweep's figures as JSON
  std::string scalingFrom;  // a sweep's JSON to report instead of sweeping again
  bool scaling = false;
  bool scalingQuick = false;
  std::string reportFrom;  // a results JSON to report on instead of running
};

struct UsageError {
  std::string message;
};

bool parseInt(const std::string& s, long long lo, long long hi, long long& out) {
  if (s.empty()) return false;
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(s.c_str(), &end, 10);
  if (errno != 0 || *end != '\0' || v < lo || v > hi) return false;
  out = v;
  return true;
}

std::optional<UsageError> parseOptions(int argc, char** argv, Options& o, bool& help) {
  const std::vector<std::string> known = allSolverNames();
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    std::string value;
    bool hasValue = false;
    if (const size_t eq = arg.find('='); arg.rfind("--", 0) == 0 && eq != std::string::npos) {
      value = arg.substr(eq + 1);
      arg = arg.substr(0, eq);
      hasValue = true;
    }
    auto next = [&]() -> std::optional<std::string> {
      if (hasValue) return value;
      if (i + 1 >= argc) return std::nullopt;
      return std::string(argv[++i]);
    };
    auto needValue = [&](std::string& out) -> std::optional<UsageError> {
      auto v = next();
      if (!v) return UsageError{arg + " needs a value"};
      out = *v;
      return std::nullopt;
    };
    // A value that must not be empty (a file or folder).
    auto needName = [&](std::string& out, const char* what) -> std::optional<UsageError> {
      if (auto e = needValue(out)) return e;
      if (out.empty()) return UsageError{arg + ": empty " + what};
      return std::nullopt;
    };
    // A comma-separated list of names from `names`, each kept once, in order.
    auto needList = [&](const std::vector<std::string>& names, const std::string& what,
                        std::vector<std::string>& out) -> std::optional<UsageError> {
      std::string text;
      if (auto e = needValue(text)) return e;
      out.clear();
      std::stringstream ss(text);
      std::string item;
      while (std::getline(ss, item, ',')) {
        if (item.empty()) continue;
        if (std::find(names.begin(), names.end(), item) == names.end()) {
          std::string list;
          for (const auto& k : names) list += (list.empty() ? "" : ", ") + k;
          return UsageError{arg + ": unknown " + what + " \"" + item + "\"; known: " + list};
        }
        if (std::find(out.begin(), out.end(), item) == out.end()) out.push_back(item);
      }
      if (out.empty()) return UsageError{arg + ": no " + what + " given"};
      return std::nullopt;
    };
    std::string v;
    long long n = 0;
    if (arg == "--help" || arg == "-h") {
      help = true;
    } else if (arg == "--embedded") {
      o.embedded = true;
    } else if (arg == "--embedded-only") {
      o.embeddedOnly = true;
    } else if (arg == "--thin-plate-set") {
      o.thinPlateSet = true;
    } else if (arg == "--mesh") {
      if (auto e = needValue(v)) return e;
      o.meshes.push_back(v);
    } else if (arg == "--placements") {
      if (auto e = needValue(v)) return e;
      if (!parseInt(v, 1, 1000000, n))
        return UsageError{"--placements: \"" + v + "\" is not 1..1000000"};
      o.placements = int(n);
    } else if (arg == "--seed") {
      if (auto e = needValue(v)) return e;
      char* end = nullptr;
      errno = 0;
      const unsigned long long s = std::strtoull(v.c_str(), &end, 10);
      if (v.empty() || v[0] == '-' || errno != 0 || *end != '\0') {
        return UsageError{"--seed: \"" + v + "\" is not a non-negative integer"};
      }
      o.seed = s;
    } else if (arg == "--methods") {
      if (auto e = needList(known, "method", o.methods)) return e;
    } else if (arg == "--da") {
      if (auto e = needValue(v)) return e;
      char* end = nullptr;
      const float x = std::strtof(v.c_str(), &end);
      if (v.empty() || *end != '\0' || !std::isfinite(x) || !(x > 0.0f) || x > 1.0f) {
        return UsageError{"--da: \"" + v + "\" is not a number in (0, 1]"};
      }
      o.da = x;
    } else if (arg == "--resolution") {
      if (auto e = needValue(v)) return e;
      if (!parseInt(v, kMinGridResolution, kMaxGridResolution, n)) {
        return UsageError{"--resolution: \"" + v + "\" is not 2..128"};
      }
      o.resolution = int(n);
    } else if (arg == "--exact-check") {
      if (auto e = needValue(v)) return e;
      if (v != "on" && v != "off")
        return UsageError{"--exact-check: \"" + v + "\" is not on or off"};
      o.exactCheck = v == "on";
    } else if (arg == "--threads") {
      if (auto e = needValue(v)) return e;
      if (!parseInt(v, 0, 1024, n)) return UsageError{"--threads: \"" + v + "\" is not 0..1024"};
      o.threads = unsigned(n);
    } else if (arg == "--sdf-far-band") {
      if (auto e = needValue(v)) return e;
      char* end = nullptr;
      const float x = std::strtof(v.c_str(), &end);
      if (v.empty() || *end != '\0' || !std::isfinite(x) || !(x >= 0.0f)) {
        return UsageError{"--sdf-far-band: \"" + v + "\" is not a distance >= 0 in metres"};
      }
      o.sdfFarBand = x;
    } else if (arg == "--sdf-backend") {
      if (auto e =
              needList({tools::kCpuBackend, tools::kVulkanBackend}, "backend", o.sdfBackends)) {
        return e;
      }
      o.sdfBackendsGiven = true;
    } else if (arg == "--json") {
      if (auto e = needName(o.json, "file name")) return e;
    } else if (arg == "--report") {
      if (auto e = needName(o.report, "folder name")) return e;
      o.scaling = true;
    } else if (arg == "--scaling-json") {
      if (auto e = needName(o.scalingJson, "file name")) return e;
      o.scaling = true;
    } else if (arg == "--scaling-from") {
      if (auto e = needName(o.scalingFrom, "file name")) return e;
      o.scaling = true;
    } else if (arg == "--report-from") {
      if (auto e = needName(o.reportFrom, "file name")) return e;
    } else if (arg == "--scaling" || arg == "--scaling-quick") {
      o.scaling = true;
      o.scalingQuick = o.scalingQuick || arg == "--scaling-quick";
    } else {
      return UsageError{"unknown option \"" + std::string(argv[i]) + "\""};
    }
  }
  if (o.methods.empty()) o.methods = known;
  if (o.thinPlateSet) {
    if (o.da != 0.1f) return UsageError{"--thin-plate-set: the set is defined at --da 0.1"};
    if (std::find(o.methods.begin(), o.methods.end(), "paper") == o.methods.end()) {
      o.methods.push_back("paper");
    }
  }
  if (!o.reportFrom.empty() && o.report.empty()) {
    return UsageError{"--report-from needs --report DIR"};
  }
  return std::nullopt;
}

// ---------------------------------------------------------------------------------------------
// Statistics

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const double pos = q * double(v.size() - 1);
  const size_t lo = size_t(std::floor(pos));
  const size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (v[hi] - v[lo]) * (pos - double(lo));
}

struct Row {
  std::string mesh;
  size_t triangles = 0;
  std::string method;
  bool usesField = false;
  std::string backend = "none";  // the SDF builder whose field the method read
  int grasps = 0;
  int failedSolves = 0;
  std::vector<double> sdfBuildMs;
  std::vector<double> solveUs;
  std::vector<double> checkUs;  // part of solveUs spent in the exact check (GraspScene::exact)
  long long exactSamples = 0;   // exact samples, summed over grasps
  std::vector<double> tipResidualMm;      // per finger in contact
  std::vector<double> contactResidualMm;  // per finger in contact: closest phalanx sphere's gap
  std::array<long long, kFingerCount> contactFingers{};     // fingers in contact, per finger
  std::array<long long, kFingerCount> tipContactFingers{};  // ... whose tip is the contact
  long long passThroughs = 0;                               // fingers whose sweep went through
  std::vector<double> penetrationMm;                        // per grasp: deepest phalanx point
  int earlyStops = 0;
  long long contacts = 0;

  double contactsMean() const { return grasps > 0 ? double(contacts) / grasps : std::nan(""); }
};

// ---------------------------------------------------------------------------------------------
// Meshes

struct MeshSource {
  std::string name;
  std::optional<fs::path> path;
  TriangleMesh embedded;
};

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

// ---------------------------------------------------------------------------------------------
// Running one mesh

using ColliderPtr = std::unique_ptr<PhysicsCollider>;
// The physics strategies do not say which collider they read; their names do.
Result<ColliderPtr> makeColliderFor(std::string_view method, const TriangleMesh& mesh) {
  const auto kind = method.find("convex") != std::string_view::npos
                        ? PhysicsCollider::Kind::convexHull
                        : PhysicsCollider::Kind::triangleMesh;
  return PhysicsCollider::create(mesh, kind);
}

struct Progress {
  bool enabled = isatty(STDERR_FILENO) != 0;
  void show(const std::string& mesh, const char* phase, size_t done, size_t total) const {
    if (!enabled || total == 0) return;
    const int width = 30;
    const int filled = int(double(done) / double(total) * width);
    std::fprintf(stderr, "\r%-24.24s %-8s [%s%s] %zu/%zu", mesh.c_str(), phase,
                 std::string(size_t(filled), '#').c_str(),
                 std::string(size_t(width - filled), '.').c_str(), done, total);
    std::fflush(stderr);
  }
  void done() const {
    if (enabled) std::fprintf(stderr, "\r\033[K");
  }
};

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

struct PhaseSeconds {
  double solve = 0.0;  // placements, SDF builds and timed solves
  double grade = 0.0;  // evaluation against the exact mesh
};

// Returns the rows of this mesh, or an error naming what failed: one row per physics method, one
// per SDF method and builder (every builder builds the field of every placement; the SDF methods
// solve on each in turn).
Result<std::vector<Row>> runMesh(const std::string& name, const TriangleMesh& original,
                                 const Options& o, const HandModel& hand, const GridBox& box,
                                 const std::vector<tools::TimedSdfBuilder*>& builders,
                                 unsigned threads, const Progress& progress,
                                 PhaseSeconds& phaseSeconds) {
  if (auto error = validateMesh(original.positions, original.indices)) {
    return makeError(error->code, error->message);
  }
  const TriangleMesh mesh = normalizedToDiagonal(original, kHandSizeDiagonal);
  auto distance = MeshDistance::create(mesh);
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
  for (const std::string& m : o.methods) {
    auto solver = createAnySolver(m);
    if (!solver) return solver.error();
    if (Status s = (*solver)->prepare(hand, box, solverOptions); s != Status::ok) {
      return makeError(s, m + ": prepare failed: " + std::string((*solver)->prepareError()));
    }
    Method method{m, std::move(*solver), nullptr};
    if (method.solver->needsCollider()) {
      auto collider = makeColliderFor(m, mesh);
      if (!collider) return makeError(collider.error().code, m + ": " + collider.error().message);
      method.collider = std::move(*collider);
    }
    anyField = anyField || method.solver->needsField();
    methods.push_back(std::move(method));
  }
  anyField = anyField && !builders.empty();
  for (tools::TimedSdfBuilder* b : builders) {
    if (Status s = b->prepare(mesh, **distance); s != Status::ok) {
      return makeError(s, b->name() + " SDF builder: cannot take the mesh");
    }
  }

  auto now = [] { return std::chrono::steady_clock::now(); };
  const auto startedAt = now();
  PlacementStats placementStats;
  const std::vector<Placement> placements =
      generatePlacements(mesh, **exact, hand, box, o.placements, o.seed, &placementStats);
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
      // (unless --exact-check off).
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
  std::atomic<size_t> graded{0};
  parallelFor(metrics.size(), threads, [&](size_t i) {
    const size_t m = i / placements.size(), p = i % placements.size();
    if (solved[m][p]) {
      metrics[i] = evaluateGrasp(**exact, hand, placements[p].objectFromHand, results[m][p]);
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

// ---------------------------------------------------------------------------------------------
// Output

// Per-finger counts, thumb to little.
std::string jsonCounts(const std::array<long long, kFingerCount>& counts) {
  std::string out = "[";
  for (int f = 0; f < kFingerCount; ++f) out += (f ? ", " : "") + std::to_string(counts[f]);
  return out + "]";
}

using bench::jsonNumber;
using bench::jsonString;

bool writeJson(const std::string& file, const Options& o, const std::vector<Row>& rows) {
  std::ofstream out(file);
  if (!out) return false;
  out << "{\n  \"placements\": " << o.placements << ",\n  \"da\": " << jsonNumber(o.da)
      << ",\n  \"resolution\": " << o.resolution << ",\n  \"seed\": " << o.seed
      << ",\n  \"exact_check\": " << (o.exactCheck ? "true" : "false") << ",\n  \"rows\": [";
  for (size_t i = 0; i < rows.size(); ++i) {
    const Row& r = rows[i];
    const double nan = std::nan("");
    const double buildMedian = r.usesField ? percentile(r.sdfBuildMs, 0.5) : nan;
    const double buildP95 = r.usesField ? percentile(r.sdfBuildMs, 0.95) : nan;
    out << (i ? ",\n" : "\n") << "    {\"mesh\": " << jsonString(r.mesh)
        << ", \"triangles\": " << r.triangles << ", \"method\": " << jsonString(r.method)
        << ", \"sdf_backend\": " << jsonString(r.backend) << ", \"grasps\": " << r.grasps
        << ",\n     \"sdf_build_ms\": {\"median\": " << jsonNumber(buildMedian)
        << ", \"p95\": " << jsonNumber(buildP95) << "}"
        << ", \"solve_us\": {\"median\": " << jsonNumber(percentile(r.solveUs, 0.5))
        << ", \"p95\": " << jsonNumber(percentile(r.solveUs, 0.95)) << "}";
    if (!r.checkUs.empty()) {
      out << ", \"check_us\": {\"median\": " << jsonNumber(percentile(r.checkUs, 0.5))
          << ", \"p95\": " << jsonNumber(percentile(r.checkUs, 0.95)) << "}"
          << ", \"exact_samples_mean\": "
          << jsonNumber(double(r.exactSamples) / double(r.checkUs.size()));
    }
    out << ",\n     \"tip_residual_mm\": {\"median\": "
        << jsonNumber(percentile(r.tipResidualMm, 0.5))
        << ", \"p95\": " << jsonNumber(percentile(r.tipResidualMm, 0.95)) << "}"
        << ", \"contact_residual_mm\": {\"median\": "
        << jsonNumber(percentile(r.contactResidualMm, 0.5))
        << ", \"p95\": " << jsonNumber(percentile(r.contactResidualMm, 0.95)) << "}"
        << ",\n     \"contact_fingers\": " << jsonCounts(r.contactFingers)
        << ", \"tip_contact_fingers\": " << jsonCounts(r.tipContactFingers)
        << ", \"pass_through\": " << r.passThroughs
        << ",\n     \"penetration_mm\": {\"p99\": " << jsonNumber(percentile(r.penetrationMm, 0.99))
        << ", \"max\": " << jsonNumber(percentile(r.penetrationMm, 1.0)) << "}"
        << ", \"early_stops\": " << r.earlyStops
        << ", \"contacts_mean\": " << jsonNumber(r.contactsMean()) << "}";
  }
  out << "\n  ]\n}\n";
  out.flush();
  return bool(out);
}

std::string fmt(double v, const char* format = "%.3g") {
  if (!std::isfinite(v)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

void printTables(const Options& o, const std::vector<Row>& rows) {
  // Rows are told apart by mesh, method and backend; the backend is shown when more than one ran.
  std::vector<std::string> meshes, backends;
  std::vector<std::pair<std::string, std::string>> variants;  // method, backend
  for (const Row& r : rows) {
    if (std::find(meshes.begin(), meshes.end(), r.mesh) == meshes.end()) meshes.push_back(r.mesh);
    const std::pair<std::string, std::string> v{r.method, r.backend};
    if (std::find(variants.begin(), variants.end(), v) == variants.end()) variants.push_back(v);
    if (r.usesField && std::find(backends.begin(), backends.end(), r.backend) == backends.end()) {
      backends.push_back(r.backend);
    }
  }
  const bool showBackend = backends.size() > 1;
  auto find = [&](const std::string& mesh, const std::string& method,
                  const std::string& backend) -> const Row* {
    for (const Row& r : rows) {
      if (r.mesh == mesh && r.method == method && r.backend == backend) return &r;
    }
    return nullptr;
  };
  size_t width = 10;
  for (const auto& m : meshes) width = std::max(width, m.size() + 1);
  const int methodWidth = showBackend ? 15 : 22;
  auto methodCells = [&](const std::string& method, const std::string& backend) {
    std::printf("%-*s", methodWidth, method.c_str());
    if (showBackend) std::printf(" %-6s", backend.c_str());
  };

  std::printf(
      "\nSolve time per grasp, median of %d placements, microseconds (paper Table 1: "
      "ms; SDF build not included)\n",
      o.placements);
  methodCells("method", "sdf");
  for (const auto& m : meshes) std::printf(" %*s", int(width), m.c_str());
  std::printf("\n");
  for (const auto& [method, backend] : variants) {
    methodCells(method, backend);
    for (const auto& m : meshes) {
      const Row* r = find(m, method, backend);
      std::printf(" %*s", int(width), r ? fmt(percentile(r->solveUs, 0.5), "%.2f").c_str() : "-");
    }
    std::printf("\n");
    bool anyCheck = false;
    for (const auto& m : meshes) {
      const Row* r = find(m, method, backend);
      anyCheck = anyCheck || (r && !r->checkUs.empty());
    }
    if (!anyCheck) continue;
    // The exact check's share of the solve above (GraspScene::exact), median per grasp.
    methodCells("  " + method + " check", backend);
    for (const auto& m : meshes) {
      const Row* r = find(m, method, backend);
      std::printf(
          " %*s", int(width),
          r && !r->checkUs.empty() ? fmt(percentile(r->checkUs, 0.5), "%.2f").c_str() : "-");
    }
    std::printf("\n");
  }
  for (const auto& backend : backends) {
    methodCells(showBackend ? "sdf build (ms)" : backend + " sdf build (ms)", backend);
    for (const auto& m : meshes) {
      std::string cell = "-";
      for (const auto& [method, b] : variants) {
        const Row* r = b == backend ? find(m, method, b) : nullptr;
        if (r && r->usesField) {
          cell = fmt(percentile(r->sdfBuildMs, 0.5), "%.2f");
          break;
        }
      }
      std::printf(" %*s", int(width), cell.c_str());
    }
    std::printf("\n");
  }
  methodCells("triangles", "");
  for (const auto& m : meshes) {
    size_t triangles = 0;
    for (const Row& r : rows) {
      if (r.mesh == m && triangles == 0) triangles = r.triangles;
    }
    std::printf(" %*zu", int(width), triangles);
  }
  std::printf(
      "\n\nQuality against the exact mesh (tip residual over fingers in contact; "
      "penetration over grasps)\n");
  std::printf("%-24s %-16s", "mesh", "method");
  if (showBackend) std::printf(" %-6s", "sdf");
  std::printf(" %6s %9s %9s %9s %9s %9s %9s %7s %8s %6s %5s\n", "grasps", "tip_med", "tip_p95",
              "cres_med", "cres_p95", "pen_p99", "pen_max", "early", "contacts", "tip%", "pass");
  for (const auto& m : meshes) {
    for (const auto& [method, backend] : variants) {
      const Row* r = find(m, method, backend);
      if (!r) continue;
      long long inContact = 0, tipContact = 0;
      for (int f = 0; f < kFingerCount; ++f) {
        inContact += r->contactFingers[f];
        tipContact += r->tipContactFingers[f];
      }
      std::printf("%-24s %-16s", m.c_str(), method.c_str());
      if (showBackend) std::printf(" %-6s", backend.c_str());
      std::printf(
          " %6d %9s %9s %9s %9s %9s %9s %7d %8s %6s %5lld\n", r->grasps,
          fmt(percentile(r->tipResidualMm, 0.5)).c_str(),
          fmt(percentile(r->tipResidualMm, 0.95)).c_str(),
          fmt(percentile(r->contactResidualMm, 0.5)).c_str(),
          fmt(percentile(r->contactResidualMm, 0.95)).c_str(),
          fmt(percentile(r->penetrationMm, 0.99)).c_str(),
          fmt(percentile(r->penetrationMm, 1.0)).c_str(), r->earlyStops,
          fmt(r->contactsMean()).c_str(),
          inContact > 0 ? fmt(100.0 * double(tipContact) / double(inContact), "%.0f").c_str() : "-",
          r->passThroughs);
    }
  }
  std::printf(
      "(mm; tip = |tip gap| and cres = |closest phalanx sphere gap|, over fingers in contact; "
      "early = fingers stopped > 5 mm short of a reachable pose; contacts = fingers within 2 mm, "
      "mean per grasp; tip%% = fingers in contact whose tip is the closest sphere; pass = fingers "
      "whose closing sweep put a sphere centre inside the mesh%s)\n",
      showBackend ? "; sdf = the backend that built the field the method read" : "");

  // Against "paper" on the same placements and, for the SDF methods, the same backend's field.
  const std::string base = "paper";
  if (std::find(o.methods.begin(), o.methods.end(), base) == o.methods.end()) return;
  std::printf("\nRatios against \"paper\", same placements (solve time x; early stops x)\n");
  std::printf("%-24s %-16s", "mesh", "method");
  if (showBackend) std::printf(" %-6s", "sdf");
  std::printf(" %10s %12s\n", "solve", "early stops");
  for (const auto& m : meshes) {
    for (const auto& [method, backend] : variants) {
      if (method == base) continue;
      const Row* r = find(m, method, backend);
      const Row* p =
          find(m, base, backend == "none" ? backends.empty() ? "" : backends.front() : backend);
      if (!r || !p) continue;
      const double solve = percentile(r->solveUs, 0.5) / percentile(p->solveUs, 0.5);
      const std::string early = p->earlyStops > 0
                                    ? fmt(double(r->earlyStops) / p->earlyStops, "%.2f")
                                    : std::to_string(r->earlyStops) + " vs 0";
      std::printf("%-24s %-16s", m.c_str(), method.c_str());
      if (showBackend) std::printf(" %-6s", backend.c_str());
      std::printf(" %10s %12s\n", fmt(solve, "%.2f").c_str(), early.c_str());
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  bool help = false;
  if (auto error = parseOptions(argc, argv, o, help)) {
    std::fprintf(stderr, "autograsp-bench: %s\n%s", error->message.c_str(), kUsage);
    return 2;
  }
  if (help) {
    std::fputs(kUsage, stdout);
    return 0;
  }
  const unsigned threads =
      o.threads ? o.threads : std::max(1u, std::thread::hardware_concurrency());
  // The sweep compares the backends asked for; by default both (the side-by-side table).
  const std::vector<std::string> scalingBackends =
      o.sdfBackendsGiven ? o.sdfBackends
                         : std::vector<std::string>{tools::kCpuBackend, tools::kVulkanBackend};
  auto reportExitCode = [](bench::ReportStatus status) {
    return status == bench::ReportStatus::failed                ? 1
           : status == bench::ReportStatus::backend_unavailable ? kExitBackendUnavailable
                                                                : 0;
  };
  if (!o.reportFrom.empty()) {
    // A long run's results, reported again (new plots, new notes) without solving again.
    return reportExitCode(bench::runReport(bench::ReportRequest{
        o.report, o.reportFrom, bench::shellCommandLine(argc, argv), threads, o.scalingQuick,
        o.resolution, sharedMeshesDir(), scalingBackends, o.scalingJson, o.scalingFrom}));
  }

  std::vector<MeshSource> sources;
  const bool useDefaults = o.meshes.empty() && !o.embeddedOnly && !o.thinPlateSet;
  if (o.embeddedOnly || o.embedded || useDefaults || o.thinPlateSet) {
    for (NamedMesh& m : embeddedObjects()) {
      if (o.thinPlateSet && m.name != "thin-plate") continue;
      sources.push_back({m.name, std::nullopt, std::move(m.mesh)});
    }
  }
  if (!o.embeddedOnly && !o.thinPlateSet) {
    std::vector<fs::path> files(o.meshes.begin(), o.meshes.end());
    if (useDefaults) {
      if (auto dir = sharedMeshesDir()) {
        files = defaultMeshFiles(*dir);
      } else {
        std::fprintf(stderr, "note: no ../shared/meshes folder found; embedded objects only\n");
      }
    }
    for (const auto& f : files) sources.push_back({f.stem().string(), f, {}});
  }

  const HandModel hand = HandModel::defaultAdult(Hand::right);
  GridBox box = GridBox::referenceDefault();
  box.resolution = glm::uvec3(uint32_t(o.resolution));
  // One builder per backend asked for; one without a device is left out, with its rows.
  std::vector<std::unique_ptr<tools::TimedSdfBuilder>> builderStore;
  std::vector<tools::TimedSdfBuilder*> builders;
  bool backendMissing = false;
  tools::TimedBuilderOptions builderOptions;
  builderOptions.cpuThreads = threads;
  builderOptions.cpuExactBand = o.sdfFarBand;
  for (const std::string& backend : o.sdfBackends) {
    auto b = tools::makeTimedBuilder(backend, builderOptions);
    if (!b) {
      std::fprintf(stderr,
                   "autograsp-bench: --sdf-backend %s: %s; its rows are left out (exit code %d)\n",
                   backend.c_str(), b.error().message.c_str(), kExitBackendUnavailable);
      backendMissing = true;
      continue;
    }
    std::fprintf(stderr, "autograsp-bench: SDF backend %s on %s\n", backend.c_str(),
                 (*b)->device().c_str());
    builders.push_back(b->get());
    builderStore.push_back(std::move(b.value()));
  }
  if (!o.exactCheck) {
    std::fprintf(stderr, "autograsp-bench: --exact-check off: \"ours\" stops on the SDF alone\n");
  }
  const Progress progress;

  bool failed = false;
  std::vector<Row> rows;
  for (const MeshSource& source : sources) {
    TriangleMesh loaded;
    const TriangleMesh* mesh = &source.embedded;
    if (source.path) {
      auto result = loadMesh(*source.path);
      if (!result) {
        // Loader messages usually start with the path already; name it once.
        const std::string& message = result.error().message;
        const std::string file = source.path->string();
        std::fprintf(stderr, "autograsp-bench: skipping %s: %s\n", file.c_str(),
                     message.size() > file.size() + 2 &&
                             message.compare(0, file.size() + 2, file + ": ") == 0
                         ? message.c_str() + file.size() + 2
                         : message.c_str());
        failed = true;
        continue;
      }
      loaded = std::move(result->mesh);
      mesh = &loaded;
    }
    const auto t0 = std::chrono::steady_clock::now();
    PhaseSeconds phases;
    auto meshRows = runMesh(source.name, *mesh, o, hand, box, builders, threads, progress, phases);
    if (!meshRows) {
      std::fprintf(stderr, "autograsp-bench: skipping %s: %s\n",
                   source.path ? source.path->string().c_str() : source.name.c_str(),
                   meshRows.error().message.c_str());
      failed = true;
      continue;
    }
    for (Row& r : *meshRows) {
      failed = failed || r.failedSolves > 0;
      rows.push_back(std::move(r));
    }
    std::fprintf(stderr,
                 "%s: %zu triangles, done in %.1f s (placements + solves %.1f s, grading %.1f s)\n",
                 source.name.c_str(), mesh->triangleCount(),
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
                 phases.solve, phases.grade);
  }

  printTables(o, rows);
  if (!o.report.empty() && o.json.empty()) o.json = bench::reportResultsPath(o.report).string();
  if (!o.json.empty() && !writeJson(o.json, o, rows)) {
    std::fprintf(stderr, "autograsp-bench: cannot write %s\n", o.json.c_str());
    failed = true;
  }
  if (o.scaling) {
    const int code = reportExitCode(bench::runReport(bench::ReportRequest{
        o.report, o.json, bench::shellCommandLine(argc, argv), threads, o.scalingQuick,
        o.resolution, sharedMeshesDir(), scalingBackends, o.scalingJson, o.scalingFrom}));
    failed = failed || code == 1;
    backendMissing = backendMissing || code == kExitBackendUnavailable;
  }
  return failed ? 1 : backendMissing ? kExitBackendUnavailable : 0;
}
