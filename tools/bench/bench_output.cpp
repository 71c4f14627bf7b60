#include "bench_output.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "json_file.h"

namespace sdfg::bench {
namespace {

std::string fmt(double v, const char* format = "%.3g") {
  if (!std::isfinite(v)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

// {"median": .., "p95": ..} and the like: the given percentiles of `v`, by name.
tools::Json percentiles(const std::vector<double>& v,
                        std::initializer_list<std::pair<const char*, double>> which) {
  tools::Json out = tools::Json::object();
  for (const auto& [name, q] : which) out[name] = tools::jsonNumber(percentile(v, q));
  return out;
}

}  // namespace

tools::Json resultsJson(const Options& o, const std::vector<Row>& rows) {
  using tools::Json;
  using tools::jsonNumber;
  Json out;
  out["placements"] = o.placements;
  out["da"] = jsonNumber(o.da);
  out["resolution"] = o.resolution;
  out["seed"] = o.seed;
  out["exact_check"] = o.exactCheck;
  // Only with --variants, so a run without keeps its JSON as before.
  if (!o.variants.empty()) out["variants"] = o.variants;
  out["provenance"] = tools::provenanceJson();
  Json& rowsOut = out["rows"] = Json::array();
  const std::initializer_list<std::pair<const char*, double>> medianP95 = {{"median", 0.5},
                                                                           {"p95", 0.95}};
  for (const Row& r : rows) {
    Json row;
    row["mesh"] = r.mesh;
    row["triangles"] = r.triangles;
    row["method"] = r.method;
    row["sdf_backend"] = r.backend;
    row["grasps"] = r.grasps;
    // Physics methods build no field: their build times are null.
    row["sdf_build_ms"] =
        percentiles(r.usesField ? r.sdfBuildMs : std::vector<double>{}, medianP95);
    row["solve_us"] = percentiles(r.solveUs, medianP95);
    if (!r.checkUs.empty()) {
      row["check_us"] = percentiles(r.checkUs, medianP95);
      row["exact_samples_mean"] = jsonNumber(double(r.exactSamples) / double(r.checkUs.size()));
    }
    row["tip_residual_mm"] = percentiles(r.tipResidualMm, medianP95);
    row["contact_residual_mm"] = percentiles(r.contactResidualMm, medianP95);
    // Per finger, thumb to little.
    row["contact_fingers"] = r.contactFingers;
    row["tip_contact_fingers"] = r.tipContactFingers;
    row["pass_through"] = r.passThroughs;
    row["penetration_mm"] = percentiles(r.penetrationMm, {{"p99", 0.99}, {"max", 1.0}});
    row["early_stops"] = r.earlyStops;
    row["contacts_mean"] = jsonNumber(r.contactsMean());
    rowsOut.push_back(std::move(row));
  }
  return out;
}

bool writeJson(const std::string& file, const Options& o, const std::vector<Row>& rows,
               const std::vector<SceneRow>& sceneRows, const std::vector<SceneRow>& bufferRows) {
  tools::Json out = resultsJson(o, rows);
  if (o.scenes) out["scenes"] = scenesJson(sceneRows);
  if (!bufferRows.empty()) out["buffer_targets"] = scenesJson(bufferRows);
  return !tools::writeJsonFile(file, out).has_value();
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

}  // namespace sdfg::bench
