#include "report.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>
#include <tuple>

#include "eval/evaluator.h"
#include "hand/hand_model.h"

#include "build_info.h"
#include "report_detail.h"

namespace fs = std::filesystem;

namespace sdfg::bench {

fs::path reportResultsPath(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir / "bench-data", ec);
  return dir / "bench-data" / "results.json";
}

std::string shellCommandLine(int argc, char** argv) {
  std::string out;
  for (int i = 0; i < argc; ++i) out += (i ? " " : "") + shellQuote(argv[i]);
  return out;
}

namespace {

struct Column {
  std::string key;  // top-level member of a row
  std::string sub;  // member of that object, or empty for a plain number
  std::string title() const { return sub.empty() ? key : key + " " + sub; }
  double get(const Json& row) const { return numberAt(row, key, sub); }
};

// A method as run on one SDF backend ("none": a physics method, no field).
struct Variant {
  std::string method, backend;
  bool operator==(const Variant&) const = default;
};

struct Table {
  std::vector<std::string> meshes;
  std::vector<Variant> variants;      // in the order the bench ran them
  std::vector<std::string> backends;  // the SDF backends that ran (not "none")
  std::map<std::tuple<std::string, std::string, std::string>, const Json*> rows;
  const Json* at(const std::string& mesh, const Variant& v) const {
    auto it = rows.find({mesh, v.method, v.backend});
    return it == rows.end() ? nullptr : it->second;
  }
  // With more than one SDF backend, rows of one method differ by backend: a column says which.
  bool showBackend() const { return backends.size() > 1; }
  std::string label(const Variant& v) const {
    return showBackend() && v.backend != "none" ? v.method + " (" + v.backend + ")" : v.method;
  }
};

std::string firstLineOf(const char* file, const char* prefix) {
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(prefix, 0) == 0) {
      const size_t colon = line.find(':');
      std::string v = colon == std::string::npos ? line : line.substr(colon + 1);
      v.erase(0, v.find_first_not_of(" \t"));
      return v;
    }
  }
  return {};
}

std::string nowUtc() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[64];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M UTC", &tm);
  return buf;
}

bool writeFile(const fs::path& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  out.flush();
  return bool(out);
}

const char* kPlotStyle =
    "set terminal pngcairo size 1000,520 noenhanced font 'sans,10'\n"
    "set datafile missing 'NaN'\n"
    "set grid ytics lc rgb '#dddddd'\n"
    "set border 3\nset tics nomirror\n";

// A clustered bar chart: one cluster per mesh, one bar per method.
std::string barPlot(const std::string& dat, const std::string& png, const std::string& title,
                    const std::string& ylabel, size_t methods, bool logY) {
  std::ostringstream gp;
  gp << kPlotStyle << "set output " << gpString(png) << "\n"
     << "set title " << gpString(title) << "\nset ylabel " << gpString(ylabel) << "\n"
     << "set style data histograms\nset style histogram clustered gap 1\n"
     << "set style fill solid 0.85 border -1\nset boxwidth 0.9\n"
     << "set key outside right top\nset xtics rotate by -25\n"
     << (logY ? "set logscale y\n" : "set yrange [0:*]\n") << "plot for [i=2:" << methods + 1
     << "] " << gpString(dat) << " using i:xtic(1) title columnheader(i)\n";
  return gp.str();
}

