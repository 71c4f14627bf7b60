#include "sdf_backends.h"

#include <algorithm>
#include <cmath>
#include <thread>

#include "io/mesh_io.h"
#include "io/shapes.h"
#include "sdf/sdf_cpu.h"

#ifdef SDFG_TOOLS_HAVE_VULKAN
#include "vulkan/vk_sdf_builder.h"
#include "vulkan_device/vk_standalone.h"
#endif

namespace sdfg::tools {
namespace {

class CpuTimedBuilder final : public TimedSdfBuilder {
 public:
  CpuTimedBuilder(unsigned threads, float exactBand)
      : threads_(threads ? threads : std::max(1u, std::thread::hardware_concurrency())),
        builder_(threads_) {
    options_.exactBand = exactBand;
  }
  std::string name() const override { return kCpuBackend; }
  std::string device() const override { return std::to_string(threads_) + " threads"; }
  Status prepare(const TriangleMesh&, const MeshDistance& distance) override {
    distance_ = &distance;
    return Status::ok;
  }
  Status build(const Pose& objectFromHand, const GridBox& box, SdfGrid& out) override {
    if (!distance_) return Status::invalid_argument;
    return builder_.build(*distance_, objectFromHand, box, out, options_);
  }
  Status buildAndSample(const Pose& objectFromHand, const GridBox& box,
                        std::span<const glm::vec3> points, std::vector<float>& samples) override {
    if (Status s = build(objectFromHand, box, grid_); s != Status::ok) return s;
    samples.resize(points.size());
    for (size_t i = 0; i < points.size(); ++i) samples[i] = grid_.sampleNormalized(points[i]);
    return Status::ok;
  }

 private:
  unsigned threads_;
  CpuSdfBuilder builder_;
  CpuSdfOptions options_;
  const MeshDistance* distance_ = nullptr;
  SdfGrid grid_;
};

#ifdef SDFG_TOOLS_HAVE_VULKAN
// Lavapipe builds a 64^3 grid of an open 70k-triangle mesh in about 30 s; a wait this long means
// the device hangs.
constexpr uint64_t kWaitNs = 600'000'000'000ull;

class VulkanTimedBuilder final : public TimedSdfBuilder {
 public:
  VulkanTimedBuilder(std::unique_ptr<StandaloneVulkan> vulkan, std::unique_ptr<VkSdfBuilder> gpu)
      : vulkan_(std::move(vulkan)), gpu_(std::move(gpu)) {}
  ~VulkanTimedBuilder() override { gpu_.reset(); }  // before the device it was made on
  std::string name() const override { return kVulkanBackend; }
  std::string device() const override { return vulkan_->deviceName(); }
  Status prepare(const TriangleMesh& mesh, const MeshDistance&) override {
    return gpu_->setMesh(mesh);
  }
  Status build(const Pose& objectFromHand, const GridBox& box, SdfGrid& out) override {
    if (Status s = finish(gpu_->submitBuild(box, objectFromHand, {}, true)); s != Status::ok) {
      return s;
    }
    if (!gpu_->grid()) return Status::internal;
    out = *gpu_->grid();
    return Status::ok;
  }
  Status buildAndSample(const Pose& objectFromHand, const GridBox& box,
                        std::span<const glm::vec3> points, std::vector<float>& samples) override {
    if (Status s = finish(gpu_->submitBuild(box, objectFromHand, points)); s != Status::ok) {
      return s;
    }
    samples.assign(gpu_->samples().begin(), gpu_->samples().end());
    return Status::ok;
  }
  std::vector<double> passTimesMs() const override {
    return {gpu_->passTimesMs().begin(), gpu_->passTimesMs().end()};
  }

 private:
  Status finish(Status submitted) {
    if (submitted != Status::ok) return submitted;
    const SdfPoll p = gpu_->wait(kWaitNs);
    if (p == SdfPoll::ready) return Status::ok;
    return p == SdfPoll::pending ? Status::internal : Status::device_lost;
  }

