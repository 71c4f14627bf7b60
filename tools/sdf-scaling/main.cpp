// autograsp-sdf-scaling: grab-box SDF build time against triangle count and resolution, the CPU
// builder and the Vulkan builder side by side in one run, with the speed-up ratio.
//
//   autograsp-sdf-scaling [--meshes DIR] [--runs N] [--res 16,32,64] [--quick] [--profile]
//
// --only torus|meshes keeps one group of rows. --wg sets the compute work-group size (default 64).
// --profile adds the Vulkan pass times (GPU timestamps) of the last run to each row.
// --far-band M runs the CPU builder in its far-field mode (CpuSdfOptions::exactBand = M metres).
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
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "mesh/mesh_distance.h"
#include "sdf/sdf_grid.h"
#include "sdf_backends.h"

namespace {

using namespace sdfg;
using Clock = std::chrono::steady_clock;

}  // namespace

int main(int argc, char** argv) {
  std::filesystem::path meshDir = "../shared/meshes";
  int runs = 5;
  bool quick = false, torusRows = true, meshRows = true;
  tools::TimedBuilderOptions builderOptions;
  std::vector<uint32_t> resolutions = {16, 32, 64};
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--meshes" && i + 1 < argc) {
      meshDir = argv[++i];
    } else if (a == "--runs" && i + 1 < argc) {
      runs = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--wg" && i + 1 < argc) {
      builderOptions.vulkanWorkGroupSize = uint32_t(std::max(1, std::atoi(argv[++i])));
    } else if (a == "--only" && i + 1 < argc) {
      const std::string which = argv[++i];
      torusRows = which == "torus";
      meshRows = which == "meshes";
    } else if (a == "--far-band" && i + 1 < argc) {
      builderOptions.cpuExactBand = std::strtof(argv[++i], nullptr);
    } else if (a == "--profile") {
      builderOptions.vulkanProfile = true;
    } else if (a == "--quick") {
      quick = true;
    } else if (a == "--res" && i + 1 < argc) {
      resolutions.clear();
      std::stringstream s(argv[++i]);
      std::string r;
      while (std::getline(s, r, ',')) resolutions.push_back(uint32_t(std::atoi(r.c_str())));
    } else {
      std::fprintf(stderr,
                   "usage: %s [--meshes DIR] [--runs N] [--res 16,32,64] [--quick] [--profile] "
                   "[--wg N] [--only torus|meshes] [--far-band M]\n",
                   argv[0]);
      return 2;
    }
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
