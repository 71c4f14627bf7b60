// autograsp-bench --report / --scaling: the Markdown report with plots, and the SDF build sweep.
//
// The report reads the bench's JSON (the file --json writes), not its in-memory rows, so a metric
// added to the JSON later shows up in the tables and plots without a change here: every key of a
// row other than the identity and speed ones becomes a quality column (an object such as
// {"median", "p95"} becomes one column per member). The scaling sweep times the grab-box SDF
// builders on their own: against triangle count (at the bench's resolution) and against grid
// resolution (on one mesh), median of a few seeded placements each. Plots are drawn by gnuplot
// (Debian's gnuplot-nox, pngcairo terminal) from .dat / .gp files written beside the results;
// without gnuplot the Markdown is still written and the message says why there are no images.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mesh.h"
#include "mesh_distance.h"
#include "pose.h"
#include "sdf_grid.h"
#include "status.h"

namespace sdfg::bench {

// One way to build the grab-box SDF, as timed by the sweep. prepare() runs once per mesh and is
// timed as set-up (BVH build, mesh upload); build() runs once per placement and is the figure.
class ScalingBuilder {
 public:
  virtual ~ScalingBuilder() = default;
  virtual std::string name() const = 0;  // column title: "CPU", "Vulkan"
  // `mesh` is the mesh already scaled to hand size; `distance` was built from it and outlives
  // every build() until the next prepare().
  virtual Status prepare(const TriangleMesh& mesh, const MeshDistance& distance) = 0;
  virtual Status build(const Pose& objectFromHand, const GridBox& box, SdfGrid& out) = 0;
};

// The builders the sweep compares; the first is the reference the speed-ups are taken against.
// Today the CPU builder (CpuSdfBuilder with `threads` workers) only. The Vulkan builder
// (GrabBoxSdf, src/vk_sdf_backend.h) plugs in here as a second entry: prepare() = setMesh(),
// build() = submit(box, pose, {}, true) + wait(); the tables and plots then gain its column and
// the CPU / Vulkan speed-up with no other change.
std::vector<std::unique_ptr<ScalingBuilder>> makeScalingBuilders(unsigned threads);

struct ScalingOptions {
  bool quick = false;    // small spheres and resolutions only (tests): seconds, not minutes
  int repeats = 5;       // placements per point; the figure is the median build time
  int resolution = 16;   // grid nodes per axis of the triangle sweep
  unsigned threads = 0;  // CPU builder threads (0: all cores)
  // Folder of the shared test meshes; when absent (or quick) spheres of 1k..330k triangles
  // stand in for them.
  std::optional<std::filesystem::path> sharedMeshes;
};

struct ScalingPoint {
  std::string mesh;
  size_t triangles = 0;
  int resolution = 0;
  double prepareMs = 0.0;       // MeshDistance::create, once per mesh
  std::vector<double> buildMs;  // median per builder, same order as ScalingResults::builders
};

struct ScalingResults {
  std::vector<std::string> builders;
  int repeats = 0;
  std::vector<ScalingPoint> byTriangles;   // sorted by triangle count
  std::vector<ScalingPoint> byResolution;  // one mesh, rising resolution
};

// Runs both sweeps; progress lines go to stderr. Errors name the mesh or builder that failed.
Result<ScalingResults> runScaling(const ScalingOptions& options);
void printScaling(const ScalingResults& results);

struct ReportRequest {
  std::filesystem::path dir;          // empty: scaling tables on stdout only, no report
  std::filesystem::path resultsJson;  // the bench's --json output, already written
  std::string commandLine;            // as typed, for the report's header
  unsigned threads = 0;               // as the bench used
  bool scalingQuick = false;          // ScalingOptions::quick
  int resolution = 16;                // the bench's grid resolution
  std::optional<std::filesystem::path> sharedMeshes;
};

// Runs the scaling sweep, prints its tables, and writes the report when `dir` is set. Returns
// false after printing the error (a failed sweep, unreadable JSON, unwritable folder); a missing
// or failing gnuplot is not an error: a note goes to stderr and into the Markdown.
bool runReport(const ReportRequest& request);

// The report alone, from the JSON and (optionally) a sweep already run; errors as runReport().
std::optional<Error> writeReport(const ReportRequest& request, const ScalingResults* scaling);

// Where --report puts the bench's JSON when --json is not given (creates the folder).
std::filesystem::path reportResultsPath(const std::filesystem::path& dir);

// argv as one shell line, quoting what needs it.
std::string shellCommandLine(int argc, char** argv);

}  // namespace sdfg::bench
