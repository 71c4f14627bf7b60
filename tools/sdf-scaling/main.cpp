// autograsp-sdf-scaling: grab-box SDF build time against triangle count and resolution, the CPU
// builder and the Vulkan builder side by side in one run, with the speed-up ratio.
//
// Options: kUsage below (--help prints it).
//
// Objects (tools/common/sdf_backends.h, the same as autograsp-bench --scaling): a procedural torus
// tessellated to 5k .. 400k triangles (the same surface at every count), then the shared test
// meshes when DIR (default ../shared/meshes) has them, each scaled to an 18 cm diagonal like the
// benchmark's objects. The box is the reference 21.33 cm cube
// placed over the object. Times are medians of N runs (default 5) after one warm-up:
//   cpu    CpuSdfBuilder::build, plus trilinear sampling of the points on the CPU
//   vulkan VkSdfBuilder::submitBuild of the SDF + sampling in one submission, until its fence
//          signals (wall time as the frame sees it a frame later, not just GPU time)
// (TimedSdfBuilder::buildAndSample of each backend.) autograsp-bench --scaling times the same
// builders in boxes at seeded hand placements instead of one box centred on the object.
// Both sample the paper's 50 points (5 fingers x 10 curl steps).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "build_info.h"
#include "cli_options.h"
#include "mesh/mesh_distance.h"
#include "sdf/sdf_grid.h"
#include "sdf_backends.h"
#ifdef SDFG_SCALING_VULKAN
#include "vulkan/vk_sdf_builder_detail.h"
#endif

namespace {

using namespace sdfg;
using Clock = std::chrono::steady_clock;

const char* const kUsage =
    "usage: autograsp-sdf-scaling [--meshes DIR] [--runs N] [--res 16,32,64] [--quick]\n"
    "                             [--profile] [--wg N] [--only torus|meshes] [--far-band M]\n"
    "                             [--flood group|node|wide]\n"
    "  --meshes DIR       folder of the test meshes (default ../shared/meshes)\n"
    "  --runs N           timed runs per row after one warm-up; the median is shown (default 5)\n"
    "  --res LIST         comma-separated grid resolutions, 2..128 (default 16,32,64)\n"
    "  --quick            tori up to 100k triangles only, no meshes\n"
    "  --profile          add the Vulkan pass times (GPU timestamps) of the last run to each row:\n"
    "                     transform, hierarchy, splat, flood, final, sample\n"
    "  --wg N             compute work-group size of the Vulkan builder (default 64)\n"
    "  --only torus|meshes  keep one group of rows\n"
    "  --far-band M       CPU builder far-field mode: CpuSdfOptions::exactBand = M metres\n"
    "                     (default 0, exact everywhere)\n"
    "  --flood PATH       Vulkan: force the flood; group: one work group for grids of up to\n"
    "                     4096 nodes (also finalizes and samples: its pass times show final\n"
    "                     and sample as 0, counted in flood; the default on CPU devices);\n"
    "                     node: one dispatch per jump step, one invocation per node (CPU\n"
    "                     devices' larger grids); wide: one dispatch per jump step, a lane per\n"
    "                     neighbour (the default on GPUs)\n"
    "  --help             this text\n"
    "exit codes: 0 done; 1 the CPU builder failed; 2 bad option\n";

}  // namespace