std::string linePlot(const std::string& dat, const std::string& png, const std::string& title,
                     const std::string& xlabel, const std::vector<std::string>& builders, bool logX,
                     bool labels, const std::string& extra = {}) {
  std::ostringstream gp;
  gp << kPlotStyle << extra << "set output " << gpString(png) << "\n"
     << "set title " << gpString(title) << "\nset xlabel " << gpString(xlabel) << "\n"
     << "set ylabel 'build time per grab (ms)'\nset logscale y\n"
     << (logX ? "set logscale x\nset format x '%.0s%c'\n" : "") << "set key left top\n"
     << "set grid xtics lc rgb '#dddddd'\n"
     << "plot ";
  for (size_t i = 0; i < builders.size(); ++i) {
    gp << (i ? ", " : "") << gpString(dat) << " using 2:" << 3 + i
       << " with linespoints lw 2 pt 7 title " << gpString(builders[i]);
  }
  if (labels) {
    // Names alternate above and below their points: meshes of equal size (100k) stay legible.
    gp << ", " << gpString(dat)
       << " using 2:(int($0) % 2 == 0 ? $3 : NaN):1 with labels offset 0,1 font 'sans,8' notitle"
       << ", " << gpString(dat)
       << " using 2:(int($0) % 2 == 1 ? $3 : NaN):1 with labels offset 0,-1 font 'sans,8' notitle";
  }
  gp << "\n";
  return gp.str();
}

}  // namespace

