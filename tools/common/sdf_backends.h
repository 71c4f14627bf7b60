// The grab-box SDF builders the tools time side by side, and the objects they time them on:
// autograsp-bench (its --sdf-backend rows and its --scaling sweep) and autograsp-sdf-scaling use
// this one place, so both measure the same thing the same way.
//
// A TimedSdfBuilder is the CPU builder (CpuSdfBuilder) or the Vulkan builder (VkSdfBuilder) on a
// standalone device of its own (vk_standalone.h: the first Vulkan 1.1 device with a compute
// queue; VK_ICD_FILENAMES picks the driver, e.g. Mesa's lavapipe). Every call returns when its
// results are in CPU memory, so the wall time around a call is what the caller times: for Vulkan
// that is from the submission until the fence signals and the readback is in hand.
//
// Tools built without Vulkan (no headers or glslang) still link this: makeTimedBuilder() then
// answers "vulkan" with an unsupported error saying so.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "base/pose.h"
#include "base/status.h"
#include "mesh/mesh.h"
#include "mesh/mesh_distance.h"
#include "sdf/sdf_grid.h"

namespace sdfg::tools {

// Backend names as the tools spell them on the command line and in JSON.
inline constexpr const char* kCpuBackend = "cpu";
inline constexpr const char* kVulkanBackend = "vulkan";
// "CPU" / "Vulkan" for table titles; other names unchanged.
std::string backendTitle(const std::string& backend);

class TimedSdfBuilder {
 public:
  virtual ~TimedSdfBuilder() = default;
  virtual std::string name() const = 0;    // kCpuBackend or kVulkanBackend
  virtual std::string device() const = 0;  // "2 threads", "llvmpipe (LLVM 15.0.6, 256 bits)"
  // Once per mesh. `mesh` is the mesh the boxes are placed against (already scaled); `distance`
  // was built from it and must outlive every later call until the next prepare(). The Vulkan
  // builder uploads the mesh at its next build.
  virtual Status prepare(const TriangleMesh& mesh, const MeshDistance& distance) = 0;
  // The whole grid in CPU memory (what a solver reads), resized to `box`.
  virtual Status build(const Pose& objectFromHand, const GridBox& box, SdfGrid& out) = 0;
  // The frame path: the grid is built and sampled at `points` (normalized box coordinates); only
  // the samples come back (`samples`, one per point). On the CPU a build plus trilinear samples.
  virtual Status buildAndSample(const Pose& objectFromHand, const GridBox& box,
                                std::span<const glm::vec3> points, std::vector<float>& samples) = 0;
  // Vulkan with profiling: milliseconds of the last build's passes (see
  // VkSdfBuilder::passTimesMs); empty otherwise.
  virtual std::vector<double> passTimesMs() const { return {}; }
};

struct TimedBuilderOptions {
  unsigned cpuThreads = 0;     // CpuSdfBuilder threads (0: one per hardware thread)
  float cpuExactBand = 0.0f;   // CpuSdfOptions::exactBand, metres (0: exact at every node)
  bool vulkanProfile = false;  // GPU timestamps per pass (VkSdfOptions::profile)
  uint32_t vulkanWorkGroupSize = 64;
};

// `backend` is kCpuBackend or kVulkanBackend. Errors: invalid_argument for another name;
// unsupported for "vulkan" when the tools were built without Vulkan, no Vulkan device could be
// created, or the builder could not be made on it (the message says which).
Result<std::unique_ptr<TimedSdfBuilder>> makeTimedBuilder(const std::string& backend,
                                                          const TimedBuilderOptions& options = {});

// An object of a scaling sweep: procedural (`mesh` set) or a file (`path` set, read by
// loadScalingObject).
struct ScalingObject {
  std::string name;
  std::optional<std::filesystem::path> path;
  TriangleMesh mesh;
};

// The same surface at rising triangle counts: the core's torus (ring 5 cm, tube 2 cm)
// tessellated to about 5k, 20k, 50k, 100k, 200k and 400k triangles (quick: 600, 2.3k, 5.2k),
// named "torus-<count>".
std::vector<ScalingObject> scalingTori(bool quick = false);
// The shared test meshes of the sweeps, smallest first, as file names in ../shared/meshes
// (4.6k .. 400k triangles, the 400k armadillo last).
const std::vector<std::string>& scalingMeshFiles();
// The files of scalingMeshFiles() present in `dir`, as objects named by their stem.
std::vector<ScalingObject> scalingMeshes(const std::filesystem::path& dir);
// The object's mesh (read when it is a file), validated and scaled uniformly to `diagonal`
// metres of bounding-box diagonal. Errors: the loader's, or validateMesh's, naming the object.
Result<TriangleMesh> loadScalingObject(const ScalingObject& object, float diagonal);

// The paper's sample count per frame: 5 fingers x 10 curl steps, along a diagonal of the box
// (where they lie does not change the cost).
std::vector<glm::vec3> frameSamplePoints();

// Median (mean of the middle two for an even count); NaN when empty.
double medianOf(std::vector<double> values);

}  // namespace sdfg::tools
