// Internal to VkSdfBuilder (vulkan/vk_sdf_builder*.cpp, vk_sdf_prepare.cpp), not part of the
// engine's interface: the passes and buffer slots the builder's files share, the Vulkan objects
// it owns, and the CPU-side preparation of a mesh and a build (pseudo-normals, the winding-number
// hierarchy's plan, the jump-flooding steps).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/mat4x4.hpp>

#include "vulkan/vk_sdf_builder.h"
#include "vulkan/vk_sdf_layout.h"

namespace sdfg {
namespace vk_sdf_detail {

namespace L = vk_layout;

enum Pass : uint32_t {
  kTransform,
  kCluster,
  kSplat,
  kJfa,         // one invocation per node and step: CPU devices' grids over L::kFloodGroupNodes
  kJfaWide,     // L::kWideFloodNodesPerGroup nodes per work group, a lane per neighbour: GPUs
  kFloodGroup,  // grids of up to L::kFloodGroupNodes nodes; none when the device is too small
  kFinalize,
  kRepair,
  kSample,
  kPassCount
};
// Timestamps: start, then after transform, hierarchy, splat, flood, finalize (+ repair), sample.
// On the one-group path with pseudo-normal signs the flood's dispatch also finalizes and samples:
// the last two stamps follow it at once.
constexpr uint32_t kTimestampCount = 7;

// Which flood a build takes (record() in vk_sdf_submit.cpp). All three give the same ids, bit for
// bit: the same steps, candidates, order and comparisons.
enum class FloodPath : uint32_t {
  automatic,  // the device's choice: see record()
  group,      // one work group in shared memory (sdf_flood_group.comp), grids up to 4096 nodes
  perNode,    // one dispatch per step, one invocation per node (sdf_jfa.comp)
  wide,       // one dispatch per step, one lane per neighbour (sdf_jfa_wide.comp)
};

// Tests and tools only: which flood the builds take.
struct FloodTestHooks {
  // When not automatic, every build floods this way where it can (the group flood only up to
  // L::kFloodGroupNodes nodes; larger grids then take the device's step-by-step flood), so the
  // paths can be compared on one device.
  std::atomic<FloodPath> force{FloodPath::automatic};
  // Builds recorded with the one-group flood (shaders/sdf_flood_group.comp).
  std::atomic<uint32_t> groupFloods{0};
  // Builds recorded with the wide step-by-step flood (shaders/sdf_jfa_wide.comp).
  std::atomic<uint32_t> wideFloods{0};
};
extern FloodTestHooks floodTestHooks;

// Buffers the builder owns, by role.
enum Slot : uint32_t {
  kParamsBuf,   // BuildParams, written by the host before each submission
  kMeshPos,     // uploaded positions (CPU-array meshes)
  kMeshIdx,     // uploaded 32-bit indices (CPU-array meshes)
  kStaging,     // host copy of positions, indices, pseudo-normals; copied by the next build
  kTris,        // triangles in box space
  kNodes,       // winding-number hierarchy
  kDistBits,    // splat minimum per node; then unrepaired values (pseudo-normals, stepwise flood)
  kIdsA,        // closest-triangle ids, ping
  kIdsB,        // closest-triangle ids, pong
  kValues,      // the SDF (device side)
  kPoints,      // points to sample, written by the host
  kSamples,     // sampled values, read by the host
  kValuesHost,  // copy of the SDF for the host (readBackGrid)
  kNormals,     // per-triangle pseudo-normals (closed CPU-array meshes)
  kSlotCount,
};

constexpr uint32_t kDevice = 0, kUpload = 1, kReadback = 2;

inline VkMemoryKind memoryKind(uint32_t kind) {
  return kind == kUpload     ? VkMemoryKind::upload
         : kind == kReadback ? VkMemoryKind::readback
                             : VkMemoryKind::device;
}

inline uint32_t ceilDiv(size_t n, uint32_t d) {
  return uint32_t((n + d - 1) / d);
}

// Spreads the low 10 bits of v to every third bit (Morton order of triangle centroids, so that
// consecutive triangles, the hierarchy's clusters, are close in space).
uint32_t spreadBits(uint32_t v);

// Pseudo-normals of every triangle's edges and corners when the mesh is closed (every edge has
// two triangles) and consistently oriented (they traverse it in opposite directions), in the
// mesh's triangle order; nothing otherwise (those meshes are signed by the winding number).
std::optional<std::vector<L::TrianglePseudoNormals>> pseudoNormals(const TriangleMesh& mesh);

glm::mat4 poseMatrix(const Pose& pose);
bool finitePose(const Pose& p);

// Levels of the winding-number hierarchy for `triangles`, each level kFanOut times smaller,
// up to a top level of at most kFanOut nodes.
struct Hierarchy {
  uint32_t levels = 0;
  uint32_t offset[L::kMaxLevels] = {};
  uint32_t count[L::kMaxLevels] = {};
  uint32_t total = 0;
};
Hierarchy planHierarchy(uint32_t triangles);

// The jump steps for a grid whose longest axis has `n` nodes: the largest power of two below n,
// halving to 1, then 2 and 1 again (JFA+2: cleans up most of the flood's misses).
std::vector<uint32_t> jumpSteps(uint32_t n);

}  // namespace vk_sdf_detail

struct VkSdfBuilder::Objects {
  // Declaration order is destruction order reversed: buffers go before the pool and layouts.
  VkOwned<VkDescriptorSetLayout> setLayout;  // the one layout every pass shares
  VkOwned<VkPipelineLayout> pipelineLayout;  // set 0 + 8 bytes of push constants
  std::array<VkOwned<VkPipeline>, vk_sdf_detail::kPassCount> pipelines;
  VkSubmitObjects submit;           // the descriptor set, command buffer and fence
  VkOwned<VkQueryPool> timestamps;  // pass boundaries, only with options.profile
  std::array<VkBufferAlloc, vk_sdf_detail::kSlotCount> buffers;
  std::array<uint32_t, vk_sdf_detail::kSlotCount> kinds{};
  bool descriptorsDirty = true;
};

}  // namespace sdfg
