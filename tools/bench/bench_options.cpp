#include "bench_options.h"

#include <algorithm>
#include <cstdlib>
#include <sstream>
#include <string>

#include "eval/strategies.h"

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
    "                     vulkan: a device of its own (VK_ICD_FILENAMES picks the driver)\n"
    "  --sdf-far-band M   cpu builder far-field mode: nodes at least M metres from the surface\n"
    "                     may hold certified lower bounds (CpuSdfOptions::exactBand; default 0,\n"
    "                     exact everywhere)\n"
    "  --thin-plate-set   only the embedded thin plate, graded on the placements where\n"
    "                     \"paper\" (added if missing; --da must be 0.1) passes through it\n"
    "  --approaching      approaching hands: the palm from 1 cm inside to 5 cm outside the\n"
    "                     surface, open hands inside the mesh kept; adds the table of the whole\n"
    "                     hand's penetration, the hand's motion and contacts, split by whether\n"
    "                     the open hand was already inside\n"
    "  --clear-hand on|off  on (default): \"ours\" moves an open hand that is inside the mesh\n"
    "                     out before closing (SolverOptions::clearance); off: as before\n"
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

namespace {

bool parseInt(const std::string& s, long long lo, long long hi, long long& out) {
  if (s.empty()) return false;
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(s.c_str(), &end, 10);
  if (errno != 0 || *end != '\0' || v < lo || v > hi) return false;
  out = v;
  return true;
}

}  // namespace

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
    } else if (arg == "--approaching") {
      o.approaching = true;
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
    } else if (arg == "--clear-hand") {
      if (auto e = needValue(v)) return e;
      if (v != "on" && v != "off")
        return UsageError{"--clear-hand: \"" + v + "\" is not on or off"};
      o.clearHand = v == "on";
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

}  // namespace sdfg::bench
