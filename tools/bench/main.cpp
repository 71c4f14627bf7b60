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

#include "evaluator.h"
#include "hand_model.h"
#include "mesh.h"
#include "mesh_distance.h"
#include "mesh_io.h"
#include "placements.h"
#include "report.h"
#include "sdf_cpu.h"
#include "sdf_grid.h"
#include "shapes.h"
#include "solver.h"
#include "solver_physics.h"

namespace fs = std::filesystem;
using namespace sdfg;

namespace {

constexpr float kHandSizeDiagonal = 0.18f;  // metres: every object is scaled to this bbox diagonal
constexpr double kSolveBatchTargetUs = 50.0;  // a timed batch lasts at least this long
constexpr int kSolveRepeats = 3;              // per-solve time = min over this many batches

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
    "  --threads N        worker threads for SDF builds and grading (default: all cores)\n"
    "  --thin-plate-set   only the embedded thin plate, graded on the placements where\n"
    "                     \"paper\" (added if missing; --da must be 0.1) passes through it\n"
    "  --json FILE        write the results as JSON\n"
    "  --report DIR       also write DIR/benchmarks.md with tables and plots (gnuplot) of this\n"
    "                     run, DIR/img/bench/*.png and DIR/bench-data/; implies --scaling\n"
    "  --scaling          also time the CPU SDF build against triangles and resolution\n"
    "  --scaling-quick    --scaling on small spheres only (tests)\n"
    "  --report-from FILE with --report: write the report from a JSON an earlier run wrote\n"
    "                     (with --json) instead of running the meshes again\n"
    "  --help             this text\n";

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
  std::string json;
  std::string report;
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
  const std::vector<std::string> known = solverNames();
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
      if (auto e = needValue(v)) return e;
      o.methods.clear();
      std::stringstream ss(v);
      std::string m;
      while (std::getline(ss, m, ',')) {
        if (m.empty()) continue;
        if (std::find(known.begin(), known.end(), m) == known.end()) {
          std::string list;
          for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
          return UsageError{"--methods: unknown method \"" + m + "\"; known: " + list};
        }
        if (std::find(o.methods.begin(), o.methods.end(), m) == o.methods.end()) {
          o.methods.push_back(m);
        }
      }
      if (o.methods.empty()) return UsageError{"--methods: no method given"};
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
    } else if (arg == "--threads") {
      if (auto e = needValue(v)) return e;
      if (!parseInt(v, 0, 1024, n)) return UsageError{"--threads: \"" + v + "\" is not 0..1024"};
      o.threads = unsigned(n);
    } else if (arg == "--json") {
      if (auto e = needValue(v)) return e;
      if (v.empty()) return UsageError{"--json: empty file name"};
      o.json = v;
    } else if (arg == "--report") {
      if (auto e = needValue(v)) return e;
      if (v.empty()) return UsageError{"--report: empty folder name"};
      o.report = v;
      o.scaling = true;
    } else if (arg == "--report-from") {
      if (auto e = needValue(v)) return e;
      if (v.empty()) return UsageError{"--report-from: empty file name"};
      o.reportFrom = v;
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

// Returns the rows of this mesh, or an error naming what failed.
Result<std::vector<Row>> runMesh(const std::string& name, const TriangleMesh& original,
                                 const Options& o, const HandModel& hand, const GridBox& box,
                                 CpuSdfBuilder& builder, unsigned threads, const Progress& progress,
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
    auto solver = createSolver(m);
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

  std::vector<Row> rows(methods.size());
  for (size_t m = 0; m < methods.size(); ++m) {
    rows[m].mesh = name;
    rows[m].triangles = mesh.triangleCount();
    rows[m].method = methods[m].name;
    rows[m].usesField = methods[m].solver->needsField();
  }
  // results[m][p]; solved[m][p] says whether the solve succeeded.
  std::vector<std::vector<GraspResult>> results(methods.size(),
                                                std::vector<GraspResult>(placements.size()));
  std::vector<std::vector<char>> solved(methods.size(), std::vector<char>(placements.size(), 0));
  std::optional<Error> firstFailure;

  SdfGrid grid(box);
  for (size_t p = 0; p < placements.size(); ++p) {
    progress.show(name, "solve", p, placements.size());
    const Placement& placement = placements[p];
    GraspScene scene;
    scene.objectFromHand = placement.objectFromHand;
    // "ours" checks its stops on the exact distance of the same mesh the SDF is built from.
    const MeshExactSource exactSource(**distance, placement.objectFromHand);
    scene.exact = &exactSource;
    if (anyField) {
      const auto t0 = now();
      const Status s = builder.build(**distance, placement.objectFromHand, box, grid);
      const double ms = std::chrono::duration<double, std::milli>(now() - t0).count();
      if (s != Status::ok) return makeError(s, "CPU SDF build failed");
      for (size_t m = 0; m < methods.size(); ++m) {
        if (rows[m].usesField) rows[m].sdfBuildMs.push_back(ms);
      }
      scene.field = &grid;
    }
    for (size_t m = 0; m < methods.size(); ++m) {
      scene.collider = methods[m].collider.get();
      Status s = Status::ok;
      double checkUs = 0.0;
      const double us = timeSolveUs(*methods[m].solver, scene, results[m][p], s, now, checkUs);
      if (s != Status::ok) {
        rows[m].failedSolves++;
        if (!firstFailure) {
          firstFailure = makeError(s, methods[m].name + ": solve failed on placement " +
                                          std::to_string(p) + " (" + toString(s) + ")");
        }
        continue;
      }
      solved[m][p] = 1;
      rows[m].solveUs.push_back(us);
      if (results[m][p].exactSamples > 0 || !rows[m].checkUs.empty()) {
        rows[m].checkUs.push_back(checkUs);
        rows[m].exactSamples += results[m][p].exactSamples;
      }
    }
  }

  const auto solvedAt = now();
  std::vector<GraspMetrics> metrics(methods.size() * placements.size());
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
    size_t paper = 0;
    while (paper < methods.size() && methods[paper].name != "paper") ++paper;
    size_t count = 0;
    for (size_t p = 0; p < placements.size(); ++p) {
      selected[p] = paper < methods.size() && solved[paper][p] &&
                    metrics[paper * placements.size() + p].passThroughs > 0;
      count += selected[p] ? 1 : 0;
    }
    std::fprintf(stderr, "%s: %zu of %zu placements where paper passes through\n", name.c_str(),
                 count, placements.size());
    for (Row& row : rows) row.mesh = name + "/paper-skips";
  }
  for (size_t m = 0; m < methods.size(); ++m) {
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

std::string jsonString(const std::string& s) {
  std::string out = "\"";
  for (unsigned char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (c < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out += buf;
        } else {
          out += char(c);
        }
    }
  }
  return out + "\"";
}

std::string jsonNumber(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// Per-finger counts, thumb to little.
std::string jsonCounts(const std::array<long long, kFingerCount>& counts) {
  std::string out = "[";
  for (int f = 0; f < kFingerCount; ++f) out += (f ? ", " : "") + std::to_string(counts[f]);
  return out + "]";
}

bool writeJson(const std::string& file, const Options& o, const std::vector<Row>& rows) {
  std::ofstream out(file);
  if (!out) return false;
  out << "{\n  \"placements\": " << o.placements << ",\n  \"da\": " << jsonNumber(o.da)
      << ",\n  \"resolution\": " << o.resolution << ",\n  \"seed\": " << o.seed
      << ",\n  \"rows\": [";
  for (size_t i = 0; i < rows.size(); ++i) {
    const Row& r = rows[i];
    const double nan = std::nan("");
    const double buildMedian = r.usesField ? percentile(r.sdfBuildMs, 0.5) : nan;
    const double buildP95 = r.usesField ? percentile(r.sdfBuildMs, 0.95) : nan;
    out << (i ? ",\n" : "\n") << "    {\"mesh\": " << jsonString(r.mesh)
        << ", \"triangles\": " << r.triangles << ", \"method\": " << jsonString(r.method)
        << ", \"sdf_backend\": " << jsonString(r.usesField ? "cpu" : "none")
        << ", \"grasps\": " << r.grasps
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
  std::vector<std::string> meshes;
  for (const Row& r : rows) {
    if (std::find(meshes.begin(), meshes.end(), r.mesh) == meshes.end()) meshes.push_back(r.mesh);
  }
  auto find = [&](const std::string& mesh, const std::string& method) -> const Row* {
    for (const Row& r : rows) {
      if (r.mesh == mesh && r.method == method) return &r;
    }
    return nullptr;
  };
  size_t width = 10;
  for (const auto& m : meshes) width = std::max(width, m.size() + 1);

  std::printf(
      "\nSolve time per grasp, median of %d placements, microseconds (paper Table 1: "
      "ms; SDF build not included)\n",
      o.placements);
  std::printf("%-22s", "method");
  for (const auto& m : meshes) std::printf(" %*s", int(width), m.c_str());
  std::printf("\n");
  for (const auto& method : o.methods) {
    std::printf("%-22s", method.c_str());
    for (const auto& m : meshes) {
      const Row* r = find(m, method);
      std::printf(" %*s", int(width), r ? fmt(percentile(r->solveUs, 0.5), "%.2f").c_str() : "-");
    }
    std::printf("\n");
    bool anyCheck = false;
    for (const auto& m : meshes) {
      const Row* r = find(m, method);
      anyCheck = anyCheck || (r && !r->checkUs.empty());
    }
    if (!anyCheck) continue;
    // The exact check's share of the solve above (GraspScene::exact), median per grasp.
    std::printf("%-22s", ("  " + method + " check").c_str());
    for (const auto& m : meshes) {
      const Row* r = find(m, method);
      std::printf(
          " %*s", int(width),
          r && !r->checkUs.empty() ? fmt(percentile(r->checkUs, 0.5), "%.2f").c_str() : "-");
    }
    std::printf("\n");
  }
  std::printf("%-22s", "cpu sdf build (ms)");
  for (const auto& m : meshes) {
    std::string cell = "-";
    for (const auto& method : o.methods) {
      const Row* r = find(m, method);
      if (r && r->usesField) {
        cell = fmt(percentile(r->sdfBuildMs, 0.5), "%.2f");
        break;
      }
    }
    std::printf(" %*s", int(width), cell.c_str());
  }
  std::printf("\n%-22s", "triangles");
  for (const auto& m : meshes) {
    const Row* r = find(m, o.methods.front());
    std::printf(" %*zu", int(width), r ? r->triangles : size_t(0));
  }
  std::printf(
      "\n\nQuality against the exact mesh (tip residual over fingers in contact; "
      "penetration over grasps)\n");
  std::printf("%-24s %-16s %6s %9s %9s %9s %9s %9s %9s %7s %8s %6s %5s\n", "mesh", "method",
              "grasps", "tip_med", "tip_p95", "cres_med", "cres_p95", "pen_p99", "pen_max", "early",
              "contacts", "tip%", "pass");
  for (const auto& m : meshes) {
    for (const auto& method : o.methods) {
      const Row* r = find(m, method);
      if (!r) continue;
      long long inContact = 0, tipContact = 0;
      for (int f = 0; f < kFingerCount; ++f) {
        inContact += r->contactFingers[f];
        tipContact += r->tipContactFingers[f];
      }
      std::printf(
          "%-24s %-16s %6d %9s %9s %9s %9s %9s %9s %7d %8s %6s %5lld\n", m.c_str(), method.c_str(),
          r->grasps, fmt(percentile(r->tipResidualMm, 0.5)).c_str(),
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
      "whose closing sweep put a sphere centre inside the mesh)\n");

  const std::string base = "paper";
  if (std::find(o.methods.begin(), o.methods.end(), base) == o.methods.end()) return;
  std::printf("\nRatios against \"paper\", same placements (solve time x; early stops x)\n");
  std::printf("%-24s %-16s %10s %12s\n", "mesh", "method", "solve", "early stops");
  for (const auto& m : meshes) {
    const Row* p = find(m, base);
    if (!p) continue;
    for (const auto& method : o.methods) {
      if (method == base) continue;
      const Row* r = find(m, method);
      if (!r) continue;
      const double solve = percentile(r->solveUs, 0.5) / percentile(p->solveUs, 0.5);
      const std::string early = p->earlyStops > 0
                                    ? fmt(double(r->earlyStops) / p->earlyStops, "%.2f")
                                    : std::to_string(r->earlyStops) + " vs 0";
      std::printf("%-24s %-16s %10s %12s\n", m.c_str(), method.c_str(), fmt(solve, "%.2f").c_str(),
                  early.c_str());
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
  if (!o.reportFrom.empty()) {
    // A long run's results, reported again (new plots, new notes) without solving again.
    const bool ok = bench::runReport(
        bench::ReportRequest{o.report, o.reportFrom, bench::shellCommandLine(argc, argv), threads,
                             o.scalingQuick, o.resolution, sharedMeshesDir()});
    return ok ? 0 : 1;
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
  CpuSdfBuilder builder(threads);
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
    auto meshRows = runMesh(source.name, *mesh, o, hand, box, builder, threads, progress, phases);
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
                 source.name.c_str(), rows.back().triangles,
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
                 phases.solve, phases.grade);
  }

  printTables(o, rows);
  if (!o.report.empty() && o.json.empty()) o.json = bench::reportResultsPath(o.report).string();
  if (!o.json.empty() && !writeJson(o.json, o, rows)) {
    std::fprintf(stderr, "autograsp-bench: cannot write %s\n", o.json.c_str());
    failed = true;
  }
  if (o.scaling && !bench::runReport(bench::ReportRequest{
                       o.report, o.json, bench::shellCommandLine(argc, argv), threads,
                       o.scalingQuick, o.resolution, sharedMeshesDir()})) {
    failed = true;
  }
  return failed ? 1 : 0;
}
