// The bench report renders what the JSON holds: a metric it has never heard of becomes a column
// and a figure, the commit the JSON recorded goes into the header (or that it recorded none); a
// broken JSON is an error that names the file, not a crash.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "build_info.h"
#include "report.h"

namespace fs = std::filesystem;

namespace {

std::string readAll(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("sdfg_bench_report_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

}  // namespace

TEST_CASE("The report renders every JSON metric, known or not", "[bench][report]") {
  const fs::path dir = scratch("generic");
  const fs::path json = dir / "in.json";
  std::ofstream(json) << R"({"placements": 2, "seed": 7, "rows": [
    {"mesh": "cube", "triangles": 12, "method": "paper", "sdf_backend": "cpu", "grasps": 2,
     "sdf_build_ms": {"median": 1.5, "p95": 2}, "solve_us": {"median": 2.25, "p95": 3},
     "tip_residual_mm": {"median": null, "p95": null}, "contact_residual_mm": {"median": 0.125},
     "pass_through": 3, "note": "text is not a column", "contact_fingers": [1, 2, 0, 1, 1]},
    {"mesh": "cube", "triangles": 12, "method": "ours", "sdf_backend": "cpu", "grasps": 2,
     "sdf_build_ms": {"median": 1.5, "p95": 2}, "solve_us": {"median": 40, "p95": 50},
     "tip_residual_mm": {"median": 0.5, "p95": 0.75}, "contact_residual_mm": {"median": 0.0625},
     "pass_through": 0},
    {"mesh": "cube", "triangles": 12, "method": "paper", "sdf_backend": "cpu", "grasps": 1,
     "solve_us": {"median": 9, "p95": 9}, "pass_through": 1}]})";
  fs::create_directories(dir / "out");
  std::ofstream(dir / "out" / "benchmarks-notes.md") << "## Notes\n\nWritten by hand.\n";
  sdfg::bench::ReportRequest request;
  request.dir = dir / "out";
  request.resultsJson = json;
  request.commandLine = "autograsp-bench --report out";
  request.threads = 1;
  REQUIRE_FALSE(sdfg::bench::writeReport(request, nullptr).has_value());
  const std::string md = readAll(request.dir / "benchmarks.md");
  REQUIRE_FALSE(md.empty());

  SECTION("the command, the commits, the settings and the speed table") {
    CHECK(md.find("autograsp-bench --report out") != std::string::npos);
    CHECK(md.find("| run settings | placements 2, seed 7 |") != std::string::npos);
    // A JSON from before the bench recorded its commit says so; the writer's is this build's.
    CHECK(md.find("| commit of the figures (bench run) | not recorded: `" + json.string() +
                  "` was written before the bench recorded its commit |") != std::string::npos);
    CHECK(md.find("| commit of the report's writer | " + sdfg::tools::describeBuild() + " |") !=
          std::string::npos);
    CHECK(md.find("commit of the SDF scaling figures") == std::string::npos);  // no sweep
    CHECK(md.find("| paper | 2.25 |") != std::string::npos);
    CHECK(md.find("| ours | 40 |") != std::string::npos);
    CHECK(md.find("| CPU SDF build (ms) | 1.5 |") != std::string::npos);
  }
  SECTION("unknown metrics become columns, missing values a dash, text and arrays are left out") {
    CHECK(md.find("contact_residual_mm median") != std::string::npos);
    CHECK(md.find("pass_through") != std::string::npos);
    CHECK(md.find("| cube | paper | 2 | - | - | 0.125 | 3 |") != std::string::npos);
    CHECK(md.find("| cube | ours | 2 | 0.5 | 0.75 | 0.0625 | 0 |") != std::string::npos);
    CHECK(md.find("text is not a column") == std::string::npos);
    CHECK(md.find("contact_fingers") == std::string::npos);  // arrays: not a single figure
  }
  SECTION("the hand-written notes are copied in at the end") {
    CHECK(md.find("## Notes\n\nWritten by hand.\n") != std::string::npos);
    CHECK(md.find("## Notes") > md.find("## Quality"));
  }
  SECTION("a second mesh of the same name gets its own column") {
    CHECK(md.find("| method | cube | cube (2) |") != std::string::npos);
    CHECK(md.find("| paper | 2.25 | 9 |") != std::string::npos);
    CHECK(md.find("| ours | 40 | - |") != std::string::npos);
    CHECK(md.find("| cube (2) | paper | 1 |") != std::string::npos);
  }
  SECTION("each metric gets a data file for its figure") {
    CHECK(fs::exists(request.dir / "bench-data" / "contact_residual_mm.dat"));
    const std::string dat = readAll(request.dir / "bench-data" / "pass_through.dat");
    CHECK(dat.find("\"cube\" 3 0") != std::string::npos);
    CHECK(dat.find("\"cube (2)\" 1 NaN") != std::string::npos);
    CHECK(md.find("img/bench/pass_through.png") != std::string::npos);
  }
}

