// autograsp-bench --report / --scaling: the Markdown report with plots, and the SDF build sweep.
//
// The report reads the bench's JSON (the file --json writes), not its in-memory rows, so a metric
// added to the JSON later shows up in the tables and plots without a change here: every key of a
// row other than the identity and speed ones becomes a quality column (an object such as
// {"median", "p95"} becomes one column per member); rows of one method with different
// `sdf_backend`s get a backend column. The scaling sweep times the grab-box SDF builders (CPU and
// Vulkan side by side, tools/common/sdf_backends.h) on their own: against triangle count (at the
// bench's resolution) and against grid resolution (on one mesh), median of a few seeded
// placements each, as a whole grid in CPU memory and as the frame path (build + 50 samples). Plots
// are drawn by gnuplot (Debian's gnuplot-nox, pngcairo terminal) from .dat / .gp files written
// beside the results; without gnuplot the Markdown is still written and the message says why there
// are no images.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "base/pose.h"
#include "base/status.h"
#include "json_file.h"
#include "mesh/mesh.h"
#include "mesh/mesh_distance.h"
#include "sdf/sdf_grid.h"
#include "sdf_backends.h"

namespace sdfg::bench {

// The builders the sweep compares, one per name of `backends` ("cpu", "vulkan"; see
// tools/common/sdf_backends.h), in that order; the first is the reference the speed-ups are taken
// against. A backend that cannot be made (no Vulkan device) is left out and named, with the
// reason, in `unavailable`.
struct ScalingBuilders {
  std::vector<std::unique_ptr<tools::TimedSdfBuilder>> builders;
  std::vector<std::string> unavailable;  // "vulkan: no Vulkan device: ..."
};
ScalingBuilders makeScalingBuilders(const std::vector<std::string>& backends, unsigned threads);

struct ScalingOptions {
  bool quick = false;    // small tori and resolutions only (tests): seconds, not minutes
  int repeats = 5;       // placements per point; the figure is the median build time
  int resolution = 16;   // grid nodes per axis of the triangle sweep
  unsigned threads = 0;  // CPU builder threads (0: all cores)
  std::vector<std::string> backends = {"cpu", "vulkan"};  // side by side, first = reference
  // Folder of the shared test meshes, swept after the tori (5k..400k triangles) when present.
  std::optional<std::filesystem::path> sharedMeshes;
};

struct ScalingPoint {
  std::string mesh;
  size_t triangles = 0;
  int resolution = 0;
  double prepareMs = 0.0;  // MeshDistance::create, once per mesh
  // Medians per builder, same order as ScalingResults::builders: the whole grid in CPU memory
  // (TimedSdfBuilder::build), and the frame path, build + 50 samples (buildAndSample).
  std::vector<double> buildMs;
  std::vector<double> buildSampleMs;
};

struct ScalingResults {
  std::vector<std::string> builders;     // backend names, "cpu", "vulkan"
  std::vector<std::string> devices;      // per builder: "2 threads", the Vulkan device's name
  std::vector<std::string> unavailable;  // backends asked for but left out, with the reason
  int repeats = 0;
  std::vector<ScalingPoint> byTriangles;   // sorted by triangle count
  std::vector<ScalingPoint> byResolution;  // one mesh (the ~100k torus), rising resolution
  // The build that ran the sweep (json_file.h: provenanceJson()); null when it was read from a
  // JSON written before the bench recorded it.
  tools::Json provenance;
};

// Runs both sweeps; progress lines go to stderr. Errors name the mesh or builder that failed; a
// backend that cannot be made is not an error (see ScalingResults::unavailable).
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
  std::vector<std::string> backends = {"cpu", "vulkan"};  // ScalingOptions::backends
  std::filesystem::path scalingJson;                      // when set, writeScalingJson() there
  std::filesystem::path scalingFrom;  // when set, the sweep is read from there (readScalingJson)
};

enum class ReportStatus {
  ok,
  failed,               // the error is printed: a failed sweep, unreadable JSON, unwritable folder
  backend_unavailable,  // all written, but a backend of the sweep was left out (printed, noted)
};

// Runs the scaling sweep, prints its tables, and writes the report when `dir` is set. A missing
// or failing gnuplot is not an error: a note goes to stderr and into the Markdown.
ReportStatus runReport(const ReportRequest& request);

// The report alone, from the JSON and (optionally) a sweep already run; errors as runReport().
std::optional<Error> writeReport(const ReportRequest& request, const ScalingResults* scaling);

// The sweep as JSON: backends, devices, unavailable, repeats, provenance (when known), and
// by_triangles / by_resolution points {mesh, triangles, resolution, setup_ms, build_ms {backend:
// ms}, build_sample_ms {...}}.
// Errors: io_error naming the file.
std::optional<Error> writeScalingJson(const std::filesystem::path& file,
                                      const ScalingResults& results);

// A sweep written by writeScalingJson(). Errors: io_error naming the file and the problem.
Result<ScalingResults> readScalingJson(const std::filesystem::path& file);

// Where --report puts the bench's JSON when --json is not given (creates the folder).
std::filesystem::path reportResultsPath(const std::filesystem::path& dir);

// argv as one shell line, quoting what needs it.
std::string shellCommandLine(int argc, char** argv);

}  // namespace sdfg::bench
