#include "bench_options.h"

#include <algorithm>
#include <string>
#include <string_view>

#include "cli_options.h"
#include "eval/strategies.h"
#include "io/mesh_variants.h"

namespace sdfg::bench {

const char* const kUsage =
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
    "                     vulkan: a device of its own (VK_ICD_FILENAMES picks the driver);\n"
    "                     it also adds \"ours/buffers\": each mesh alone (and with --scenes\n"
    "                     every scene) as buffer targets in that device's buffers, solved\n"
    "                     through a GraspSession as the layer solves them\n"
    "  --sdf-far-band M   cpu builder far-field mode: nodes at least M metres from the surface\n"
    "                     may hold certified lower bounds (CpuSdfOptions::exactBand; default 0,\n"
    "                     exact everywhere)\n"
    "  --thin-plate-set   only the embedded thin plate, graded on the placements where\n"
    "                     \"paper\" (added if missing; --da must be 0.1) passes through it\n"
    "  --approaching      approaching hands: the palm from 1 cm inside to 5 cm outside the\n"
    "                     surface, open hands inside the mesh kept; adds the table of the whole\n"
    "                     hand's penetration, the hand's motion and contacts, split by whether\n"
    "                     the open hand was already inside\n"
    "  --scenes           also run every method in scenes: each mesh resting on a table top,\n"
    "                     two mugs 5 mm apart, a spoon in a mug, a mug's handle 1.5 cm from a\n"
    "                     wall; the whole hand's penetration into objects not held, grasps of\n"
    "                     the wrong object, and the single-object figures (--placements each)\n"
    "  --clear-hand on|off  on (default): \"ours\" moves an open hand that is inside the mesh\n"
    "                     out before closing (SolverOptions::clearance); off: as before\n"
    "  --variants LIST    comma-separated: soup, flat, seams. Also run each mesh with its\n"
    "                     vertices split as game exporters do (soup: every triangle its own\n"
    "                     vertices; flat: hard edges over 30 degrees; seams: box-mapping UV\n"
    "                     charts), rows \"<mesh>/<variant>\": solved on the variant, placements\n"
    "                     and grading on the mesh as loaded (default: none; not in --scenes)\n"
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

std::optional<UsageError> parseOptions(int argc, char** argv, Options& o, bool& help) {
  namespace cli = tools::cli;
  const std::vector<std::string> known = allSolverNames();
  CLI::App app{"", "autograsp-bench"};
  cli::addHelpFlag(app, help);
  app.add_flag("--embedded", o.embedded);
  app.add_flag("--embedded-only", o.embeddedOnly);
  app.add_flag("--thin-plate-set", o.thinPlateSet);
  app.add_flag("--approaching", o.approaching);
  app.add_flag("--scenes", o.scenes);
  cli::addRepeatable(app, "--mesh", o.meshes);
  cli::addInteger(app, "--placements", o.placements, 1, 1000000);
  cli::addUnsigned64(app, "--seed", o.seed);
  cli::addList(app, "--methods", known, "method", o.methods);
  cli::addNumber(
      app, "--da", o.da, [](float x) { return x > 0.0f && x <= 1.0f; }, "a number in (0, 1]");
  cli::addInteger(app, "--resolution", o.resolution, kMinGridResolution, kMaxGridResolution);
  cli::addOnOff(app, "--exact-check", o.exactCheck);
  cli::addOnOff(app, "--clear-hand", o.clearHand);
  std::vector<std::string> variantNames;
  for (std::string_view v : meshVariantNames()) variantNames.emplace_back(v);
  cli::addList(app, "--variants", variantNames, "variant", o.variants);
  cli::addInteger(app, "--threads", o.threads, 0, 1024);
  cli::addNumber(
      app, "--sdf-far-band", o.sdfFarBand, [](float x) { return x >= 0.0f; },
      "a distance >= 0 in metres");
  const CLI::Option* backends = cli::addList(
      app, "--sdf-backend", {tools::kCpuBackend, tools::kVulkanBackend}, "backend", o.sdfBackends);
  cli::addName(app, "--json", o.json, "file name");
  cli::addName(app, "--report", o.report, "folder name");
  cli::addName(app, "--scaling-json", o.scalingJson, "file name");
  cli::addName(app, "--scaling-from", o.scalingFrom, "file name");
  cli::addName(app, "--report-from", o.reportFrom, "file name");
  bool scaling = false, scalingQuick = false;
  app.add_flag("--scaling", scaling);
  app.add_flag("--scaling-quick", scalingQuick);
  if (auto error = cli::parse(app, argc, argv)) return UsageError{*error};

  o.sdfBackendsGiven = backends->count() > 0;
  // --report, --scaling-json and --scaling-from imply --scaling.
  o.scalingQuick = scalingQuick;
  o.scaling = scaling || scalingQuick || !o.report.empty() || !o.scalingJson.empty() ||
              !o.scalingFrom.empty();
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

}  // namespace sdfg::bench
