// autograsp-bench's measurement of one mesh: its placements, the timed SDF builds and solves of
// every strategy, and the grading of each grasp against the exact surface (eval/evaluator.h),
// gathered into one Row per strategy and SDF builder. Also where the meshes come from.
#pragma once

#include <array>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <unistd.h>

#include "base/status.h"
#include "bench_options.h"
#include "grasp/solver.h"
#include "hand/hand_model.h"
#include "mesh/mesh.h"
#include "sdf/sdf_grid.h"
#include "sdf_backends.h"

namespace sdfg::bench {

namespace fs = std::filesystem;

// Linear interpolation between order statistics; NaN for an empty sample.
double percentile(std::vector<double> v, double q);

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
  // --approaching, per grasp: the whole hand's deepest point inside (eval/approaching.h), how
  // far the strategy moved the hand (GraspResult::handMoved), mm; whether the open hand was
  // already inside; fingers touching.
  std::vector<double> handPenetrationMm;
  std::vector<double> handMovedMm;
  std::vector<char> openInside;
  std::vector<int> graspContacts;
  std::vector<char> pastBound;  // the hand needed more than the clearance's bound: not moved

  double contactsMean() const { return grasps > 0 ? double(contacts) / grasps : std::nan(""); }
};

struct MeshSource {
  std::string name;
  std::optional<fs::path> path;
  TriangleMesh embedded;
};

// ../shared/meshes (or $SDFG_SHARED_MESHES), when present.
std::optional<fs::path> sharedMeshesDir();
// Every *.obj / *.ply of the folder, sorted; a stem present in both formats (the dragon) is kept
// once, as .ply (the original the .obj was converted from).
std::vector<fs::path> defaultMeshFiles(const fs::path& dir);

// A progress bar on stderr, when it is a terminal.
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

struct PhaseSeconds {
  double solve = 0.0;  // placements, SDF builds and timed solves
  double grade = 0.0;  // evaluation against the exact mesh
};

// Returns the rows of this mesh, or an error naming what failed: one row per physics method, one
// per SDF method and builder (every builder builds the field of every placement; the SDF methods
// solve on each in turn). With a `reference` (--variants: the mesh `original` is a variant of),
// the strategies read `original` (fields, exact check, colliders) while the placements and the
// grading come from the reference, both scaled by the reference's bounds (normalizedLike()).
Result<std::vector<Row>> runMesh(const std::string& name, const TriangleMesh& original,
                                 const Options& o, const HandModel& hand, const GridBox& box,
                                 const std::vector<tools::TimedSdfBuilder*>& builders,
                                 unsigned threads, const Progress& progress,
                                 PhaseSeconds& phaseSeconds,
                                 const TriangleMesh* reference = nullptr);

}  // namespace sdfg::bench