std::optional<Error> writeReport(const ReportRequest& request, const ScalingResults* scaling) {
  const Result<Json> json = tools::readJsonFile(request.resultsJson);
  if (!json) return json.error();
  const Json* rowsJson = member(*json, "rows");
  if (!rowsJson || !rowsJson->is_array()) {
    return makeError(Status::io_error, request.resultsJson.string() + ": no \"rows\" array");
  }

  const fs::path imgDir = request.dir / "img" / "bench";
  const fs::path dataDir = request.dir / "bench-data";
  std::error_code ec;
  fs::create_directories(imgDir, ec);
  fs::create_directories(dataDir, ec);
  if (ec) return makeError(Status::io_error, request.dir.string() + ": " + ec.message());

  // Rows by mesh and method, in the order the bench ran them; the quality columns are every
  // member not shown elsewhere, in the JSON's order.
  Table table;
  std::vector<Column> quality;
  const std::vector<std::string> identity = {"mesh",      "method",   "sdf_backend",
                                             "triangles", "solve_us", "sdf_build_ms"};
  for (const Json& row : *rowsJson) {
    std::string mesh = stringOf(member(row, "mesh"));
    const std::string method = stringOf(member(row, "method"));
    // Results written before the backend column were all CPU builds.
    const Json* backendJson = member(row, "sdf_backend");
    const Variant variant{method, backendJson ? stringOf(backendJson) : tools::kCpuBackend};
    // Two meshes of one name (the embedded torus and torus.obj): the later one is "name (2)".
    for (int n = 2; table.at(mesh, variant); ++n) {
      mesh = stringOf(member(row, "mesh")) + " (" + std::to_string(n) + ")";
    }
    if (std::find(table.meshes.begin(), table.meshes.end(), mesh) == table.meshes.end()) {
      table.meshes.push_back(mesh);
    }
    if (std::find(table.variants.begin(), table.variants.end(), variant) == table.variants.end()) {
      table.variants.push_back(variant);
    }
    if (variant.backend != "none" && std::find(table.backends.begin(), table.backends.end(),
                                               variant.backend) == table.backends.end()) {
      table.backends.push_back(variant.backend);
    }
    table.rows[{mesh, variant.method, variant.backend}] = &row;
    if (row.is_object()) {
      for (const auto& [key, value] : row.items()) {
        if (std::find(identity.begin(), identity.end(), key) != identity.end()) continue;
        std::vector<Column> found;
        if (value.is_object()) {
          for (const auto& [subKey, subValue] : value.items()) {
            if (subValue.is_number() || subValue.is_null()) found.push_back({key, subKey});
          }
        } else if (value.is_number() || value.is_null()) {
          found.push_back({key, ""});
        }
        for (const Column& c : found) {
          const bool known = std::any_of(quality.begin(), quality.end(), [&](const Column& q) {
            return q.key == c.key && q.sub == c.sub;
          });
          if (!known) quality.push_back(c);
        }
      }
    }
  }

  // Every top-level number or flag of the JSON (placements, seed, da, resolution, exact_check...)
  // as "key value".
  std::string settings;
  for (const auto& [key, value] : json->items()) {
    if (value.is_number()) {
      settings += (settings.empty() ? "" : ", ") + key + " " + fmt(value.get<double>());
    } else if (value.is_boolean()) {
      settings += (settings.empty() ? "" : ", ") + key + (value.get<bool>() ? " on" : " off");
    }
  }
  std::ostringstream md;
  md << "# Benchmarks: `autograsp-bench`\n\n"
     << "This file and the plots in `img/bench/` are written by `autograsp-bench --report` "
        "from one run; edit the program (or `benchmarks-notes.md`, copied in at the end), not "
        "this file. The command:\n\n```sh\n"
     << request.commandLine << "\n```\n\n";
  const std::string cpu = firstLineOf("/proc/cpuinfo", "model name");
  std::string load;
  {
    std::ifstream loadavg("/proc/loadavg");
    std::string a, b, c;
    if (loadavg >> a >> b >> c) load = a + ", " + b + ", " + c;
  }
  // Which code made the figures: the commit each JSON recorded (a JSON from before the bench
  // recorded it says so), and the code that wrote this page.
  auto commitOf = [](const Json* provenance, const fs::path& file, const std::string& what) {
    if (auto described = tools::describeProvenance(provenance ? *provenance : Json())) {
      return *described;
    }
    return "not recorded: `" + file.string() + "` was written before " + what +
           " recorded its commit";
  };
  md << "| | |\n|---|---|\n"
     << "| commit of the figures (bench run) | "
     << commitOf(member(*json, "provenance"), request.resultsJson, "the bench") << " |\n";
  if (scaling) {
    md << "| commit of the SDF scaling figures | "
       << commitOf(&scaling->provenance, request.scalingFrom, "the sweep") << " |\n";
  }
  md << "| commit of the report's writer | " << tools::describeBuild() << " |\n"
     << "| date | " << nowUtc() << " |\n"
     << "| CPU | " << (cpu.empty() ? "unknown" : cpu) << " |\n"
     << "| hardware threads (nproc) | " << std::thread::hardware_concurrency() << " |\n"
     << "| threads used (SDF builds, grading) | " << request.threads << " |\n"
     << "| load average at the end (1, 5, 15 min) | " << (load.empty() ? "unknown" : load) << " |\n"
     << "| compiler | " <<
#ifdef __VERSION__
      __VERSION__
#else
      "unknown"
#endif
     << " |\n"
     << "| run settings | " << settings << " |\n\n"
     << "Times are wall-clock and depend on the machine and on what else ran on it; the load "
        "average above says how busy it was.\n\n";

  // Written-by-hand text survives regeneration: it lives in its own file, copied in at the end;
  // when it is there it holds the definitions, else a short version goes here.
  std::string notes;
  if (std::ifstream notesIn{request.dir / "benchmarks-notes.md"}) {
    std::stringstream text;
    text << notesIn.rdbuf();
    notes = text.str();
  }
  if (!notes.empty()) {
    md << "How to run it and what each figure means: at the end of this page. `-` in a table: no "
          "data (no finger in contact, no field for a physics method).\n\n";
  } else {
    md << "## What is measured\n\n"
       << "Every mesh is scaled to an 18 cm bounding-box diagonal (hand size). Seeded hand "
          "placements (`src/offline/eval/placements.h`) put the open palm 1 to 4 cm from a random "
          "surface "
          "point; every method solves the same placements. `solve_us`: per-solve time, minimum "
          "over repeated batches, SDF build not included (as in the paper's Table 1). "
          "`sdf_build_ms`: the grab-box SDF build per placement on the row's `sdf_backend` (CPU, "
          "or Vulkan until its fence signals and the grid is read back), for the methods that "
          "read a field. Quality is graded against CGAL's exact distance to the original surface "
          "(`src/offline/eval/evaluator.h`): `tip_residual_mm` |d(tip) - r_tip| over fingers in "
          "contact; "
          "`penetration_mm` deepest phalanx point inside the mesh per grasp; `early_stops` "
          "fingers (summed over grasps) that stopped more than 5 mm short of a reachable pose; "
          "`contacts_mean` fingers within 2 mm per grasp. Any other column is a metric of the "
          "JSON documented in `src/offline/eval/evaluator.h`. `-`: no data (e.g. no finger in "
          "contact, no "
          "field for a physics method).\n\n";
  }

  // Speed table: the paper's Table 1 layout, with a backend column when more than one ran.
  const bool showBackend = table.showBackend();
  const std::string backendHead = showBackend ? " SDF backend |" : "";
  const std::string backendAlign = showBackend ? "---|" : "";
  md << "## Speed\n\nSolve time per grasp, median, microseconds (the paper's Table 1 reports 0.01 "
        "to 0.03 ms for its SDF method and 0.04 to 0.1 ms for physics, Unity on an Apple M1)"
     << (showBackend ? "; the SDF methods once per backend, each solving on the field that "
                       "backend built"
                     : "")
     << ":\n\n| method |" << backendHead;
  for (const auto& m : table.meshes) md << " " << m << " |";
  md << "\n|---|" << backendAlign;
  for (size_t i = 0; i < table.meshes.size(); ++i) md << "---:|";
  md << "\n";
  const Column solve{"solve_us", "median"}, build{"sdf_build_ms", "median"};
  for (const Variant& v : table.variants) {
    md << "| " << v.method << " |" << (showBackend ? " " + v.backend + " |" : "");
    for (const auto& mesh : table.meshes) {
      const Json* r = table.at(mesh, v);
      md << " " << (r ? fmt(solve.get(*r)) : "-") << " |";
    }
    md << "\n";
  }
  // One build row per backend: every SDF method of a backend reads the same builds.
  for (const std::string& backend : table.backends) {
    md << (showBackend ? "| SDF build (ms) | " + backend + " |"
                       : "| " + tools::backendTitle(backend) + " SDF build (ms) |");
    for (const auto& mesh : table.meshes) {
      double ms = std::nan("");
      for (const Variant& v : table.variants) {
        const Json* r = v.backend == backend ? table.at(mesh, v) : nullptr;
        if (r && std::isfinite(build.get(*r))) {
          ms = build.get(*r);
          break;
        }
      }
      md << " " << fmt(ms) << " |";
    }
    md << "\n";
  }
  md << "| triangles |" << (showBackend ? " |" : "");
  for (const auto& mesh : table.meshes) {
    const Json* t = nullptr;
    for (const Variant& v : table.variants) {
      if (const Json* r = table.at(mesh, v); r && !t) t = member(*r, "triangles");
    }
    md << " " << (t && t->is_number() ? withThousands(size_t(numberOf(t))) : "-") << " |";
  }
  md << "\n\n![solve time](img/bench/solve_time.png)\n\n";

  md << "## Quality\n\nAgainst the exact mesh; millimetres unless the name says otherwise.\n\n"
     << "| mesh | method |" << backendHead;
  for (const Column& c : quality) md << " " << c.title() << " |";
  md << "\n|---|---|" << backendAlign;
  for (size_t i = 0; i < quality.size(); ++i) md << "---:|";
  md << "\n";
  for (const auto& mesh : table.meshes) {
    for (const Variant& v : table.variants) {
      const Json* r = table.at(mesh, v);
      if (!r) continue;
      md << "| " << mesh << " | " << v.method << " |"
         << (showBackend ? " " + v.backend + " |" : "");
      for (const Column& c : quality) md << " " << fmt(c.get(*r)) << " |";
      md << "\n";
    }
  }
  md << "\n";

  // Plots of the bench rows: one data file per figure, meshes down, methods across.
  struct BarFigure {
    std::string file, title, ylabel;
    Column column;
    bool logY;
  };
  std::vector<BarFigure> bars = {{"solve_time",
                                  "Solve time per grasp, median (SDF build not included)",
                                  "microseconds (log scale)", solve, true}};
  for (const Column& c : quality) {
    // One figure per metric: its median / p99 (the figure that summarises it), or the number.
    if (c.key == "grasps") continue;
    const bool primary =
        c.sub.empty() || c.sub == "median" || (c.sub == "p99" && c.key == "penetration_mm");
    if (!primary) continue;
    bars.push_back({c.key, c.title() + " per method and mesh", c.title(), c, false});
  }
  std::ostringstream gpAll;
  for (const BarFigure& f : bars) {
    std::ostringstream dat;
    dat << "mesh";
    for (const Variant& v : table.variants) dat << " " << datString(table.label(v));
    dat << "\n";
    for (const auto& mesh : table.meshes) {
      dat << datString(mesh);
      for (const Variant& v : table.variants) {
        const Json* r = table.at(mesh, v);
        dat << " " << datNumber(r ? f.column.get(*r) : std::nan(""));
      }
      dat << "\n";
    }
    const fs::path datPath = dataDir / (f.file + ".dat");
    if (!writeFile(datPath, dat.str())) {
      return makeError(Status::io_error, datPath.string() + ": cannot write");
    }
    gpAll << barPlot(f.file + ".dat", "../img/bench/" + f.file + ".png", f.title, f.ylabel,
                     table.variants.size(), f.logY);
    if (f.file != "solve_time") {
      md << "![" << f.title << "](img/bench/" << f.file << ".png)\n\n";
    }
  }

  if (scaling) {
    const ScalingResults& s = *scaling;
    md << "## SDF build scaling\n\n" << scalingTables(s, "###");
    // One line per builder and kind of time: the builds first, then build + sampling.
    std::vector<std::string> seriesNames;
    for (const char* what : {" build", " build + sampling"}) {
      for (const auto& b : s.builders) seriesNames.push_back(tools::backendTitle(b) + what);
    }
    auto writeDat = [&](const std::vector<ScalingPoint>& points, const std::string& name,
                        bool byTriangles) -> std::optional<Error> {
      std::ostringstream dat;
      dat << "# mesh x";
      for (const auto& series : seriesNames) dat << " " << datString(series);
      dat << "\n";
      for (const ScalingPoint& p : points) {
        dat << datString(p.mesh) << " " << (byTriangles ? double(p.triangles) : p.resolution);
        for (double ms : p.buildMs) dat << " " << datNumber(ms);
        for (double ms : p.buildSampleMs) dat << " " << datNumber(ms);
        dat << "\n";
      }
      const fs::path path = dataDir / (name + ".dat");
      if (!writeFile(path, dat.str())) {
        return makeError(Status::io_error, path.string() + ": cannot write");
      }
      return std::nullopt;
    };
    // Log x axes: a margin keeps end points and labels off the border.
    auto xrange = [](const std::vector<ScalingPoint>& points, bool byTriangles) {
      double lo = 1e300, hi = 0.0;
      for (const ScalingPoint& p : points) {
        const double x = byTriangles ? double(p.triangles) : double(p.resolution);
        lo = std::min(lo, x);
        hi = std::max(hi, x);
      }
      // Labels are centred on their points: the right end needs more room than the left.
      const double right = byTriangles ? 2.5 : 1.4;
      return "set xrange [" + datNumber(lo / 1.4) + ":" + datNumber(hi * right) + "]\n";
    };
    if (auto e = writeDat(s.byTriangles, "sdf_build_triangles", true)) return e;
    if (auto e = writeDat(s.byResolution, "sdf_build_resolution", false)) return e;
    if (!s.byTriangles.empty()) {
      gpAll << linePlot("sdf_build_triangles.dat", "../img/bench/sdf_build_triangles.png",
                        "Grab-box SDF build time against triangle count (" +
                            std::to_string(s.byTriangles.front().resolution) + "^3 nodes)",
                        "triangles (log scale)", seriesNames, true, true,
                        xrange(s.byTriangles, true));
      md << "![SDF build time against triangles](img/bench/sdf_build_triangles.png)\n\n";
    }
    if (!s.byResolution.empty()) {
      std::string xtics = "set xtics (";
      for (size_t i = 0; i < s.byResolution.size(); ++i) {
        xtics += (i ? ", " : "") + std::to_string(s.byResolution[i].resolution);
      }
      xtics += ")\n" + xrange(s.byResolution, false);
      gpAll << linePlot("sdf_build_resolution.dat", "../img/bench/sdf_build_resolution.png",
                        "Grab-box SDF build time against resolution (" +
                            s.byResolution.front().mesh + ", " +
                            withThousands(s.byResolution.front().triangles) + " triangles)",
                        "grid nodes per axis (log scale)", seriesNames, true, false, xtics);
      md << "![SDF build time against resolution](img/bench/sdf_build_resolution.png)\n\n";
    }
  }

  // gnuplot: one script for every figure, run in bench-data/ (paths in it are relative, so the
  // folder can be moved and replotted); "reset" between figures keeps their styles apart.
  const fs::path script = dataDir / "plots.gp";
  std::string gp = gpAll.str();
  for (size_t at = gp.find("set terminal", 1); at != std::string::npos;
       at = gp.find("set terminal", at + 20)) {
    gp.insert(at, "reset\n");
  }
  if (!writeFile(script, gp))
    return makeError(Status::io_error, script.string() + ": cannot write");
  std::string plotNote;
  if (std::system("command -v gnuplot >/dev/null 2>&1") != 0) {
    plotNote = "gnuplot not found (Debian: apt-get install gnuplot-nox); no plots drawn";
  } else if (std::system(("cd " + shellQuote(dataDir.string()) + " && gnuplot plots.gp").c_str()) !=
             0) {
    plotNote = "gnuplot failed on " + script.string() + "; plots may be missing";
  }
  if (!plotNote.empty()) {
    std::fprintf(stderr, "autograsp-bench: %s\n", plotNote.c_str());
    md << "_Note: " << plotNote << "._\n\n";
  }
  md << scenesSection(*json);
  md << "The data behind the plots: `bench-data/` (the bench's JSON, one `.dat` per figure and "
        "the gnuplot script `plots.gp`).\n";
  if (!notes.empty()) md << "\n<!-- from benchmarks-notes.md -->\n\n" << notes;

  const fs::path mdPath = request.dir / "benchmarks.md";
  if (!writeFile(mdPath, md.str())) {
    return makeError(Status::io_error, mdPath.string() + ": cannot write");
  }
  std::fprintf(stderr, "autograsp-bench: report written to %s\n", mdPath.string().c_str());
  return std::nullopt;
}

