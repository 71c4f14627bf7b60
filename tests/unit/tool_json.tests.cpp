// The tools' JSON files are written by a JSON library, so any string they carry reads back as it
// was (the hand-written frame-cost writer once wrote quotes and newlines raw, and its files did
// not parse), and every results file records the commit of the code that wrote it.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "bench_output.h"
#include "build_info.h"
#include "json_file.h"
#include "results.h"

namespace fs = std::filesystem;
using sdfg::tools::Json;

namespace {

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("sdfg_tool_json_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// Quotes, a backslash, control characters, two- to four-byte UTF-8.
const std::vector<std::string> kAwkward = {
    "say \"hi\"",
    "C:\\meshes\\mug.obj",
    "two\nlines\r\n",
    "tab\there\x01\x1f",
    "caf\xc3\xa9 \xe6\x97\xa5\xe6\x9c\xac \xf0\x9f\x96\x90",
    "}, \"rows\": [",
    "",
};

// The file as a JSON library reads it back.
Json readBack(const fs::path& file) {
  auto json = sdfg::tools::readJsonFile(file);
  INFO((json ? std::string() : json.error().message));
  REQUIRE(json);
  return *json;
}

// The provenance record is this build's.
void checkProvenance(const Json& file) {
  REQUIRE(file.contains("provenance"));
  const Json& p = file["provenance"];
  CHECK(p["commit"] == sdfg::tools::buildCommit());
  switch (sdfg::tools::buildTreeState()) {
    case sdfg::tools::TreeState::clean:
      CHECK(p["tree_dirty"] == false);
      break;
    case sdfg::tools::TreeState::dirty:
      CHECK(p["tree_dirty"] == true);
      break;
    case sdfg::tools::TreeState::unknown:
      CHECK(p["tree_dirty"].is_null());
      break;
  }
}

}  // namespace

TEST_CASE("The bench's JSON reads back every string as written", "[tools][json]") {
  using namespace sdfg::bench;
  const fs::path dir = scratch("bench");
  Options o;
  o.placements = 2;
  o.seed = std::numeric_limits<uint64_t>::max();
  std::vector<Row> rows;
  for (const std::string& s : kAwkward) {
    Row r;
    r.mesh = s;
    r.method = "method " + s;
    r.backend = s;
    r.usesField = true;
    r.grasps = 2;
    r.sdfBuildMs = {1.5, 2.5};
    r.solveUs = {3.0, 4.0};
    rows.push_back(r);
  }
  REQUIRE(writeJson((dir / "bench.json").string(), o, rows));
  const Json json = readBack(dir / "bench.json");

  SECTION("strings") {
    REQUIRE(json["rows"].size() == kAwkward.size());
    for (size_t i = 0; i < kAwkward.size(); ++i) {
      CAPTURE(i);
      CHECK(json["rows"][i]["mesh"] == kAwkward[i]);
      CHECK(json["rows"][i]["method"] == "method " + kAwkward[i]);
      CHECK(json["rows"][i]["sdf_backend"] == kAwkward[i]);
    }
  }
  SECTION("numbers, and null where there is no figure") {
    CHECK(json["seed"] == std::numeric_limits<uint64_t>::max());
    CHECK(json["da"].get<double>() == 0.1);  // written as 0.1, not as the float's 0.100000001
    const Json& row = json["rows"][0];
    CHECK(row["sdf_build_ms"]["median"].get<double>() == 2.0);
    CHECK(row["solve_us"]["p95"].get<double>() == Approx(3.95));
    CHECK(row["tip_residual_mm"]["median"].is_null());
    CHECK(row["contacts_mean"].get<double>() == 0.0);
  }
  SECTION("the commit of the code that wrote it") {
    checkProvenance(json);
  }
}

TEST_CASE("The frame-cost JSON reads back every string as written", "[tools][json]") {
  using namespace sdfg::frame_cost;
  const fs::path dir = scratch("frame_cost");
  std::vector<MeshResult> results;
  for (const std::string& s : kAwkward) {
    MeshResult r;
    r.name = s;
    r.triangles = 12;
    r.error = "layer on: " + s;
    r.on.callMs[s] = {0.25, 0.5};
    r.on.grabLatencyFrames = 3;
    r.added[1] = percentiles({0.125, 0.25, 1.0});
    results.push_back(r);
  }
  REQUIRE_FALSE(
      sdfg::tools::writeJsonFile(dir / "fc.json", resultsJson(results, 5, 11.111111, kAwkward)));
  const Json json = readBack(dir / "fc.json");

  SECTION("strings") {
    CHECK(json["skipped"] == Json(kAwkward));
    REQUIRE(json["meshes"].size() == kAwkward.size());
    for (size_t i = 0; i < kAwkward.size(); ++i) {
      CAPTURE(i);
      const Json& m = json["meshes"][i];
      CHECK(m["name"] == kAwkward[i]);
      CHECK(m["error"] == "layer on: " + kAwkward[i]);
      REQUIRE(m["calls_on"].contains(kAwkward[i]));
      CHECK(m["calls_on"][kAwkward[i]]["max_ms"].get<double>() == 0.5);
    }
  }
  SECTION("numbers, in the members docs and plot.sh read") {
    CHECK(json["frames_per_phase"] == 5);
    CHECK(json["frame_period_ms"].get<double>() == 11.111111);
    const Json& grab = json["meshes"][0]["phases"]["grab"];
    CHECK(grab["frames"] == 3);
    CHECK(grab["added_p50_ms"].get<double>() == 0.25);
    CHECK(grab["added_max_ms"].get<double>() == 1.0);
    CHECK(json["meshes"][0]["grab_latency_frames"] == 3);
  }
  SECTION("the commit of the code that wrote it") {
    checkProvenance(json);
  }
}

TEST_CASE("JSON files: bad bytes and bad files are handled, not fatal", "[tools][json]") {
  const fs::path dir = scratch("edge");
  SECTION("a string that is not UTF-8 is written with U+FFFD in place of the bad byte") {
    Json value;
    value["name"] = std::string("mug\xe9.obj");  // Latin-1, as an old file name might be
    REQUIRE_FALSE(sdfg::tools::writeJsonFile(dir / "latin1.json", value));
    CHECK(readBack(dir / "latin1.json")["name"] == "mug\xef\xbf\xbd.obj");
  }
  SECTION("numbers: doubles exactly, floats in their shortest form, null when not finite") {
    CHECK(sdfg::tools::jsonNumber(std::nan("")).is_null());
    CHECK(sdfg::tools::jsonNumber(std::numeric_limits<double>::infinity()).is_null());
    CHECK(sdfg::tools::jsonNumber(-std::numeric_limits<float>::infinity()).is_null());
    CHECK(sdfg::tools::jsonNumber(0.1f).dump() == "0.1");
    CHECK(sdfg::tools::jsonNumber(1e-7f).dump() == "1e-07");
    CHECK(sdfg::tools::jsonNumber(1234567.0).dump() == "1234567.0");
    // A timing that rounds differently at 3 digits once it is rounded to 6: it reads back as is.
    const double timing = 3.2150004364923;
    Json value;
    value["ms"] = sdfg::tools::jsonNumber(timing);
    REQUIRE_FALSE(sdfg::tools::writeJsonFile(dir / "exact.json", value));
    CHECK(readBack(dir / "exact.json")["ms"].get<double>() == timing);
  }
  SECTION("a truncated file is an error naming the file") {
    std::ofstream(dir / "cut.json") << R"({"rows": [{"mesh": "a)";
    const auto json = sdfg::tools::readJsonFile(dir / "cut.json");
    REQUIRE_FALSE(json);
    CHECK(json.error().message.find("cut.json") != std::string::npos);
    CHECK(json.error().message.find("parse error") != std::string::npos);
  }
  SECTION("a missing file is an error naming the file") {
    const auto json = sdfg::tools::readJsonFile(dir / "absent.json");
    REQUIRE_FALSE(json);
    CHECK(json.error().message.find("absent.json") != std::string::npos);
  }
  SECTION("provenance reads back as written; a file without it has none") {
    CHECK(sdfg::tools::describeProvenance(sdfg::tools::provenanceJson()) ==
          sdfg::tools::describeBuild());
    CHECK_FALSE(sdfg::tools::describeProvenance(Json()).has_value());
    CHECK(sdfg::tools::describeProvenance(Json{{"commit", "abc"}, {"tree_dirty", true}}) ==
          "abc (modified: tracked files differed from the commit)");
  }
}
