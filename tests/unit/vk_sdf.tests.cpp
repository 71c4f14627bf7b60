// The Vulkan SDF backend on a real driver (Mesa's lavapipe under ctest) with the Khronos
// validation layer on: any validation warning or error fails the test; no device -> skipped.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <fstream>
#include <random>
#include <span>
#include <sstream>
#include <thread>

#include <unistd.h>
#include <cstring>
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
// From the sanitizer runtime (compiler-rt's allocator_interface.h, which GCC does not install).
extern "C" size_t __sanitizer_get_current_allocated_bytes();
#endif

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "io/mesh_io.h"
#include "io/shapes.h"
#include "mesh/mesh.h"
#include "mesh/mesh_distance.h"
#include "sdf/sdf_cpu.h"
#include "sdf/sdf_grid.h"
#include "test_support.h"
#include "vulkan/vk_mesh_readback.h"
#include "vulkan/vk_sdf_backend.h"
#include "vulkan/vk_sdf_builder.h"
#include "vulkan/vk_sdf_builder_detail.h"
#include "vulkan_device/vk_standalone.h"

namespace {

using namespace sdfg;

// ---- Device ---------------------------------------------------------------------------------

std::unique_ptr<StandaloneVulkan> makeDevice() {
  StandaloneVulkanOptions options;
  options.validation = true;
  auto v = StandaloneVulkan::create(options);
  if (!v) {
    std::cout << "no Vulkan device: " << v.error().message << std::endl;
    return nullptr;
  }
  return std::move(v.value());
}

#define REQUIRE_DEVICE(var) \
  auto var = makeDevice();  \
  if (!var) SDFG_SKIP("no Vulkan 1.1 device with compute and validation");

// ---- Meshes ---------------------------------------------------------------------------------

// A mesh file through the project's loader (OBJ or PLY); nothing when it cannot be read.
std::optional<TriangleMesh> readObj(const std::filesystem::path& path) {
  auto loaded = loadMesh(path);
  if (!loaded) return std::nullopt;
  return std::move(loaded->mesh);
}

std::optional<TriangleMesh> sharedTestMesh(const std::string& name) {
  const auto path = test::sharedMesh(name);
  if (!path) return std::nullopt;
  auto mesh = readObj(*path);
  if (!mesh) return std::nullopt;
  return normalizedToDiagonal(*mesh, 0.18f);
}

// A torus in the XZ plane (the core's shape: closed, genus 1, outward counter-clockwise faces),
// so the tests that need no shared mesh run everywhere.
TriangleMesh localTorus(float major, float minor, int ring, int tube) {
  return makeTorus(major, minor, ring, tube);
}

// ---- Reference ------------------------------------------------------------------------------

glm::vec3 closestOnTriangle(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b,
                            const glm::vec3& c) {
  const glm::vec3 ab = b - a, ac = c - a, ap = p - a;
  const float d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const glm::vec3 bp = p - b;
  const float d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const glm::vec3 cp = p - c;
  const float d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  }
  const float denom = 1.0f / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

// Brute force over every triangle: exact distance, sign from the exact generalized winding
// number (double precision). Independent of the GPU's culling, flooding and hierarchy.
float referenceSdf(const TriangleMesh& m, const glm::vec3& p) {
  float best = INFINITY;
  double omega = 0.0;
  for (size_t t = 0; t < m.triangleCount(); ++t) {
    const glm::vec3& a = m.positions[m.indices[3 * t]];
    const glm::vec3& b = m.positions[m.indices[3 * t + 1]];
    const glm::vec3& c = m.positions[m.indices[3 * t + 2]];
    best = std::min(best, glm::length(p - closestOnTriangle(p, a, b, c)));
    const glm::dvec3 da = glm::dvec3(a) - glm::dvec3(p), db = glm::dvec3(b) - glm::dvec3(p),
                     dc = glm::dvec3(c) - glm::dvec3(p);
    const double la = glm::length(da), lb = glm::length(db), lc = glm::length(dc);
    const double det = glm::dot(da, glm::cross(db, dc));
    const double den =
        la * lb * lc + glm::dot(da, db) * lc + glm::dot(db, dc) * la + glm::dot(dc, da) * lb;
    omega += 2.0 * std::atan2(det, den);
  }
  return omega / (4.0 * M_PI) > 0.5 ? -best : best;
}

// The placement every mesh test uses: the box rotated and shifted so it clips the object (some
// triangles lie outside it) and the object itself rotated in hand space.
GridBox testBox(uint32_t n) {
  GridBox box;
  box.size = glm::vec3(0.2133f);
  box.resolution = glm::uvec3(n);
  box.handFromBox.position = glm::vec3(0.045f, -0.02f, 0.03f);
  box.handFromBox.orientation = glm::angleAxis(0.35f, glm::normalize(glm::vec3(1, 2, 0.5f)));
  return box;
}
Pose testObjectFromHand() {
  Pose p;
  p.orientation = glm::angleAxis(-0.6f, glm::normalize(glm::vec3(0.3f, 1, -0.2f)));
  p.position = glm::vec3(0.004f, -0.003f, 0.002f);
  return p;
}

// Builds on the GPU, waits, returns the read-back grid.
SdfGrid buildOnGpu(VkSdfBuilder& builder, const GridBox& box, const Pose& objectFromHand) {
  REQUIRE(builder.submitBuild(box, objectFromHand, {}, true) == Status::ok);
  REQUIRE(builder.wait(600'000'000'000ull) == SdfPoll::ready);
  REQUIRE(builder.grid() != nullptr);
  return *builder.grid();
}

// Compares the GPU grid with the reference at nodes chosen so that the brute force stays within
// a budget: every node when it fits, else half near the surface and half uniformly.
void compareWithReference(const TriangleMesh& mesh, const SdfGrid& gpu,
                          const Pose& objectFromHand) {
  const GridBox& box = gpu.box();
  const size_t nodes = box.nodeCount();
  const double budget = 4e7;  // triangle evaluations per grid
  const size_t wanted = size_t(std::max(200.0, budget / double(mesh.triangleCount())));
  const float h = box.maxSpacing();
  std::vector<size_t> chosen;
  if (wanted >= nodes) {
    for (size_t v = 0; v < nodes; ++v) chosen.push_back(v);
  } else {
    std::mt19937 rng(1234);
    std::vector<size_t> near;
    for (size_t v = 0; v < nodes; ++v) {
      if (std::abs(gpu.values()[v]) < 2.0f * h) near.push_back(v);
    }
    std::shuffle(near.begin(), near.end(), rng);
    near.resize(std::min(near.size(), wanted / 2));
    chosen = near;
    std::uniform_int_distribution<size_t> any(0, nodes - 1);
    while (chosen.size() < wanted) chosen.push_back(any(rng));
  }
  const Pose objectFromBox = objectFromHand * box.handFromBox;
  std::vector<float> ref(chosen.size());
  std::atomic<size_t> next{0};
  auto work = [&] {
    for (size_t i; (i = next.fetch_add(1)) < chosen.size();) {
      const size_t v = chosen[i];
      const uint32_t x = uint32_t(v % box.resolution.x);
      const uint32_t y = uint32_t((v / box.resolution.x) % box.resolution.y);
      const uint32_t z = uint32_t(v / (size_t(box.resolution.x) * box.resolution.y));
      ref[i] = referenceSdf(mesh, objectFromBox.transformPoint(box.nodeLocal(x, y, z)));
    }
  };
  std::thread other(work);
  work();
  other.join();

  size_t nearCount = 0, signChecked = 0, badNear = 0, badFar = 0, badSign = 0;
  float worstNear = 0, worstFar = 0;
  size_t worstNode = 0;
  float worstGpu = 0, worstRef = 0;
  for (size_t i = 0; i < chosen.size(); ++i) {
    const float g = gpu.values()[chosen[i]], r = ref[i];
    const float err = std::abs(g - r);
    if (std::abs(r) < h) {
      ++nearCount;
      worstNear = std::max(worstNear, err);
      if (err > 0.1f * h) ++badNear;
    }
    if (err > worstFar) {
      worstFar = err;
      worstNode = chosen[i];
      worstGpu = g;
      worstRef = r;
    }
    if (err > 0.5f * h) ++badFar;
    if (std::abs(r) > h) {
      ++signChecked;
      if ((g < 0) != (r < 0)) ++badSign;
    }
  }
  INFO("resolution " << box.resolution.x << ", " << chosen.size() << " nodes checked, " << nearCount
                     << " near the surface, " << signChecked << " sign-checked; worst error near "
                     << worstNear / h << " voxel, anywhere " << worstFar / h << " voxel (node "
                     << worstNode << ": gpu " << worstGpu / h << ", reference " << worstRef / h
                     << " voxel)");
  CHECK(badNear == 0);
  CHECK(badFar == 0);
  CHECK(badSign == 0);
  CHECK(nearCount > 0);
}

// Compares every node of the GPU grid with the CPU builder's (the project's reference: BVH
// closest point, pseudo-normal sign on closed meshes, fast winding number on open ones).
void compareWithCpuBuilder(const SdfGrid& gpu, const SdfGrid& cpu) {
  const float h = gpu.box().maxSpacing();
  size_t nearCount = 0, signChecked = 0, badNear = 0, badFar = 0, badSign = 0;
  float worstNear = 0, worstFar = 0;
  for (size_t v = 0; v < gpu.values().size(); ++v) {
    const float g = gpu.values()[v], r = cpu.values()[v];
    const float err = std::abs(g - r);
    if (std::abs(r) < h) {
      ++nearCount;
      worstNear = std::max(worstNear, err);
      if (err > 0.1f * h) ++badNear;
    }
    worstFar = std::max(worstFar, err);
    if (err > 0.5f * h) ++badFar;
    if (std::abs(r) > h) {
      ++signChecked;
      if ((g < 0) != (r < 0)) ++badSign;
    }
  }
  INFO("resolution " << gpu.box().resolution.x << ": every node, " << nearCount
                     << " near the surface, " << signChecked << " sign-checked; worst error near "
                     << worstNear / h << " voxel, anywhere " << worstFar / h << " voxel");
  CHECK(badNear == 0);
  CHECK(badFar == 0);
  CHECK(badSign == 0);
  CHECK(nearCount > 0);
}

void checkMesh(const std::string& file) {
  REQUIRE_DEVICE(vk);
  const auto mesh = sharedTestMesh(file);
  if (!mesh) SDFG_SKIP("shared mesh " + file + " not found");
  auto builder = VkSdfBuilder::create(vk->device());
  REQUIRE(builder.ok());
  REQUIRE((*builder)->setMesh(*mesh) == Status::ok);
  auto distance = MeshDistance::create(*mesh);
  REQUIRE(distance.ok());
  CpuSdfBuilder cpuBuilder;
  for (uint32_t n : {16u, 32u, 64u}) {
    CAPTURE(file, n);
    const SdfGrid gpu = buildOnGpu(**builder, testBox(n), testObjectFromHand());
    SdfGrid cpu;
    REQUIRE(cpuBuilder.build(**distance, testObjectFromHand(), testBox(n), cpu) == Status::ok);
    compareWithCpuBuilder(gpu, cpu);
  }
  CHECK(vk->messageCount() == 0);
}

}  // namespace

TEST_CASE("Vulkan SDF matches the reference on the torus", "[gpu][vk_sdf]") {
  checkMesh("torus.obj");
}
TEST_CASE("Vulkan SDF matches the reference on the open teapot", "[gpu][vk_sdf]") {
  checkMesh("newell-teapot.obj");
}
TEST_CASE("Vulkan SDF matches the reference on the open bunny", "[gpu][vk_sdf]") {
  checkMesh("stanford-bunny.obj");
}
TEST_CASE("Vulkan SDF matches the reference on the armadillo", "[gpu][vk_sdf]") {
  checkMesh("stanford-armadillo-100k.obj");
}
TEST_CASE("Vulkan SDF matches the reference on the dragon", "[gpu][vk_sdf]") {
  checkMesh("stanford-dragon-100k.obj");
}
TEST_CASE("Vulkan SDF matches the reference on the igea scan", "[gpu][vk_sdf]") {
  checkMesh("igea-268k.obj");
}
TEST_CASE("Vulkan SDF matches the reference on the 400k armadillo", "[gpu][vk_sdf]") {
  checkMesh("stanford-armadillo-400k-subdiv.obj");
}

TEST_CASE("Vulkan SDF matches the reference on a non-cubic box with anisotropic spacing",
          "[gpu][vk_sdf]") {
  REQUIRE_DEVICE(vk);
  const TriangleMesh torus = localTorus(0.05f, 0.018f, 40, 20);
  auto builder = VkSdfBuilder::create(vk->device());
  REQUIRE(builder.ok());
  REQUIRE((*builder)->setMesh(torus) == Status::ok);
  GridBox box = testBox(16);
  box.size = glm::vec3(0.2f, 0.13f, 0.24f);
  box.resolution = glm::uvec3(20, 24, 28);
  const SdfGrid gpu = buildOnGpu(**builder, box, testObjectFromHand());
  compareWithReference(torus, gpu, testObjectFromHand());
  CHECK(vk->messageCount() == 0);
}

TEST_CASE("Vulkan sampling equals CPU trilinear sampling of the same grid", "[gpu][vk_sdf]") {
  REQUIRE_DEVICE(vk);
  auto builder = VkSdfBuilder::create(vk->device());
  REQUIRE(builder.ok());
  VkSdfBuilder& b = **builder;
  REQUIRE(b.setMesh(localTorus(0.05f, 0.018f, 40, 20)) == Status::ok);
  GridBox box = testBox(16);
  box.resolution = glm::uvec3(17, 23, 31);

  // Random points, some outside the box (clamped), plus every box corner and a few nodes.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-0.2f, 1.2f);
  std::vector<glm::vec3> points;
  for (int i = 0; i < 5000; ++i) points.emplace_back(u(rng), u(rng), u(rng));
  for (int c = 0; c < 8; ++c) points.emplace_back(c & 1, (c >> 1) & 1, (c >> 2) & 1);
  points.emplace_back(0.5f, 0.5f, 0.5f);
  points.emplace_back(3.0f / 16.0f, 5.0f / 22.0f, 29.0f / 30.0f);

  SECTION("in the build's own submission") {
    REQUIRE(b.submitBuild(box, testObjectFromHand(), points, true) == Status::ok);
    REQUIRE(b.wait(60'000'000'000ull) == SdfPoll::ready);
    REQUIRE(b.grid() != nullptr);
    REQUIRE(b.samples().size() == points.size());
    size_t mismatches = 0;
    for (size_t i = 0; i < points.size(); ++i) {
      const float cpu = b.grid()->sampleNormalized(points[i]);
      if (std::abs(b.samples()[i] - cpu) > 1e-6f * std::max(1.0f, std::abs(cpu))) ++mismatches;
    }
    CHECK(mismatches == 0);
  }
  SECTION("again on the built grid at new points, with no rebuild") {
    REQUIRE(b.submitBuild(box, testObjectFromHand(), {}, true) == Status::ok);
    REQUIRE(b.wait(60'000'000'000ull) == SdfPoll::ready);
    const SdfGrid grid = *b.grid();
    CHECK(b.samples().empty());
    REQUIRE(b.submitSample(points) == Status::ok);
    REQUIRE(b.wait(60'000'000'000ull) == SdfPoll::ready);
    REQUIRE(b.samples().size() == points.size());
    size_t mismatches = 0;
    for (size_t i = 0; i < points.size(); ++i) {
      const float cpu = grid.sampleNormalized(points[i]);
      if (std::abs(b.samples()[i] - cpu) > 1e-6f * std::max(1.0f, std::abs(cpu))) ++mismatches;
    }
    CHECK(mismatches == 0);
  }
  CHECK(vk->messageCount() == 0);
}

namespace {

using vk_sdf_detail::FloodPath;

// Sets the builder's flood for the scope (vk_sdf_detail::floodTestHooks) and restores it after.
struct ForcedFlood {
  explicit ForcedFlood(FloodPath path) { vk_sdf_detail::floodTestHooks.force = path; }
  ~ForcedFlood() { vk_sdf_detail::floodTestHooks.force = FloodPath::automatic; }
  ForcedFlood(const ForcedFlood&) = delete;
  ForcedFlood& operator=(const ForcedFlood&) = delete;
};

struct BuildResult {
  SdfGrid grid;
  std::vector<float> samples;
};

BuildResult buildAndSample(VkSdfBuilder& b, const GridBox& box, std::span<const glm::vec3> points,
                           FloodPath path) {
  const ForcedFlood flood(path);
  REQUIRE(b.submitBuild(box, testObjectFromHand(), points, true) == Status::ok);
  REQUIRE(b.wait(600'000'000'000ull) == SdfPoll::ready);
  REQUIRE(b.grid() != nullptr);
  return {*b.grid(), std::vector<float>(b.samples().begin(), b.samples().end())};
}

size_t bitDifferences(std::span<const float> x, std::span<const float> y) {
  REQUIRE(x.size() == y.size());
  size_t n = 0;
  for (size_t i = 0; i < x.size(); ++i) n += std::memcmp(&x[i], &y[i], sizeof(float)) != 0;
  return n;
}

// The floods against each other on the same mesh and box: the one-group flood (grids up to 4096
// nodes, shaders/sdf_flood_group.comp), the per-node stepwise flood (sdf_jfa.comp) and the wide
// stepwise flood (sdf_jfa_wide.comp), each forced, and the device's own choice: every node value
// and every sample equal bit for bit (the same steps, candidates and comparisons), the samples
// also equal to the CPU's trilinear sampling of the read-back grid, and no validation message.
void checkFloodPaths(const std::string& name, const TriangleMesh& mesh) {
  REQUIRE_DEVICE(vk);
  auto builder = VkSdfBuilder::create(vk->device());
  REQUIRE(builder.ok());
  VkSdfBuilder& b = **builder;
  REQUIRE(b.setMesh(mesh) == Status::ok);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-0.1f, 1.1f);
  std::vector<glm::vec3> points;
  for (int i = 0; i < 3000; ++i) points.emplace_back(u(rng), u(rng), u(rng));
  const bool cpuDevice = b.context().properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
  auto& hooks = vk_sdf_detail::floodTestHooks;
  // 16^3, and the largest grids on either side of the one-group limit.
  for (const glm::uvec3 res : {glm::uvec3(16), glm::uvec3(20, 10, 20), glm::uvec3(17, 16, 16)}) {
    CAPTURE(name, res.x, res.y, res.z);
    GridBox box = testBox(16);
    box.resolution = res;
    const bool fits = box.nodeCount() <= 4096;
    uint32_t groups = hooks.groupFloods, wides = hooks.wideFloods;
    const BuildResult group = buildAndSample(b, box, points, FloodPath::group);
    // Too large for one group: the device's stepwise flood instead.
    CHECK(hooks.groupFloods - groups == (fits ? 1u : 0u));
    CHECK(hooks.wideFloods - wides == (fits || cpuDevice ? 0u : 1u));
    groups = hooks.groupFloods, wides = hooks.wideFloods;
    const BuildResult perNode = buildAndSample(b, box, points, FloodPath::perNode);
    const BuildResult wide = buildAndSample(b, box, points, FloodPath::wide);
    CHECK(hooks.groupFloods == groups);
    CHECK(hooks.wideFloods - wides == 1u);
    groups = hooks.groupFloods, wides = hooks.wideFloods;
    const BuildResult automatic = buildAndSample(b, box, points, FloodPath::automatic);
    // CPU devices: the one-group flood where it fits; GPUs: the wide flood where it fits.
    CHECK(hooks.groupFloods - groups == (cpuDevice && fits ? 1u : 0u));
    CHECK(hooks.wideFloods - wides == (!cpuDevice && fits ? 1u : 0u));
    for (const BuildResult* other : {&perNode, &wide, &automatic}) {
      CHECK(bitDifferences(group.grid.values(), other->grid.values()) == 0);
      CHECK(bitDifferences(group.samples, other->samples) == 0);
    }
    size_t mismatches = 0;
    for (size_t i = 0; i < points.size(); ++i) {
      const float cpu = automatic.grid.sampleNormalized(points[i]);
      if (std::abs(automatic.samples[i] - cpu) > 1e-6f * std::max(1.0f, std::abs(cpu))) {
        ++mismatches;
      }
    }
    CHECK(mismatches == 0);
    // The grid sampled again with no rebuild (sdf_sample.comp on the values the flood wrote).
    REQUIRE(b.submitSample(points) == Status::ok);
    REQUIRE(b.wait(600'000'000'000ull) == SdfPoll::ready);
    CHECK(bitDifferences(b.samples(), automatic.samples) == 0);
  }
  // 32^3 floods step by step, one invocation per node on every device; the wide flood agrees.
  const uint32_t groups = hooks.groupFloods, wides = hooks.wideFloods;
  const BuildResult automatic = buildAndSample(b, testBox(32), points, FloodPath::automatic);
  CHECK(hooks.groupFloods == groups);
  CHECK(hooks.wideFloods == wides);
  const BuildResult other = buildAndSample(b, testBox(32), points, FloodPath::wide);
  CHECK(bitDifferences(automatic.grid.values(), other.grid.values()) == 0);
  CHECK(bitDifferences(automatic.samples, other.samples) == 0);
  CHECK(vk->messageCount() == 0);
}

}  // namespace

TEST_CASE("The one-group flood equals the stepwise flood on the embedded objects",
          "[gpu][vk_sdf]") {
  for (NamedMesh& object : embeddedObjects()) {
    checkFloodPaths(object.name, normalizedToDiagonal(object.mesh, 0.18f));
  }
}

TEST_CASE("The one-group flood equals the stepwise flood on open meshes (winding-number sign)",
          "[gpu][vk_sdf]") {
  // A torus with a band of triangles removed: open, so signed by the winding number, whose
  // final pass runs after the one-group flood as its own dispatch.
  TriangleMesh open = localTorus(0.05f, 0.018f, 40, 20);
  open.indices.erase(open.indices.begin(), open.indices.begin() + 3 * 40);
  checkFloodPaths("open torus", open);
  if (const auto bunny = sharedTestMesh("stanford-bunny.obj")) checkFloodPaths("bunny", *bunny);
}

TEST_CASE("The one-group flood equals the stepwise flood on the shared meshes", "[gpu][vk_sdf]") {
  for (const char* file : {"torus.obj", "stanford-armadillo-100k.obj", "newell-teapot.obj"}) {
    const auto mesh = sharedTestMesh(file);
    if (!mesh) {
      WARN("shared mesh " << file << " not found");
      continue;
    }
    checkFloodPaths(file, *mesh);
  }
}

namespace {

// A host-visible storage buffer made with the test's own loader, as an app would have.
struct AppBuffer {
  VkDevice device = VK_NULL_HANDLE;
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  AppBuffer(const VulkanDevice& d, const void* data, size_t bytes) : device(d.device) {
    auto info = vkStruct<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
    info.size = bytes;
    info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_VERTEX_BUFFER_BIT |
                 VK_BUFFER_USAGE_INDEX_BUFFER_BIT;
    REQUIRE(vkCreateBuffer(device, &info, nullptr, &buffer) == VK_SUCCESS);
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device, buffer, &req);
    VkPhysicalDeviceMemoryProperties props;
    vkGetPhysicalDeviceMemoryProperties(d.physicalDevice, &props);
    uint32_t type = 0;
    const VkMemoryPropertyFlags want =
        VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    while (type < props.memoryTypeCount &&
           (!(req.memoryTypeBits & (1u << type)) ||
            (props.memoryTypes[type].propertyFlags & want) != want)) {
      ++type;
    }
    REQUIRE(type < props.memoryTypeCount);
    auto alloc = vkStruct<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = type;
    REQUIRE(vkAllocateMemory(device, &alloc, nullptr, &memory) == VK_SUCCESS);
    REQUIRE(vkBindBufferMemory(device, buffer, memory, 0) == VK_SUCCESS);
    void* mapped = nullptr;
    REQUIRE(vkMapMemory(device, memory, 0, VK_WHOLE_SIZE, 0, &mapped) == VK_SUCCESS);
    std::memcpy(mapped, data, bytes);
    vkUnmapMemory(device, memory);
  }
  ~AppBuffer() {
    vkDestroyBuffer(device, buffer, nullptr);
    vkFreeMemory(device, memory, nullptr);
  }
  AppBuffer(const AppBuffer&) = delete;
  AppBuffer& operator=(const AppBuffer&) = delete;
};

}  // namespace

TEST_CASE("Vulkan SDF reads app-owned buffers with stride and offset and 16-bit indices",
          "[gpu][vk_sdf]") {
  REQUIRE_DEVICE(vk);
  const TriangleMesh torus = localTorus(0.05f, 0.018f, 40, 20);
  REQUIRE(torus.vertexCount() < 65536);
  // Interleaved vertices: 2 floats of padding before the first, then position + normal + one
  // float (28-byte stride), as a skinned mesh's vertex buffer might be.
  const uint32_t strideFloats = 7, leadFloats = 2;
  std::vector<float> vertices(leadFloats + strideFloats * torus.vertexCount(), -7.0f);
  for (size_t v = 0; v < torus.vertexCount(); ++v) {
    for (int k = 0; k < 3; ++k) vertices[leadFloats + strideFloats * v + k] = torus.positions[v][k];
  }
  // 16-bit indices after three leading ones (a 6-byte offset: not a multiple of 4).
  std::vector<uint16_t> indices = {0xffff, 0xffff, 0xffff};
  for (uint32_t i : torus.indices) indices.push_back(uint16_t(i));
  if (indices.size() % 2) indices.push_back(0xffff);
  AppBuffer vb(vk->device(), vertices.data(), vertices.size() * 4);
  AppBuffer ib(vk->device(), indices.data(), indices.size() * 2);

  auto builder = VkSdfBuilder::create(vk->device());
  REQUIRE(builder.ok());
  VkSdfBuilder& b = **builder;
  REQUIRE(b.setMesh(torus) == Status::ok);
  const SdfGrid fromArrays = buildOnGpu(b, testBox(16), testObjectFromHand());

  VkMeshBuffers m;
  m.positions = vb.buffer;
  m.positionOffset = leadFloats * 4;
  m.positionStride = strideFloats * 4;
  m.vertexCount = uint32_t(torus.vertexCount());
  m.indices = ib.buffer;
  m.indexOffset = 3 * 2;
  m.indexType = VK_INDEX_TYPE_UINT16;
  m.indexCount = uint32_t(torus.indices.size());
  REQUIRE(b.setMesh(m) == Status::ok);
  const SdfGrid fromBuffers = buildOnGpu(b, testBox(16), testObjectFromHand());

  // Not bit-identical: the upload reorders triangles, so ties between triangles at equal
  // distance (a shared edge or vertex) seed the flood differently. Both must be as accurate.
  float worst = 0.0f;
  for (size_t v = 0; v < fromArrays.values().size(); ++v) {
    worst = std::max(worst, std::abs(fromArrays.values()[v] - fromBuffers.values()[v]));
  }
  CHECK(worst < 0.1f * testBox(16).maxSpacing());
  compareWithReference(torus, fromBuffers, testObjectFromHand());

  SECTION("misaligned or empty descriptions are refused") {
    VkMeshBuffers bad = m;
    bad.positionStride = 14;
    CHECK(b.setMesh(bad) == Status::invalid_argument);
    bad = m;
    bad.indexOffset = 3;
    CHECK(b.setMesh(bad) == Status::invalid_argument);
    bad = m;
    bad.indexCount = 4;
    CHECK(b.setMesh(bad) == Status::invalid_argument);
    bad = m;
    bad.positions = VK_NULL_HANDLE;
    CHECK(b.setMesh(bad) == Status::invalid_argument);
  }
  SECTION("the mesh read back (vk_mesh_readback.h) is the arrays, and the indices come on ask") {
    auto made = VkMeshReadback::create(vk->device());
    REQUIRE(made.ok());
    VkMeshReadback& r = **made;
    auto gather = [&](bool withIndices) {
      REQUIRE(r.submit(7, 11, m, withIndices) == Status::ok);
      CHECK(r.submit(7, 12, m, withIndices) == Status::unsupported);  // one at a time
      CHECK(r.busyWith() == 7);
      std::optional<MeshReadback> got = r.wait(10'000'000'000ull);
      REQUIRE(got.has_value());
      CHECK_FALSE(r.busy());
      CHECK(got->id == 7);
      CHECK(got->generation == 11);
      return *got;
    };
    const MeshReadback full = gather(true);
    CHECK(full.positions == torus.positions);
    CHECK(full.indices == torus.indices);
    const MeshReadback positions = gather(false);
    CHECK(positions.positions == torus.positions);
    CHECK(positions.indices.empty());
    // A last 16-bit index in the two bytes past the buffer's last whole word cannot be read by
    // a shader: it reads as UINT32_MAX, which the CPU's checks refuse (never a read out of range).
    AppBuffer odd(vk->device(), indices.data(), (3 + torus.indices.size()) * 2);
    VkMeshBuffers cut = m;
    cut.indices = odd.buffer;
    if ((3 + torus.indices.size()) % 2 == 1) {
      REQUIRE(r.submit(8, 1, cut, true) == Status::ok);
      std::optional<MeshReadback> got = r.wait(10'000'000'000ull);
      REQUIRE(got.has_value());
      CHECK(got->indices.back() == UINT32_MAX);
      CHECK(std::equal(got->indices.begin(), got->indices.end() - 1, torus.indices.begin()));
    }
    VkMeshBuffers bad = m;
    bad.positionStride = 14;
    CHECK(r.submit(9, 1, bad, true) == Status::invalid_argument);
  }
  SECTION("an index out of range drops its triangle instead of reading past the buffer") {
    std::vector<uint16_t> broken = indices;
    broken[3 + 5] = 60000;  // triangle 1 now points far past the last vertex
    AppBuffer ib2(vk->device(), broken.data(), broken.size() * 2);
    VkMeshBuffers m2 = m;
    m2.indices = ib2.buffer;
    REQUIRE(b.setMesh(m2) == Status::ok);
    const SdfGrid g = buildOnGpu(b, testBox(16), testObjectFromHand());
    for (float value : g.values()) REQUIRE(std::isfinite(value));
  }
  CHECK(vk->messageCount() == 0);
}

namespace {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
// Under a sanitizer the resident size measures the sanitizer, not us: AddressSanitizer keeps
// freed blocks in quarantine (10.6 GB resident after this test's builds, against a flat line
// without it). Its allocator counts the bytes the process holds allocated now, freed ones not
// included, which is the quantity a leak makes grow.
size_t liveBytes() {
  return __sanitizer_get_current_allocated_bytes();
}
#else
size_t liveBytes() {
  std::ifstream statm("/proc/self/statm");
  size_t pages = 0, resident = 0;
  statm >> pages >> resident;
  return resident * size_t(sysconf(_SC_PAGESIZE));
}
#endif
}  // namespace

TEST_CASE("Thousands of Vulkan builds leak neither memory nor Vulkan objects", "[gpu][vk_sdf]") {
  REQUIRE_DEVICE(vk);
  auto builder = VkSdfBuilder::create(vk->device());
  REQUIRE(builder.ok());
  VkSdfBuilder& b = **builder;
  const TriangleMesh torus = localTorus(0.05f, 0.018f, 24, 12);
  REQUIRE(b.setMesh(torus) == Status::ok);
  const std::vector<glm::vec3> points(50, glm::vec3(0.4f, 0.5f, 0.6f));
  // Plain counting in the loop: thousands of Catch2 assertions would themselves cost memory.
  size_t failures = 0;
  auto cycle = [&](int i) {
    if (i % 500 == 0 && b.setMesh(torus) != Status::ok) ++failures;
    if (b.submitBuild(testBox(16), testObjectFromHand(), points, i % 10 == 0) != Status::ok ||
        b.wait(10'000'000'000ull) != SdfPoll::ready || b.samples().size() != points.size()) {
      ++failures;
    }
  };
  for (int i = 0; i < 50; ++i) cycle(i);  // warm-up: buffers reach their size
  const int64_t objects = b.context().liveObjects();
  const size_t live = liveBytes();
  for (int i = 0; i < 2000; ++i) cycle(i);
  CHECK(failures == 0);
  CHECK(b.context().liveObjects() == objects);
  CHECK(liveBytes() <= live + 4 * 1024 * 1024);
  CHECK(vk->messageCount() == 0);
}

TEST_CASE("Vulkan SDF builder refuses bad input and survives a lost device", "[gpu][vk_sdf]") {
  REQUIRE_DEVICE(vk);
  std::vector<std::string> log;
  VkSdfOptions options;
  options.log = [&](const std::string& line) { log.push_back(line); };
  auto builder = VkSdfBuilder::create(vk->device(), options);
  REQUIRE(builder.ok());
  VkSdfBuilder& b = **builder;
  CHECK(b.poll() == SdfPoll::idle);

  SECTION("bad input changes nothing") {
    CHECK(b.submitBuild(testBox(16), Pose{}, {}) == Status::invalid_argument);  // no mesh yet
    TriangleMesh nan = localTorus(0.05f, 0.018f, 8, 6);
    nan.positions[3].y = NAN;
    CHECK(b.setMesh(nan) == Status::invalid_argument);
    REQUIRE(b.setMesh(localTorus(0.05f, 0.018f, 8, 6)) == Status::ok);
    GridBox bad = testBox(16);
    bad.resolution.x = 1;
    CHECK(b.submitBuild(bad, Pose{}, {}) == Status::invalid_argument);
    Pose nanPose;
    nanPose.position.x = NAN;
    CHECK(b.submitBuild(testBox(16), nanPose, {}) == Status::invalid_argument);
    CHECK(b.submitSample(std::vector<glm::vec3>(3)) == Status::invalid_argument);  // not built
    REQUIRE(b.submitBuild(testBox(16), Pose{}, {}) == Status::ok);
    CHECK(b.submitBuild(testBox(16), Pose{}, {}) == Status::unsupported);  // busy
    CHECK(b.wait(10'000'000'000ull) == SdfPoll::ready);
    CHECK(log.empty());
    CHECK_FALSE(b.failed());
  }
  SECTION("a lost device disables the builder with one log line") {
    REQUIRE(b.setMesh(localTorus(0.05f, 0.018f, 8, 6)) == Status::ok);
    b.simulateDeviceLostForTesting();
    CHECK(b.submitBuild(testBox(16), Pose{}, {}) == Status::device_lost);
    CHECK(b.poll() == SdfPoll::failed);
    CHECK(b.submitBuild(testBox(16), Pose{}, {}) == Status::device_lost);
    CHECK(b.setMesh(localTorus(0.05f, 0.018f, 8, 6)) == Status::device_lost);
    CHECK(b.failed());
    CHECK(log.size() == 1);
  }
  CHECK(vk->messageCount() == 0);
}

TEST_CASE("GrabBoxSdf redoes a request on the CPU when the device is lost", "[gpu][vk_sdf]") {
  REQUIRE_DEVICE(vk);
  std::vector<std::string> log;
  VkSdfOptions options;
  options.log = [&](const std::string& line) { log.push_back(line); };
  const VulkanDevice device = vk->device();
  auto sdf = GrabBoxSdf::create(&device, options);
  REQUIRE(sdf->backend() == SdfBackendKind::vulkan);
  const TriangleMesh torus = localTorus(0.05f, 0.018f, 24, 12);
  REQUIRE(sdf->setMesh(torus) == Status::ok);
  const std::vector<glm::vec3> points = {{0.5f, 0.5f, 0.5f}, {0.1f, 0.9f, 0.3f}};

  auto cpuOnly = GrabBoxSdf::create(nullptr);
  REQUIRE(cpuOnly->backend() == SdfBackendKind::cpu);
  REQUIRE(cpuOnly->setMesh(torus) == Status::ok);
  REQUIRE(cpuOnly->submit(testBox(16), testObjectFromHand(), points) == Status::ok);
  REQUIRE(cpuOnly->poll() == SdfPoll::ready);
  const std::vector<float> expected(cpuOnly->samples().begin(), cpuOnly->samples().end());

  SECTION("a working device gives the CPU path's values") {
    REQUIRE(sdf->submit(testBox(16), testObjectFromHand(), points) == Status::ok);
    REQUIRE(sdf->wait(10'000'000'000ull) == SdfPoll::ready);
    for (size_t i = 0; i < points.size(); ++i) {
      CHECK(sdf->samples()[i] == Approx(expected[i]).margin(0.05f * testBox(16).maxSpacing()));
    }
  }
  SECTION("results equal the CPU path after a loss") {
    auto lost = GrabBoxSdf::create(&device, options);
    REQUIRE(lost->setMesh(torus) == Status::ok);
    lost->simulateDeviceLostForTesting();
    CHECK(lost->submit(testBox(16), testObjectFromHand(), points) == Status::ok);
    CHECK(lost->poll() == SdfPoll::ready);
    CHECK(lost->backend() == SdfBackendKind::cpu);
    REQUIRE(lost->samples().size() == points.size());
    for (size_t i = 0; i < points.size(); ++i) CHECK(lost->samples()[i] == expected[i]);
    CHECK(log.size() == 1);
  }
  CHECK(vk->messageCount() == 0);
}