ReportStatus runReport(const ReportRequest& request) {
  // A missing JSON fails now, not after a sweep of minutes.
  if (!request.dir.empty() && !std::ifstream(request.resultsJson)) {
    std::fprintf(stderr, "autograsp-bench: report: %s: cannot read\n",
                 request.resultsJson.string().c_str());
    return ReportStatus::failed;
  }
  ScalingOptions options;
  options.quick = request.scalingQuick;
  options.resolution = request.resolution;
  options.threads = request.threads;
  options.sharedMeshes = request.sharedMeshes;
  options.backends = request.backends;
  auto scaling =
      request.scalingFrom.empty() ? runScaling(options) : readScalingJson(request.scalingFrom);
  if (!scaling) {
    std::fprintf(stderr, "autograsp-bench: scaling: %s\n", scaling.error().message.c_str());
    return ReportStatus::failed;
  }
  printScaling(*scaling);
  if (!request.scalingJson.empty()) {
    if (auto error = writeScalingJson(request.scalingJson, *scaling)) {
      std::fprintf(stderr, "autograsp-bench: scaling: %s\n", error->message.c_str());
      return ReportStatus::failed;
    }
  }
  if (!request.dir.empty()) {
    if (auto error = writeReport(request, &*scaling)) {
      std::fprintf(stderr, "autograsp-bench: report: %s\n", error->message.c_str());
      return ReportStatus::failed;
    }
  }
  return scaling->unavailable.empty() ? ReportStatus::ok : ReportStatus::backend_unavailable;
}

}  // namespace sdfg::bench