TEST_CASE("Rows of one method on two SDF backends get a backend column", "[bench][report]") {
  const fs::path dir = scratch("backends");
  const fs::path json = dir / "in.json";
  std::ofstream(json) << R"({"placements": 2,
    "provenance": {"commit": "0123abc", "tree_dirty": true}, "rows": [
    {"mesh": "cube", "triangles": 12, "method": "paper", "sdf_backend": "cpu", "grasps": 2,
     "sdf_build_ms": {"median": 1.5}, "solve_us": {"median": 2.25}, "pass_through": 3},
    {"mesh": "cube", "triangles": 12, "method": "paper", "sdf_backend": "vulkan", "grasps": 2,
     "sdf_build_ms": {"median": 40}, "solve_us": {"median": 2.5}, "pass_through": 4},
    {"mesh": "cube", "triangles": 12, "method": "physics-mesh", "sdf_backend": "none",
     "grasps": 2, "sdf_build_ms": {"median": null}, "solve_us": {"median": 90},
     "pass_through": 1}]})";
  sdfg::bench::ReportRequest request;
  request.dir = dir / "out";
  request.resultsJson = json;
  REQUIRE_FALSE(sdfg::bench::writeReport(request, nullptr).has_value());
  const std::string md = readAll(request.dir / "benchmarks.md");
  REQUIRE_FALSE(md.empty());

  SECTION("the commit the JSON recorded; its provenance is no setting") {
    CHECK(md.find("| commit of the figures (bench run) | 0123abc (modified: tracked files "
                  "differed from the commit) |") != std::string::npos);
    CHECK(md.find("| run settings | placements 2 |") != std::string::npos);
  }
  SECTION("the speed table: one row per method and backend, one build row per backend") {
    CHECK(md.find("| method | SDF backend | cube |") != std::string::npos);
    CHECK(md.find("| paper | cpu | 2.25 |") != std::string::npos);
    CHECK(md.find("| paper | vulkan | 2.5 |") != std::string::npos);
    CHECK(md.find("| physics-mesh | none | 90 |") != std::string::npos);
    CHECK(md.find("| SDF build (ms) | cpu | 1.5 |") != std::string::npos);
    CHECK(md.find("| SDF build (ms) | vulkan | 40 |") != std::string::npos);
  }
  SECTION("the quality table keeps both rows apart") {
    CHECK(md.find("| mesh | method | SDF backend | grasps | pass_through |") != std::string::npos);
    CHECK(md.find("| cube | paper | cpu | 2 | 3 |") != std::string::npos);
    CHECK(md.find("| cube | paper | vulkan | 2 | 4 |") != std::string::npos);
  }
  SECTION("the figures name the backend of each bar") {
    const std::string dat = readAll(request.dir / "bench-data" / "pass_through.dat");
    CHECK(dat.find("\"paper (cpu)\" \"paper (vulkan)\" \"physics-mesh\"") != std::string::npos);
    CHECK(dat.find("\"cube\" 3 4 1") != std::string::npos);
  }
}

