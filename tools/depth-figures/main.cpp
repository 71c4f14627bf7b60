// autograsp-depth-figures: what a hand grasps of objects it knows only through an app's depth.
//
// Each embedded object (io/shapes.h) stands on the benchmark's table (eval/scenes.h); a head
// 40 cm away, above and in front of it, sees the scene as a D24 depth image (512 x 512 pixels,
// 90 degrees); the hand reaches for seen surface points, palm from above and from the side
// (eval/depth_quality.h), and "ours" closes on the depth volume fused around it. Every finger is
// graded on the nearest true surface (the object's or the table's, CGAL's exact distance).
// Prints one row per object and reach; --json writes them with the build that made them.
//
// Deterministic for a seed: the placements are seeded, and nothing is timed.
#include <cstdio>
#include <set>
#include <string>
#include <vector>

#include "build_info.h"
#include "cli_options.h"
#include "eval/depth_quality.h"
#include "eval/scenes.h"
#include "grasp/solver.h"
#include "io/shapes.h"
#include "json_file.h"
#include "sdf/sdf_backend.h"

namespace {

using namespace sdfg;

const char* const kUsage =
    "usage: autograsp-depth-figures [--placements N] [--seed S] [--only NAME]... [--json FILE]\n"
    "  --placements N  reaches per object and kind (above, side); default 200\n"
    "  --seed S        seed of the placements (default 1)\n"
    "  --only NAME     only the embedded object NAME (repeatable): mug, torus, thin-plate\n"
    "  --json FILE     also write the figures as JSON, with the build that made them\n"
    "  --help          this text\n";

}  // namespace

int main(int argc, char** argv) {
  DepthQualityOptions options;
  std::vector<std::string> only;
  std::string json;
  CLI::App cli{"", "autograsp-depth-figures"};
  tools::cli::addInteger(cli, "--placements", options.placements, 1, 100000);
  tools::cli::addUnsigned64(cli, "--seed", options.seed);
  tools::cli::addRepeatable(cli, "--only", only);
  tools::cli::addName(cli, "--json", json, "file name");
  if (auto exit = tools::cli::parseOrUsage(cli, argc, argv, "autograsp-depth-figures", kUsage))
    return *exit;
  const std::set<std::string> wanted(only.begin(), only.end());
  const HandModel hand = HandModel::defaultAdult(Hand::right);
  const GridBox box = GridBox::referenceDefault();
  auto solver = createSolver("ours");
  if (!solver || (*solver)->prepare(hand, box, SolverOptions{}) != Status::ok) {
    std::fprintf(stderr, "autograsp-depth-figures: the solver cannot be prepared\n");
    return 1;
  }
  const std::unique_ptr<SdfBackend> backend = makeCpuSdfBackend(1);

  std::printf("%-12s %-6s %7s %6s %9s %9s %9s %9s\n", "object", "reach", "reaches", "made",
              "pen p99", "pen max", "res med", "res p95");
  tools::Json rows = tools::Json::array();
  std::set<std::string> ran;
  for (const NamedMesh& m : embeddedObjects()) {
    if (!wanted.empty() && wanted.count(m.name) == 0) continue;
    ran.insert(m.name);
    auto q = depthSceneQuality(tableScene(m.name, m.mesh), hand, box, **solver, *backend, options);
    if (!q) {
      std::fprintf(stderr, "autograsp-depth-figures: %s: %s\n", m.name.c_str(),
                   q.error().message.c_str());
      return 1;
    }
    for (const DepthReachFigures& f : q->reaches) {
      tools::Json row = {{"object", m.name}, {"reach", f.reach}, {"reaches", f.reaches}};
      if (f.reaches == 0) {
        // A flat object on the table leaves the open hand no room beside it.
        std::printf("%-12s %-6s %7d   (no such reach: the open hand meets the table)\n",
                    m.name.c_str(), f.reach.c_str(), 0);
        rows.push_back(row);
        continue;
      }
      std::printf("%-12s %-6s %7d %5.1f%% %6.2f mm %6.2f mm %6.2f mm %6.2f mm\n", m.name.c_str(),
                  f.reach.c_str(), f.reaches, 100.0 * f.made / f.reaches,
                  double(f.penetrationP99Mm), double(f.penetrationMaxMm),
                  double(f.residualMedianMm), double(f.residualP95Mm));
      row["made"] = f.made;
      row["penetration_p99_mm"] = tools::jsonNumber(f.penetrationP99Mm);
      row["penetration_max_mm"] = tools::jsonNumber(f.penetrationMaxMm);
      row["residual_median_mm"] = tools::jsonNumber(f.residualMedianMm);
      row["residual_p95_mm"] = tools::jsonNumber(f.residualP95Mm);
      rows.push_back(row);
    }
  }
  for (const std::string& name : wanted) {
    if (ran.count(name) == 0) {
      std::fprintf(stderr, "autograsp-depth-figures: no embedded object is called %s\n",
                   name.c_str());
      return 2;
    }
  }
  if (!json.empty()) {
    const tools::Json doc = {{"tool", "autograsp-depth-figures"},
                             {"provenance", tools::provenanceJson()},
                             {"placements", options.placements},
                             {"seed", options.seed},
                             {"rows", rows}};
    if (auto e = tools::writeJsonFile(json, doc)) {
      std::fprintf(stderr, "autograsp-depth-figures: %s\n", e->message.c_str());
      return 1;
    }
  }
  return 0;
}
