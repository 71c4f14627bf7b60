// autograsp-sdf-scaling: grab-box SDF build time against triangle count and resolution, the CPU
// builder and the Vulkan builder side by side in one run, with the speed-up ratio.
//
//   autograsp-sdf-scaling [--meshes DIR] [--runs N] [--res 16,32,64] [--quick] [--profile]
//
// --only torus|meshes keeps one group of rows. --wg sets the compute work-group size (default 64).
// --profile adds the Vulkan pass times (GPU timestamps) of the last run to each row.
//
// Objects: a procedural torus tessellated to 5k .. 400k triangles (the same surface at every
// count), then the shared test meshes when DIR (default ../shared/meshes) has them, each scaled
// to an 18 cm diagonal like the benchmark's objects. The box is the reference 21.33 cm cube
// placed over the object. Times are medians of N runs (default 5) after one warm-up:
//   cpu    CpuSdfBuilder::build, plus trilinear sampling of the points on the CPU
//   vulkan VkSdfBuilder::submitBuild of the SDF + sampling in one submission, until its fence
//          signals (wall time as the frame sees it a frame later, not just GPU time)
// Both sample the paper's 50 points (5 fingers x 10 curl steps).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "mesh.h"
#include "mesh_distance.h"
#include "mesh_io.h"
#include "sdf_cpu.h"
#include "sdf_grid.h"
#include "shapes.h"
#include "vk_sdf_builder.h"
#include "vk_standalone.h"

namespace {

using namespace sdfg;
using Clock = std::chrono::steady_clock;

// The same surface at any triangle count: the core's torus (ring 5 cm, tube 2 cm).
TriangleMesh torus(int ring, int tube) {
  return makeTorus(0.05f, 0.02f, ring, tube);
}

// A mesh file through the project's loader (OBJ or PLY); nothing when it cannot be read.
std::optional<TriangleMesh> readObj(const std::filesystem::path& path) {
  auto loaded = loadMesh(path);
  if (!loaded) return std::nullopt;
  return std::move(loaded->mesh);
}

double medianMs(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? NAN : v[v.size() / 2];
}

struct Row {
  std::string object;
  size_t triangles;
  uint32_t res;
  double cpuMs, vkMs;
};

}  // namespace

int main(int argc, char** argv) {
  std::filesystem::path meshDir = "../shared/meshes";
  int runs = 5;
  bool quick = false, profile = false, torusRows = true, meshRows = true;
  uint32_t workGroup = 64;
  std::vector<uint32_t> resolutions = {16, 32, 64};
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--meshes" && i + 1 < argc) {
      meshDir = argv[++i];
    } else if (a == "--runs" && i + 1 < argc) {
      runs = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--wg" && i + 1 < argc) {
      workGroup = uint32_t(std::max(1, std::atoi(argv[++i])));
    } else if (a == "--only" && i + 1 < argc) {
      const std::string which = argv[++i];
      torusRows = which == "torus";
      meshRows = which == "meshes";
    } else if (a == "--profile") {
      profile = true;
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
                   "[--wg N] [--only torus|meshes]\n",
                   argv[0]);
      return 2;
    }
  }

  std::vector<std::pair<std::string, TriangleMesh>> objects;
  // ring x tube x 2 triangles: ~5k, 20k, 50k, 100k, 200k, 400k.
  const std::vector<std::pair<int, int>> tess = {{72, 36},   {144, 72},  {224, 112},
                                                 {316, 158}, {448, 224}, {632, 316}};
  for (const auto& [ring, tube] : tess) {
    if (!torusRows || (quick && ring > 316)) break;
    objects.emplace_back("torus", normalizedToDiagonal(torus(ring, tube), 0.18f));
  }
  if (!quick && meshRows) {
    for (const char* name :
         {"newell-teapot.obj", "stanford-bunny.obj", "stanford-armadillo-100k.obj",
          "stanford-dragon-100k.obj", "igea-268k.obj", "stanford-armadillo-400k-subdiv.obj"}) {
      if (auto m = readObj(meshDir / name)) {
        objects.emplace_back(name, normalizedToDiagonal(*m, 0.18f));
      } else {
        std::fprintf(stderr, "%s: not found or unreadable in %s\n", name, meshDir.c_str());
      }
    }
  }

  auto vk = StandaloneVulkan::create({});
  std::unique_ptr<VkSdfBuilder> gpu;
  std::string deviceName = "none";
  if (vk) {
    VkSdfOptions options;
    options.profile = profile;
    options.workGroupSize = workGroup;
    auto b = VkSdfBuilder::create(vk.value()->device(), options);
    if (b) {
      gpu = std::move(b.value());
      deviceName = vk.value()->deviceName();
    } else {
      std::fprintf(stderr, "vulkan builder unavailable: %s\n", b.error().message.c_str());
    }
  } else {
    std::fprintf(stderr, "no Vulkan device: %s\n", vk.error().message.c_str());
  }
  CpuSdfBuilder cpu;

  // 50 points along a diagonal of the box: where they are does not change the cost.
  std::vector<glm::vec3> points;
  for (int i = 0; i < 50; ++i) points.emplace_back(0.2f + 0.012f * float(i), 0.5f, 0.45f);

  std::printf("# autograsp-sdf-scaling: grab-box SDF build + 50 samples, median of %d runs\n",
              runs);
  std::printf("# vulkan device: %s; cpu threads: %u\n", deviceName.c_str(),
              std::max(1u, std::thread::hardware_concurrency()));
  std::printf("| object | triangles | resolution | cpu ms | vulkan ms | cpu/vulkan |\n");
  std::printf("|---|---:|---:|---:|---:|---:|\n");
  std::fflush(stdout);
  for (const auto& [name, mesh] : objects) {
    auto distance = MeshDistance::create(mesh);
    if (!distance) {
      std::fprintf(stderr, "%s: %s\n", name.c_str(), distance.error().message.c_str());
      continue;
    }
    if (gpu && gpu->setMesh(mesh) != Status::ok) gpu.reset();
    for (uint32_t res : resolutions) {
      GridBox box = GridBox::referenceDefault();
      box.resolution = glm::uvec3(res);
      box.handFromBox = Pose{};
      const Pose objectFromHand{};  // box centred on the object
      std::vector<double> cpuMs, vkMs;
      SdfGrid grid;
      for (int r = 0; r <= runs; ++r) {
        const auto t0 = Clock::now();
        if (cpu.build(**distance, objectFromHand, box, grid) != Status::ok) break;
        float sink = 0;
        for (const glm::vec3& p : points) sink += grid.sampleNormalized(p);
        const auto t1 = Clock::now();
        if (r > 0 && std::isfinite(sink)) {
          cpuMs.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
        }
        if (gpu) {
          const auto g0 = Clock::now();
          if (gpu->submitBuild(box, objectFromHand, points) != Status::ok ||
              gpu->wait(600'000'000'000ull) != SdfPoll::ready) {
            std::fprintf(stderr, "vulkan failed: %s\n", gpu->failure().c_str());
            gpu.reset();
          } else if (r > 0) {
            vkMs.push_back(std::chrono::duration<double, std::milli>(Clock::now() - g0).count());
          }
        }
      }
      const double c = medianMs(cpuMs), g = medianMs(vkMs);
      std::printf("| %s | %zu | %u^3 | %.2f | %.2f | %.2f |", name.c_str(), mesh.triangleCount(),
                  res, c, g, c / g);
      if (profile && gpu) {
        std::printf(" passes ms:");
        for (double t : gpu->passTimesMs()) std::printf(" %.2f", t);
      }
      std::printf("\n");
      std::fflush(stdout);
    }
  }
  return 0;
}