  std::unique_ptr<StandaloneVulkan> vulkan_;
  std::unique_ptr<VkSdfBuilder> gpu_;
};
#endif

}  // namespace

std::string backendTitle(const std::string& backend) {
  if (backend == kCpuBackend) return "CPU";
  if (backend == kVulkanBackend) return "Vulkan";
  return backend;
}

Result<std::unique_ptr<TimedSdfBuilder>> makeTimedBuilder(const std::string& backend,
                                                          const TimedBuilderOptions& options) {
  if (backend == kCpuBackend) {
    return std::unique_ptr<TimedSdfBuilder>(
        new CpuTimedBuilder(options.cpuThreads, options.cpuExactBand));
  }
  if (backend != kVulkanBackend) {
    return makeError(Status::invalid_argument, "unknown SDF backend \"" + backend + "\"");
  }
#ifdef SDFG_TOOLS_HAVE_VULKAN
  auto vulkan = StandaloneVulkan::create({});
  if (!vulkan) {
    // StandaloneVulkan's messages start with "vulkan: "; ours already names it.
    std::string why = vulkan.error().message;
    if (why.rfind("vulkan: ", 0) == 0) why.erase(0, 8);
    return makeError(Status::unsupported, "no Vulkan device: " + why);
  }
  VkSdfOptions vkOptions;
  vkOptions.profile = options.vulkanProfile;
  vkOptions.workGroupSize = options.vulkanWorkGroupSize;
  auto gpu = VkSdfBuilder::create(vulkan.value()->device(), vkOptions);
  if (!gpu) {
    return makeError(Status::unsupported, "Vulkan SDF builder unavailable on " +
                                              vulkan.value()->deviceName() + ": " +
                                              gpu.error().message);
  }
  return std::unique_ptr<TimedSdfBuilder>(
      new VulkanTimedBuilder(std::move(vulkan.value()), std::move(gpu.value())));
#else
  return makeError(Status::unsupported,
                   "no Vulkan device: built without Vulkan (headers or glslangValidator missing)");
#endif
}

std::vector<ScalingObject> scalingTori(bool quick) {
  // ring x tube x 2 triangles.
  const std::vector<std::pair<int, int>> full = {{72, 36},   {144, 72},  {224, 112},
                                                 {316, 158}, {448, 224}, {632, 316}};
  const std::vector<std::pair<int, int>> small = {{24, 12}, {48, 24}, {72, 36}};
  std::vector<ScalingObject> out;
  for (const auto& [ring, tube] : quick ? small : full) {
    TriangleMesh m = makeTorus(0.05f, 0.02f, ring, tube);
    out.push_back({"torus-" + std::to_string(m.triangleCount()), std::nullopt, std::move(m)});
  }
  return out;
}

const std::vector<std::string>& scalingMeshFiles() {
  static const std::vector<std::string> files = {"torus.obj",
                                                 "newell-teapot.obj",
                                                 "stanford-bunny.obj",
                                                 "stanford-armadillo-100k.obj",
                                                 "stanford-dragon-100k.ply",
                                                 "igea-268k.obj",
                                                 "stanford-armadillo-400k-subdiv.obj"};
  return files;
}

std::vector<ScalingObject> scalingMeshes(const std::filesystem::path& dir) {
  std::vector<ScalingObject> out;
  for (const std::string& f : scalingMeshFiles()) {
    const std::filesystem::path path = dir / f;
    std::error_code ec;
    if (std::filesystem::is_regular_file(path, ec)) {
      out.push_back({path.stem().string(), path, {}});
    }
  }
  return out;
}

Result<TriangleMesh> loadScalingObject(const ScalingObject& object, float diagonal) {
  TriangleMesh loaded;
  const TriangleMesh* mesh = &object.mesh;
  if (object.path) {
    auto result = loadMesh(*object.path);
    if (!result) return result.error();
    loaded = std::move(result->mesh);
    mesh = &loaded;
  }
  if (auto error = validateMesh(mesh->positions, mesh->indices)) {
    return makeError(error->code, object.name + ": " + error->message);
  }
  return normalizedToDiagonal(*mesh, diagonal);
}

std::vector<glm::vec3> frameSamplePoints() {
  std::vector<glm::vec3> points;
  for (int i = 0; i < 50; ++i) points.emplace_back(0.2f + 0.012f * float(i), 0.5f, 0.45f);
  return points;
}

double medianOf(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace sdfg::tools
