// autograsp-bench: speed and quality of every grasp strategy on the same seeded placements.
//
// Per mesh: load, scale to hand size (18 cm bounding-box diagonal), draw the placements once, then
// for each placement build the grab-box SDF on the CPU (timed) and solve it with every method
// (timed over repeated batches), and grade each grasp against the exact surface of the mesh
// (evaluator.h). Prints the paper's Table 1 layout (methods x meshes, solve time), a quality
// table and side-by-side ratios; --json writes every figure for docs to quote.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "approaching_table.h"
#include "bench_options.h"
#include "bench_output.h"
#include "io/mesh_io.h"
#include "io/mesh_variants.h"
#include "io/shapes.h"
#include "report.h"
#include "run_mesh.h"
#include "run_scenes.h"
#include "sdf_backends.h"

using namespace sdfg;
using namespace sdfg::bench;

int main(int argc, char** argv) {
  Options o;
  bool help = false;
  if (auto error = parseOptions(argc, argv, o, help)) {
    std::fprintf(stderr, "autograsp-bench: %s\n%s", error->message.c_str(), kUsage);
    return 2;
  }
  if (help) {
    std::fputs(kUsage, stdout);
    return 0;
  }
  const unsigned threads =
      o.threads ? o.threads : std::max(1u, std::thread::hardware_concurrency());
  // The sweep compares the backends asked for; by default both (the side-by-side table).
  const std::vector<std::string> scalingBackends =
      o.sdfBackendsGiven ? o.sdfBackends
                         : std::vector<std::string>{tools::kCpuBackend, tools::kVulkanBackend};
  auto reportExitCode = [](bench::ReportStatus status) {
    return status == bench::ReportStatus::failed                ? 1
           : status == bench::ReportStatus::backend_unavailable ? kExitBackendUnavailable
                                                                : 0;
  };
  if (!o.reportFrom.empty()) {
    // A long run's results, reported again (new plots, new notes) without solving again.
    return reportExitCode(bench::runReport(bench::ReportRequest{
        o.report, o.reportFrom, bench::shellCommandLine(argc, argv), threads, o.scalingQuick,
        o.resolution, sharedMeshesDir(), scalingBackends, o.scalingJson, o.scalingFrom}));
  }

  std::vector<MeshSource> sources;
  const bool useDefaults = o.meshes.empty() && !o.embeddedOnly && !o.thinPlateSet;
  if (o.embeddedOnly || o.embedded || useDefaults || o.thinPlateSet) {
    for (NamedMesh& m : embeddedObjects()) {
      if (o.thinPlateSet && m.name != "thin-plate") continue;
      sources.push_back({m.name, std::nullopt, std::move(m.mesh)});
    }
  }
  if (!o.embeddedOnly && !o.thinPlateSet) {
    std::vector<fs::path> files(o.meshes.begin(), o.meshes.end());
    if (useDefaults) {
      if (auto dir = sharedMeshesDir()) {
        files = defaultMeshFiles(*dir);
      } else {
        std::fprintf(stderr, "note: no ../shared/meshes folder found; embedded objects only\n");
      }
    }
    for (const auto& f : files) sources.push_back({f.stem().string(), f, {}});
  }

  const HandModel hand = HandModel::defaultAdult(Hand::right);
  GridBox box = GridBox::referenceDefault();
  box.resolution = glm::uvec3(uint32_t(o.resolution));
  // One builder per backend asked for; one without a device is left out, with its rows.
  std::vector<std::unique_ptr<tools::TimedSdfBuilder>> builderStore;
  std::vector<tools::TimedSdfBuilder*> builders;
  bool backendMissing = false;
  tools::TimedBuilderOptions builderOptions;
  builderOptions.cpuThreads = threads;
  builderOptions.cpuExactBand = o.sdfFarBand;
  for (const std::string& backend : o.sdfBackends) {
    auto b = tools::makeTimedBuilder(backend, builderOptions);
    if (!b) {
      std::fprintf(stderr,
                   "autograsp-bench: --sdf-backend %s: %s; its rows are left out (exit code %d)\n",
                   backend.c_str(), b.error().message.c_str(), kExitBackendUnavailable);
      backendMissing = true;
      continue;
    }
    std::fprintf(stderr, "autograsp-bench: SDF backend %s on %s\n", backend.c_str(),
                 (*b)->device().c_str());
    builders.push_back(b->get());
    builderStore.push_back(std::move(b.value()));
  }
  if (!o.exactCheck) {
    std::fprintf(stderr, "autograsp-bench: --exact-check off: \"ours\" stops on the SDF alone\n");
  }
  const Progress progress;

  bool failed = false;
  std::vector<Row> rows;
  // With --sdf-backend vulkan, "ours" on buffer targets: each mesh alone (the single-object
  // rows), then with --scenes every scene, through a GraspSession on a device of its own.
  const bool bufferRowsWanted =
      std::find(o.sdfBackends.begin(), o.sdfBackends.end(), tools::kVulkanBackend) !=
          o.sdfBackends.end() &&
      std::find(o.methods.begin(), o.methods.end(), "ours") != o.methods.end();
  std::vector<BenchScene> bufferScenes;
  // --scenes: each mesh that ran on a table, then the scenes of several objects (embedded ones).
  std::vector<BenchScene> scenes;
  bool embeddedRan = false;
  for (const MeshSource& source : sources) {
    TriangleMesh loaded;
    const TriangleMesh* mesh = &source.embedded;
    if (source.path) {
      auto result = loadMesh(*source.path);
      if (!result) {
        // Loader messages usually start with the path already; name it once.
        const std::string& message = result.error().message;
        const std::string file = source.path->string();
        std::fprintf(stderr, "autograsp-bench: skipping %s: %s\n", file.c_str(),
                     message.size() > file.size() + 2 &&
                             message.compare(0, file.size() + 2, file + ": ") == 0
                         ? message.c_str() + file.size() + 2
                         : message.c_str());
        failed = true;
        continue;
      }
      loaded = std::move(result->mesh);
      mesh = &loaded;
    }
    const auto t0 = std::chrono::steady_clock::now();
    PhaseSeconds phases;
    auto meshRows = runMesh(source.name, *mesh, o, hand, box, builders, threads, progress, phases);
    if (!meshRows) {
      std::fprintf(stderr, "autograsp-bench: skipping %s: %s\n",
                   source.path ? source.path->string().c_str() : source.name.c_str(),
                   meshRows.error().message.c_str());
      failed = true;
      continue;
    }
    for (Row& r : *meshRows) {
      failed = failed || r.failedSolves > 0;
      rows.push_back(std::move(r));
    }
    if (bufferRowsWanted) {
      bufferScenes.push_back(
          aloneScene(source.path ? source.path->filename().string() : source.name, *mesh));
    }
    // A file is named with its extension: the shared torus.obj apart from the embedded torus.
    if (o.scenes) {
      scenes.push_back(
          tableScene(source.path ? source.path->filename().string() : source.name, *mesh));
    }
    embeddedRan = embeddedRan || !source.path;
    std::fprintf(stderr,
                 "%s: %zu triangles, done in %.1f s (placements + solves %.1f s, grading %.1f s)\n",
                 source.name.c_str(), mesh->triangleCount(),
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
                 phases.solve, phases.grade);
    // --variants: the same surface with its vertices split, solved on the variant and measured
    // against the mesh as loaded, on the same placements.
    for (const std::string& v : o.variants) {
      const std::string name = source.name + "/" + v;
      const auto v0 = std::chrono::steady_clock::now();
      auto variant = makeMeshVariant(v, *mesh);
      if (!variant) {
        std::fprintf(stderr, "autograsp-bench: skipping %s: %s\n", name.c_str(),
                     variant.error().message.c_str());
        failed = true;
        continue;
      }
      auto variantRows =
          runMesh(name, *variant, o, hand, box, builders, threads, progress, phases, mesh);
      if (!variantRows) {
        std::fprintf(stderr, "autograsp-bench: skipping %s: %s\n", name.c_str(),
                     variantRows.error().message.c_str());
        failed = true;
        continue;
      }
      for (Row& r : *variantRows) {
        failed = failed || r.failedSolves > 0;
        rows.push_back(std::move(r));
      }
      std::fprintf(stderr,
                   "%s: %zu vertices (%zu as loaded), done in %.1f s (placements + solves %.1f s, "
                   "grading %.1f s)\n",
                   name.c_str(), variant->vertexCount(), mesh->vertexCount(),
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - v0).count(),
                   phases.solve, phases.grade);
    }
  }

  printTables(o, rows);
  std::vector<SceneRow> sceneRows;
  if (o.scenes) {
    if (embeddedRan) {
      for (BenchScene& s : objectScenes()) scenes.push_back(std::move(s));
    }
    if (useDefaults && !sharedMeshesDir()) {
      std::fprintf(stderr,
                   "note: --scenes without ../shared/meshes: the research meshes' table scenes "
                   "are skipped\n");
    }
    sceneRows = runScenes(scenes, o, box, threads, failed);
    printSceneTable(sceneRows);
    if (bufferRowsWanted) bufferScenes.insert(bufferScenes.end(), scenes.begin(), scenes.end());
  }
  std::vector<SceneRow> bufferRows;
  if (bufferRowsWanted) {
    bool available = false;
    bufferRows = runBufferScenes(bufferScenes, o, box, threads, failed, available);
    backendMissing = backendMissing || !available;
    if (available) {
      printSceneTable(bufferRows,
                      "Buffer targets: \"ours\" through a GraspSession whose meshes are in a "
                      "Vulkan device's buffers (read back, set up and built as the layer does for "
                      "XrGraspTargetVulkanBuffersSDFG); each mesh alone, then the scenes");
    }
  }
  if (o.approaching) {
    std::printf(
        "\nApproaching hands (palm 1 cm inside to 5 cm outside), split by whether the "
        "open hand was already inside:\n\n");
    printApproachingTable(stdout, rows);
  }
  if (!o.report.empty() && o.json.empty()) o.json = bench::reportResultsPath(o.report).string();
  if (!o.json.empty() && !writeJson(o.json, o, rows, sceneRows, bufferRows)) {
    std::fprintf(stderr, "autograsp-bench: cannot write %s\n", o.json.c_str());
    failed = true;
  }
  if (o.scaling) {
    const int code = reportExitCode(bench::runReport(bench::ReportRequest{
        o.report, o.json, bench::shellCommandLine(argc, argv), threads, o.scalingQuick,
        o.resolution, sharedMeshesDir(), scalingBackends, o.scalingJson, o.scalingFrom}));
    failed = failed || code == 1;
    backendMissing = backendMissing || code == kExitBackendUnavailable;
  }
  return failed ? 1 : backendMissing ? kExitBackendUnavailable : 0;
}