TEST_CASE("A run with --scenes gets a Scenes table, one line per scene and method",
          "[bench][report]") {
  const fs::path dir = scratch("scenes");
  const fs::path json = dir / "in.json";
  std::ofstream(json) << R"({"placements": 2, "rows": [
    {"mesh": "cube", "triangles": 12, "method": "ours", "sdf_backend": "cpu", "grasps": 2,
     "sdf_build_ms": {"median": 1.5}, "solve_us": {"median": 40}, "pass_through": 0}],
    "scenes": [
    {"scene": "cube/table", "description": "a cube on a table", "objects": "cube, table",
     "method": "ours", "grasps": 2, "other_penetration_mm": {"p99": 0.25, "max": 0.5},
     "facing_graspable": 2, "wrong_object": 1, "held_nothing": 0, "contacts_mean": 4.5,
     "contact_residual_mm": {"median": 0.05, "p95": null}, "penetration_mm": {"max": 0.125},
     "early_stops": 0, "pass_through": 0},
    {"scene": "cube/table", "description": "a cube on a table", "objects": "cube, table",
     "method": "paper", "grasps": 2, "other_penetration_mm": {"p99": 30, "max": 31},
     "facing_graspable": 2, "wrong_object": 0, "held_nothing": 1, "contacts_mean": 5,
     "early_stops": 0, "pass_through": 7}]})";
  sdfg::bench::ReportRequest request;
  request.dir = dir / "out";
  request.resultsJson = json;
  REQUIRE_FALSE(sdfg::bench::writeReport(request, nullptr).has_value());
  const std::string md = readAll(request.dir / "benchmarks.md");
  CHECK(md.find("## Scenes") != std::string::npos);
  CHECK(md.find("| `cube/table` | ours | 2 | 0.25 | 0.5 | 1 / 2 | 0 | 4.5 | 0.05 | - | 0.125 | "
                "0 | 0 |") != std::string::npos);
  // The scene is named once; missing figures are "-".
  CHECK(md.find("|  | paper | 2 | 30 | 31 | 0 / 2 | 1 | 5 | - | - | - | 0 | 7 |") !=
        std::string::npos);
  CHECK(md.find("- `cube/table`: a cube on a table (cube, table)") != std::string::npos);
}

TEST_CASE("A run without --scenes has no Scenes table", "[bench][report]") {
  const fs::path dir = scratch("no_scenes");
  const fs::path json = dir / "in.json";
  std::ofstream(json) << R"({"placements": 2, "rows": [
    {"mesh": "cube", "triangles": 12, "method": "ours", "sdf_backend": "cpu", "grasps": 2,
     "sdf_build_ms": {"median": 1.5}, "solve_us": {"median": 40}, "pass_through": 0}]})";
  sdfg::bench::ReportRequest request;
  request.dir = dir / "out";
  request.resultsJson = json;
  REQUIRE_FALSE(sdfg::bench::writeReport(request, nullptr).has_value());
  CHECK(readAll(request.dir / "benchmarks.md").find("## Scenes") == std::string::npos);
}

TEST_CASE("A broken or missing JSON is an error naming the file", "[bench][report]") {
  const fs::path dir = scratch("broken");
  sdfg::bench::ReportRequest request;
  request.dir = dir / "out";
  SECTION("missing") {
    request.resultsJson = dir / "absent.json";
    const auto error = sdfg::bench::writeReport(request, nullptr);
    REQUIRE(error.has_value());
    CHECK(error->message.find("absent.json") != std::string::npos);
  }
  SECTION("truncated") {
    request.resultsJson = dir / "cut.json";
    std::ofstream(request.resultsJson) << R"({"rows": [{"mesh": "a", "solve_us": {"median": 1)";
    const auto error = sdfg::bench::writeReport(request, nullptr);
    REQUIRE(error.has_value());
    CHECK(error->message.find("cut.json") != std::string::npos);
  }
  SECTION("no rows") {
    request.resultsJson = dir / "empty.json";
    std::ofstream(request.resultsJson) << R"({"placements": 1})";
    const auto error = sdfg::bench::writeReport(request, nullptr);
    REQUIRE(error.has_value());
    CHECK(error->message.find("rows") != std::string::npos);
  }
}