int main(int argc, char** argv) {
  namespace cli = tools::cli;
  std::filesystem::path meshDir = "../shared/meshes";
  int runs = 5;
  bool quick = false, torusRows = true, meshRows = true;
  tools::TimedBuilderOptions builderOptions;
  std::vector<uint32_t> resolutions = {16, 32, 64};
  CLI::App app{"", "autograsp-sdf-scaling"};
  std::string meshes;
  cli::addName(app, "--meshes", meshes, "folder name");
  // --runs and --wg below 1 are raised to 1, as they always were.
  const long long intMin = std::numeric_limits<int>::min(),
                  intMax = std::numeric_limits<int>::max();
  cli::addInteger(
      app, "--runs", intMin, intMax, [&](long long n) { runs = std::max(1, int(n)); },
      "an integer");
  cli::addInteger(
      app, "--wg", intMin, intMax,
      [&](long long n) { builderOptions.vulkanWorkGroupSize = uint32_t(std::max(1, int(n))); },
      "an integer");
  std::vector<std::string> only;
  cli::addList(app, "--only", {"torus", "meshes"}, "group", only);
  cli::addNumber(
      app, "--far-band", builderOptions.cpuExactBand, [](float x) { return x >= 0.0f; },
      "a distance >= 0 in metres");
  app.add_flag("--profile", builderOptions.vulkanProfile);
  app.add_flag("--quick", quick);
  std::string flood;
  app.add_option("--flood", flood);
  std::vector<long long> res;
  cli::addIntegerList(app, "--res", kMinGridResolution, kMaxGridResolution, "resolution", res);
  if (auto exit = cli::parseOrUsage(app, argc, argv, "autograsp-sdf-scaling", kUsage)) return *exit;
  if (!meshes.empty()) meshDir = meshes;
  if (!flood.empty()) {
#ifdef SDFG_SCALING_VULKAN
    using vk_sdf_detail::FloodPath;
    const FloodPath path = flood == "group"  ? FloodPath::group
                           : flood == "node" ? FloodPath::perNode
                           : flood == "wide" ? FloodPath::wide
                                             : FloodPath::automatic;
    if (path == FloodPath::automatic) {
      std::fprintf(stderr, "--flood: group, node or wide, not %s\n", flood.c_str());
      return 2;
    }
    vk_sdf_detail::floodTestHooks.force = path;
#else
    std::fprintf(stderr, "--flood: built without the Vulkan builder\n");
    return 2;
#endif
  }
  if (!res.empty()) resolutions.assign(res.begin(), res.end());
  if (!only.empty()) {
    // --only torus,meshes keeps both, as no --only does.
    torusRows = std::find(only.begin(), only.end(), "torus") != only.end();
    meshRows = std::find(only.begin(), only.end(), "meshes") != only.end();
  }

  std::vector<tools::ScalingObject> objects;
  if (torusRows) {
    for (tools::ScalingObject& t : tools::scalingTori()) {
      if (quick && t.mesh.triangleCount() > 100'000) break;
      objects.push_back(std::move(t));
    }
  }
  if (!quick && meshRows) {
    std::vector<tools::ScalingObject> meshes = tools::scalingMeshes(meshDir);
    if (meshes.size() < tools::scalingMeshFiles().size()) {
      std::fprintf(stderr, "%zu of %zu test meshes found in %s\n", meshes.size(),
                   tools::scalingMeshFiles().size(), meshDir.c_str());
    }
    for (tools::ScalingObject& m : meshes) objects.push_back(std::move(m));
  }

  std::vector<std::unique_ptr<tools::TimedSdfBuilder>> builders;
  for (const char* backend : {tools::kCpuBackend, tools::kVulkanBackend}) {
    auto b = tools::makeTimedBuilder(backend, builderOptions);
    if (b) {
      builders.push_back(std::move(b.value()));
    } else {
      std::fprintf(stderr, "%s: %s\n", backend, b.error().message.c_str());
    }
  }
  const bool haveVulkan = builders.size() == 2;

  const std::vector<glm::vec3> points = tools::frameSamplePoints();
  std::printf("# autograsp-sdf-scaling: grab-box SDF build + 50 samples, median of %d runs\n",
              runs);
  std::printf("# code at commit %s\n", tools::describeBuild().c_str());
  std::printf("# vulkan device: %s; cpu: %s, far-field band %g m\n",
              haveVulkan ? builders[1]->device().c_str() : "none", builders[0]->device().c_str(),
              double(builderOptions.cpuExactBand));
  std::printf("| object | triangles | resolution | cpu ms | vulkan ms | cpu/vulkan |\n");
  std::printf("|---|---:|---:|---:|---:|---:|\n");
  std::fflush(stdout);
  for (const tools::ScalingObject& object : objects) {
    auto mesh = tools::loadScalingObject(object, 0.18f);
    if (!mesh) {
      std::fprintf(stderr, "%s: %s\n", object.name.c_str(), mesh.error().message.c_str());
      continue;
    }
    auto distance = MeshDistance::create(*mesh);
    if (!distance) {
      std::fprintf(stderr, "%s: %s\n", object.name.c_str(), distance.error().message.c_str());
      continue;
    }
    for (size_t b = 0; b < builders.size(); ++b) {
      if (builders[b]->prepare(*mesh, **distance) != Status::ok) builders.resize(b);
    }
    if (builders.empty()) return 1;  // the CPU builder failed: nothing left to compare
    for (uint32_t res : resolutions) {
      GridBox box = GridBox::referenceDefault();
      box.resolution = glm::uvec3(res);
      box.handFromBox = Pose{};
      const Pose objectFromHand{};  // box centred on the object
      std::vector<std::vector<double>> ms(builders.size());
      std::vector<float> samples;
      for (int r = 0; r <= runs; ++r) {  // run 0: warm-up (and the Vulkan mesh upload)
        for (size_t b = 0; b < builders.size(); ++b) {
          const auto t0 = Clock::now();
          if (builders[b]->buildAndSample(objectFromHand, box, points, samples) != Status::ok) {
            std::fprintf(stderr, "%s failed on %s\n", builders[b]->name().c_str(),
                         object.name.c_str());
            if (b == 0) return 1;
            builders.resize(b);
            break;
          }
          if (r > 0)
            ms[b].push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
        }
      }
      const double c = tools::medianOf(ms[0]);
      const double g = ms.size() > 1 ? tools::medianOf(ms[1]) : NAN;
      std::printf("| %s | %zu | %u^3 | %.2f | %.2f | %.2f |", object.name.c_str(),
                  mesh->triangleCount(), res, c, g, c / g);
      if (builderOptions.vulkanProfile && builders.size() > 1) {
        std::printf(" passes ms:");
        for (double t : builders[1]->passTimesMs()) std::printf(" %.2f", t);
      }
      std::printf("\n");
      std::fflush(stdout);
    }
  }
  return 0;
}
