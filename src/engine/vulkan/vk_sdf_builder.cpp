#define VK_NO_PROTOTYPES  // every call goes through the borrowed device's function table
#include "vulkan/vk_sdf_builder.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <iostream>
#include <optional>

#include <glm/gtc/quaternion.hpp>

#include "sdfg_spirv.h"
#include "vulkan/vk_sdf_layout.h"

namespace sdfg {

namespace L = vk_layout;

namespace {

enum Pass : uint32_t {
  kTransform,
  kCluster,
  kSplat,
  kJfa,
  kFinalize,
  kRepair,
  kSample,
  kPassCount
};
// Timestamps: start, then after transform, hierarchy, splat, flood, finalize (+ repair), sample.
constexpr uint32_t kTimestampCount = 7;

// Buffers the builder owns, by role.
enum Slot : uint32_t {
  kParamsBuf,   // BuildParams, written by the host before each submission
  kMeshPos,     // uploaded positions (CPU-array meshes)
  kMeshIdx,     // uploaded 32-bit indices (CPU-array meshes)
  kStaging,     // host copy of positions, indices, pseudo-normals; copied by the next build
  kTris,        // triangles in box space
  kNodes,       // winding-number hierarchy
  kDistBits,    // splat minimum per node
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

VkMemoryKind memoryKind(uint32_t kind) {
  return kind == kUpload     ? VkMemoryKind::upload
         : kind == kReadback ? VkMemoryKind::readback
                             : VkMemoryKind::device;
}

uint32_t ceilDiv(size_t n, uint32_t d) {
  return uint32_t((n + d - 1) / d);
}

// Spreads the low 10 bits of v to every third bit (Morton order of triangle centroids, so that
// consecutive triangles, the hierarchy's clusters, are close in space).
uint32_t spreadBits(uint32_t v) {
  v &= 0x3ffu;
  v = (v | (v << 16)) & 0x030000ffu;
  v = (v | (v << 8)) & 0x0300f00fu;
  v = (v | (v << 4)) & 0x030c30c3u;
  v = (v | (v << 2)) & 0x09249249u;
  return v;
}

// Pseudo-normals of every triangle's edges and corners when the mesh is closed (every edge has
// two triangles) and consistently oriented (they traverse it in opposite directions), in the
// mesh's triangle order; nothing otherwise (those meshes are signed by the winding number).
std::optional<std::vector<L::TrianglePseudoNormals>> pseudoNormals(const TriangleMesh& mesh) {
  const size_t triangles = mesh.triangleCount();
  struct HalfEdge {
    uint64_t key;
    uint32_t slot;  // 3 * triangle + edge
  };
  std::vector<HalfEdge> half(3 * triangles);
  for (size_t t = 0; t < triangles; ++t) {
    for (uint32_t e = 0; e < 3; ++e) {
      const uint32_t u = mesh.indices[3 * t + e], v = mesh.indices[3 * t + (e + 1) % 3];
      half[3 * t + e] = {(uint64_t(std::min(u, v)) << 32) | std::max(u, v), uint32_t(3 * t + e)};
    }
  }
  std::sort(half.begin(), half.end(),
            [](const HalfEdge& x, const HalfEdge& y) { return x.key < y.key; });
  std::vector<glm::dvec3> face(triangles), vertex(mesh.vertexCount(), glm::dvec3(0.0));
  for (size_t t = 0; t < triangles; ++t) {
    const glm::dvec3 p[3] = {glm::dvec3(mesh.positions[mesh.indices[3 * t]]),
                             glm::dvec3(mesh.positions[mesh.indices[3 * t + 1]]),
                             glm::dvec3(mesh.positions[mesh.indices[3 * t + 2]])};
    face[t] = glm::normalize(glm::cross(p[1] - p[0], p[2] - p[0]));
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3 e1 = glm::normalize(p[(k + 1) % 3] - p[k]);
      const glm::dvec3 e2 = glm::normalize(p[(k + 2) % 3] - p[k]);
      vertex[mesh.indices[3 * t + k]] +=
          std::acos(std::clamp(glm::dot(e1, e2), -1.0, 1.0)) * face[t];
    }
  }
  std::vector<L::TrianglePseudoNormals> out(triangles);
  for (size_t i = 0; i < half.size(); i += 2) {
    if (i + 1 >= half.size() || half[i].key != half[i + 1].key ||
        (i + 2 < half.size() && half[i + 2].key == half[i].key)) {
      return std::nullopt;  // a boundary or non-manifold edge
    }
    const uint32_t s0 = half[i].slot, s1 = half[i + 1].slot;
    if (mesh.indices[s0] == mesh.indices[s1]) return std::nullopt;  // neighbours disagree
    const glm::vec4 n(glm::vec3(face[s0 / 3] + face[s1 / 3]), 0.0f);
    out[s0 / 3].edge[s0 % 3] = n;
    out[s1 / 3].edge[s1 % 3] = n;
  }
  for (size_t t = 0; t < triangles; ++t) {
    for (int k = 0; k < 3; ++k) {
      out[t].corner[k] = glm::vec4(glm::vec3(vertex[mesh.indices[3 * t + k]]), 0.0f);
    }
  }
  return out;
}

glm::mat4 poseMatrix(const Pose& pose) {
  glm::mat4 m = glm::mat4_cast(pose.orientation);
  m[3] = glm::vec4(pose.position, 1.0f);
  return m;
}

bool finitePose(const Pose& p) {
  const glm::quat& q = p.orientation;
  return std::isfinite(q.w) && std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) &&
         std::isfinite(p.position.x) && std::isfinite(p.position.y) &&
         std::isfinite(p.position.z) && std::abs(glm::length(q) - 1.0f) < 1e-3f;
}

// Levels of the winding-number hierarchy for `triangles`, each level kFanOut times smaller,
// up to a top level of at most kFanOut nodes.
struct Hierarchy {
  uint32_t levels = 0;
  uint32_t offset[L::kMaxLevels] = {};
  uint32_t count[L::kMaxLevels] = {};
  uint32_t total = 0;
};
Hierarchy planHierarchy(uint32_t triangles) {
  Hierarchy h;
  uint32_t n = ceilDiv(triangles, L::kFanOut);
  while (true) {
    h.offset[h.levels] = h.total;
    h.count[h.levels] = n;
    h.total += n;
    ++h.levels;
    if (n <= L::kFanOut || h.levels == L::kMaxLevels) break;
    n = ceilDiv(n, L::kFanOut);
  }
  return h;
}

// The jump steps for a grid whose longest axis has `n` nodes: the largest power of two below n,
// halving to 1, then 2 and 1 again (JFA+2: cleans up most of the flood's misses).
std::vector<uint32_t> jumpSteps(uint32_t n) {
  std::vector<uint32_t> steps;
  uint32_t s = 1;
  while (s * 2 < n) s *= 2;
  for (; s >= 1; s /= 2) steps.push_back(s);
  if (n > 2) {
    steps.push_back(2);
    steps.push_back(1);
  }
  return steps;
}

}  // namespace

struct VkSdfBuilder::Objects {
  // Declaration order is destruction order reversed: buffers go before the pool and layouts.
  VkOwned<VkDescriptorSetLayout> setLayout;  // the one layout every pass shares
  VkOwned<VkPipelineLayout> pipelineLayout;  // set 0 + 8 bytes of push constants
  std::array<VkOwned<VkPipeline>, kPassCount> pipelines;
  VkOwned<VkDescriptorPool> descriptorPool;  // owns `set`
  VkDescriptorSet set = VK_NULL_HANDLE;
  VkOwned<VkCommandPool> commandPool;    // owns `cmd`; family = the borrowed queue's
  VkCommandBuffer cmd = VK_NULL_HANDLE;  // re-recorded for every submission
  VkOwned<VkFence> fence;                // signalled when a submission completes (polled)
  VkOwned<VkQueryPool> timestamps;       // pass boundaries, only with options.profile
  std::array<VkBufferAlloc, kSlotCount> buffers;
  std::array<uint32_t, kSlotCount> kinds{};
  bool descriptorsDirty = true;
};

Result<std::unique_ptr<VkSdfBuilder>> VkSdfBuilder::create(const VulkanDevice& device,
                                                           const VkSdfOptions& options) {
  auto ctx = VkContext::create(device);
  if (!ctx) return ctx.error();
  std::unique_ptr<VkSdfBuilder> b(new VkSdfBuilder());
  b->ctx_ = std::move(ctx.value());
  b->options_ = options;
  b->objects_ = std::make_unique<Objects>();
  const VkContext& c = *b->ctx_;
  const VkFunctions& fn = c.fn();
  Objects& o = *b->objects_;
  const VkDevice dev = c.handle();
  auto error = [](VkResult r, const char* what) {
    return makeError(r == VK_ERROR_OUT_OF_HOST_MEMORY || r == VK_ERROR_OUT_OF_DEVICE_MEMORY
                         ? Status::out_of_memory
                     : r == VK_ERROR_DEVICE_LOST ? Status::device_lost
                                                 : Status::internal,
                     std::string("vulkan: ") + what + " failed: " + vkResultName(r));
  };

  const VkPhysicalDeviceLimits& limits = c.properties().limits;
  b->workGroupSize_ = std::clamp<uint32_t>(
      options.workGroupSize, 1u,
      std::min(limits.maxComputeWorkGroupSize[0], limits.maxComputeWorkGroupInvocations));

  std::array<VkDescriptorSetLayoutBinding, L::kBindingCount> bindings{};
  for (uint32_t i = 0; i < L::kBindingCount; ++i) {
    bindings[i].binding = i;
    bindings[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    bindings[i].descriptorCount = 1;
    bindings[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
  }
  auto setInfo = vkStruct<VkDescriptorSetLayoutCreateInfo>(
      VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO);
  setInfo.bindingCount = L::kBindingCount;
  setInfo.pBindings = bindings.data();
  VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
  if (VkResult r = fn.vkCreateDescriptorSetLayout(dev, &setInfo, nullptr, &setLayout)) {
    return error(r, "vkCreateDescriptorSetLayout");
  }
  o.setLayout = VkOwned<VkDescriptorSetLayout>(c, setLayout);

  VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(L::PushConstants)};
  auto layoutInfo =
      vkStruct<VkPipelineLayoutCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO);
  layoutInfo.setLayoutCount = 1;
  layoutInfo.pSetLayouts = &setLayout;
  layoutInfo.pushConstantRangeCount = 1;
  layoutInfo.pPushConstantRanges = &push;
  VkPipelineLayout pipelineLayout = VK_NULL_HANDLE;
  if (VkResult r = fn.vkCreatePipelineLayout(dev, &layoutInfo, nullptr, &pipelineLayout)) {
    return error(r, "vkCreatePipelineLayout");
  }
  o.pipelineLayout = VkOwned<VkPipelineLayout>(c, pipelineLayout);

  const std::array<std::span<const uint32_t>, kPassCount> code = {
      spirv::k_sdf_transform, spirv::k_sdf_cluster, spirv::k_sdf_splat, spirv::k_sdf_jfa,
      spirv::k_sdf_finalize,  spirv::k_sdf_repair,  spirv::k_sdf_sample};
  const VkSpecializationMapEntry entry{0, 0, sizeof(uint32_t)};  // constant_id 0: local_size_x
  const uint32_t groupSize = b->workGroupSize_;
  const VkSpecializationInfo spec{1, &entry, sizeof(uint32_t), &groupSize};
  for (uint32_t p = 0; p < kPassCount; ++p) {
    auto moduleInfo =
        vkStruct<VkShaderModuleCreateInfo>(VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO);
    moduleInfo.codeSize = code[p].size_bytes();
    moduleInfo.pCode = code[p].data();
    VkShaderModule module = VK_NULL_HANDLE;
    if (VkResult r = fn.vkCreateShaderModule(dev, &moduleInfo, nullptr, &module)) {
      return error(r, "vkCreateShaderModule");
    }
    VkOwned<VkShaderModule> ownedModule(c, module);  // only needed until the pipeline exists
    auto pipeInfo =
        vkStruct<VkComputePipelineCreateInfo>(VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO);
    pipeInfo.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    pipeInfo.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    pipeInfo.stage.module = module;
    pipeInfo.stage.pName = "main";
    pipeInfo.stage.pSpecializationInfo = &spec;
    pipeInfo.layout = pipelineLayout;
    VkPipeline pipeline = VK_NULL_HANDLE;
    if (VkResult r =
            fn.vkCreateComputePipelines(dev, VK_NULL_HANDLE, 1, &pipeInfo, nullptr, &pipeline)) {
      return error(r, "vkCreateComputePipelines");
    }
    o.pipelines[p] = VkOwned<VkPipeline>(c, pipeline);
  }

  const std::array<VkDescriptorPoolSize, 1> poolSizes = {
      VkDescriptorPoolSize{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, L::kBindingCount}};
  auto poolInfo =
      vkStruct<VkDescriptorPoolCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO);
  poolInfo.maxSets = 1;
  poolInfo.poolSizeCount = uint32_t(poolSizes.size());
  poolInfo.pPoolSizes = poolSizes.data();
  VkDescriptorPool pool = VK_NULL_HANDLE;
  if (VkResult r = fn.vkCreateDescriptorPool(dev, &poolInfo, nullptr, &pool)) {
    return error(r, "vkCreateDescriptorPool");
  }
  o.descriptorPool = VkOwned<VkDescriptorPool>(c, pool);
  auto setAlloc =
      vkStruct<VkDescriptorSetAllocateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO);
  setAlloc.descriptorPool = pool;
  setAlloc.descriptorSetCount = 1;
  setAlloc.pSetLayouts = &setLayout;
  if (VkResult r = fn.vkAllocateDescriptorSets(dev, &setAlloc, &o.set)) {
    return error(r, "vkAllocateDescriptorSets");
  }

  auto cmdPoolInfo = vkStruct<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
  cmdPoolInfo.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  cmdPoolInfo.queueFamilyIndex = device.queueFamilyIndex;
  VkCommandPool cmdPool = VK_NULL_HANDLE;
  if (VkResult r = fn.vkCreateCommandPool(dev, &cmdPoolInfo, nullptr, &cmdPool)) {
    return error(r, "vkCreateCommandPool");
  }
  o.commandPool = VkOwned<VkCommandPool>(c, cmdPool);
  auto cmdAlloc =
      vkStruct<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
  cmdAlloc.commandPool = cmdPool;
  cmdAlloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cmdAlloc.commandBufferCount = 1;
  if (VkResult r = fn.vkAllocateCommandBuffers(dev, &cmdAlloc, &o.cmd)) {
    return error(r, "vkAllocateCommandBuffers");
  }

  auto fenceInfo = vkStruct<VkFenceCreateInfo>(VK_STRUCTURE_TYPE_FENCE_CREATE_INFO);
  VkFence fence = VK_NULL_HANDLE;
  if (VkResult r = fn.vkCreateFence(dev, &fenceInfo, nullptr, &fence)) {
    return error(r, "vkCreateFence");
  }
  o.fence = VkOwned<VkFence>(c, fence);

  uint32_t familyCount = 0;
  fn.vkGetPhysicalDeviceQueueFamilyProperties(device.physicalDevice, &familyCount, nullptr);
  std::vector<VkQueueFamilyProperties> families(familyCount);
  fn.vkGetPhysicalDeviceQueueFamilyProperties(device.physicalDevice, &familyCount, families.data());
  if (options.profile && families[device.queueFamilyIndex].timestampValidBits > 0) {
    auto queryInfo = vkStruct<VkQueryPoolCreateInfo>(VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO);
    queryInfo.queryType = VK_QUERY_TYPE_TIMESTAMP;
    queryInfo.queryCount = kTimestampCount;
    VkQueryPool queries = VK_NULL_HANDLE;
    if (VkResult r = fn.vkCreateQueryPool(dev, &queryInfo, nullptr, &queries)) {
      return error(r, "vkCreateQueryPool");
    }
    o.timestamps = VkOwned<VkQueryPool>(c, queries);
  }

  o.kinds = {kUpload, kDevice, kDevice, kUpload, kDevice,   kDevice,   kDevice,
             kDevice, kDevice, kDevice, kUpload, kReadback, kReadback, kDevice};
  // Every binding gets a buffer now, so the descriptor set is complete before the first build.
  if (Status s = b->ensureBuffer(kParamsBuf, L::kBuildParamsBytes, kUpload); s != Status::ok) {
    return makeError(s, b->failure_);
  }
  if (Status s = b->ensureBuffers(8, 1, false); s != Status::ok) return makeError(s, b->failure_);
  for (Slot slot : {kMeshPos, kMeshIdx, kNormals}) {
    if (Status s = b->ensureBuffer(slot, 16, kDevice); s != Status::ok) {
      return makeError(s, b->failure_);
    }
  }
  return b;
}

VkSdfBuilder::~VkSdfBuilder() {
  if (!ctx_ || !objects_) return;
  if (pending_) {
    // The GPU may still read our buffers; destroying them first would be undefined behaviour.
    // Also after a failure: a simulated loss (or one reported by a poll while the submission
    // still runs) leaves real work in flight; on a lost device the wait returns at once.
    const VkFence fence = objects_->fence.get();
    const VkResult r =
        ctx_->fn().vkWaitForFences(ctx_->handle(), 1, &fence, VK_TRUE, 2'000'000'000ull);
    if (r == VK_TIMEOUT) {
      // A hung device: leaking is the only safe choice.
      for (VkBufferAlloc& b : objects_->buffers) {
        b.buffer.release();
        b.memory.release();
      }
      objects_->commandPool.release();
      objects_->descriptorPool.release();
      for (auto& p : objects_->pipelines) p.release();
      objects_->fence.release();
      objects_->pipelineLayout.release();
      objects_->setLayout.release();
    }
  }
  objects_.reset();
}

Status VkSdfBuilder::fail(const Error& error) {
  if (!failed_) {
    failed_ = true;
    failure_ = error.message;
    const std::string line =
        "sdfg: Vulkan SDF backend disabled, falling back to the CPU: " + error.message;
    if (options_.log) {
      options_.log(line);
    } else {
      std::cerr << line << std::endl;
    }
  }
  return error.code;
}

Status VkSdfBuilder::fail(VkResult result, const char* what) {
  const Status code =
      result == VK_ERROR_DEVICE_LOST ? Status::device_lost
      : (result == VK_ERROR_OUT_OF_HOST_MEMORY || result == VK_ERROR_OUT_OF_DEVICE_MEMORY)
          ? Status::out_of_memory
          : Status::internal;
  return fail(makeError(code, std::string(what) + " returned " + vkResultName(result)));
}

Status VkSdfBuilder::checkUsable() const {
  if (failed_) return Status::device_lost;
  if (pending_) return Status::unsupported;
  return Status::ok;
}

Status VkSdfBuilder::ensureBuffer(uint32_t slot, size_t bytes, uint32_t kind) {
  VkBufferAlloc& b = objects_->buffers[slot];
  bytes = std::max<size_t>(bytes, 16);
  if (b.buffer && b.size >= bytes) return Status::ok;
  // Grow by half again so a slowly growing mesh or point count does not reallocate each time.
  const size_t size = b.buffer ? std::max(bytes, size_t(b.size) + size_t(b.size) / 2) : bytes;
  const VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                   VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                   VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  b = VkBufferAlloc{};  // frees the old one first (nothing is in flight: checked by callers)
  auto created = createBuffer(*ctx_, size, usage, memoryKind(kind));
  if (!created) return fail(created.error());
  b = std::move(created.value());
  objects_->descriptorsDirty = true;
  return Status::ok;
}

Status VkSdfBuilder::ensureBuffers(size_t nodeCount, size_t pointCount, bool readBack) {
  const Hierarchy h = planHierarchy(std::max<uint32_t>(triangleCount_, 1));
  const std::array<std::pair<Slot, size_t>, 9> sizes = {{
      {kTris, size_t(std::max<uint32_t>(triangleCount_, 1)) * sizeof(L::BoxTriangle)},
      {kNodes, size_t(h.total) * sizeof(L::HierarchyNode)},
      {kDistBits, nodeCount * 4},
      {kIdsA, nodeCount * 4},
      {kIdsB, nodeCount * 4},
      {kValues, nodeCount * 4},
      {kPoints, pointCount * sizeof(L::SamplePoint)},
      {kSamples, pointCount * 4},
      {kValuesHost, readBack ? nodeCount * 4 : 16},
  }};
  for (const auto& [slot, bytes] : sizes) {
    if (Status s = ensureBuffer(slot, bytes, objects_->kinds[slot]); s != Status::ok) return s;
  }
  return Status::ok;
}

void VkSdfBuilder::updateDescriptors() {
  if (!objects_->descriptorsDirty) return;
  std::array<VkDescriptorBufferInfo, L::kBindingCount> infos{};
  const std::array<Slot, L::kBindingCount> slots = {kParamsBuf, kMeshPos,  kMeshIdx, kTris,
                                                    kNodes,     kDistBits, kIdsA,    kIdsB,
                                                    kValues,    kPoints,   kSamples, kNormals};
  std::array<VkWriteDescriptorSet, L::kBindingCount> writes{};
  for (uint32_t i = 0; i < L::kBindingCount; ++i) {
    infos[i].buffer = objects_->buffers[slots[i]].buffer.get();
    infos[i].offset = 0;
    infos[i].range = i == L::kParams ? L::kBuildParamsBytes : VK_WHOLE_SIZE;
    if (meshSource_ == MeshSource::app && i == L::kPositions) infos[i].buffer = appMesh_.positions;
    if (meshSource_ == MeshSource::app && i == L::kIndices) infos[i].buffer = appMesh_.indices;
    writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    writes[i].dstSet = objects_->set;
    writes[i].dstBinding = i;
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[i].pBufferInfo = &infos[i];
  }
  ctx_->fn().vkUpdateDescriptorSets(ctx_->handle(), L::kBindingCount, writes.data(), 0, nullptr);
  objects_->descriptorsDirty = false;
}

Status VkSdfBuilder::setMesh(const TriangleMesh& mesh) {
  if (Status s = checkUsable(); s != Status::ok) return s;
  if (auto error = validateMesh(mesh.positions, mesh.indices)) return error->code;
  if (mesh.triangleCount() > (size_t(1) << 30)) return Status::invalid_argument;
  const uint32_t triangles = uint32_t(mesh.triangleCount());
  const uint32_t vertices = uint32_t(mesh.vertexCount());

  // Triangles in Morton order of their centroids: the hierarchy clusters consecutive triangles,
  // so spatially coherent clusters keep its far-field terms accurate and its walk short.
  const Aabb bounds = computeBounds(mesh.positions);
  const glm::vec3 extent = glm::max(bounds.extent(), glm::vec3(1e-30f));
  std::vector<std::pair<uint32_t, uint32_t>> order(triangles);
  for (uint32_t t = 0; t < triangles; ++t) {
    const glm::vec3 c =
        (mesh.positions[mesh.indices[3 * t]] + mesh.positions[mesh.indices[3 * t + 1]] +
         mesh.positions[mesh.indices[3 * t + 2]]) /
        3.0f;
    const glm::uvec3 q = glm::uvec3(glm::clamp((c - bounds.min) / extent, 0.0f, 1.0f) * 1023.0f);
    order[t] = {spreadBits(q.x) | (spreadBits(q.y) << 1) | (spreadBits(q.z) << 2), t};
  }
  std::sort(order.begin(), order.end());

  const auto normals = pseudoNormals(mesh);
  const size_t posBytes = size_t(vertices) * 12, idxBytes = size_t(triangles) * 12;
  const size_t normalBytes = normals ? normals->size() * sizeof(L::TrianglePseudoNormals) : 0;
  if (Status s = ensureBuffer(kMeshPos, posBytes, kDevice); s != Status::ok) return s;
  if (Status s = ensureBuffer(kMeshIdx, idxBytes, kDevice); s != Status::ok) return s;
  if (Status s = ensureBuffer(kNormals, normalBytes, kDevice); s != Status::ok) return s;
  if (Status s = ensureBuffer(kStaging, posBytes + idxBytes + normalBytes, kUpload);
      s != Status::ok) {
    return s;
  }
  VkBufferAlloc& staging = objects_->buffers[kStaging];
  auto* bytes = static_cast<unsigned char*>(staging.mapped);
  std::memcpy(bytes, mesh.positions.data(), posBytes);
  auto* idx = reinterpret_cast<uint32_t*>(bytes + posBytes);
  for (uint32_t t = 0; t < triangles; ++t) {
    std::memcpy(idx + 3 * t, &mesh.indices[3 * size_t(order[t].second)], 12);
  }
  if (normals) {
    auto* n = reinterpret_cast<L::TrianglePseudoNormals*>(bytes + posBytes + idxBytes);
    for (uint32_t t = 0; t < triangles; ++t) n[t] = (*normals)[order[t].second];
  }
  if (VkResult r = flushBuffer(*ctx_, staging)) return fail(r, "vkFlushMappedMemoryRanges");

  if (meshSource_ == MeshSource::app) objects_->descriptorsDirty = true;
  meshSource_ = MeshSource::cpu;
  pseudoNormalSign_ = normals.has_value();
  triangleCount_ = triangles;
  vertexCount_ = vertices;
  uploadPending_ = true;
  built_ = false;
  return Status::ok;
}

Status VkSdfBuilder::setMesh(const VkMeshBuffers& m) {
  if (Status s = checkUsable(); s != Status::ok) return s;
  const VkDeviceSize indexSize = m.indexType == VK_INDEX_TYPE_UINT16 ? 2 : 4;
  if (m.positions == VK_NULL_HANDLE || m.indices == VK_NULL_HANDLE || m.vertexCount == 0 ||
      m.indexCount < 3 || m.indexCount % 3 != 0 || m.positionStride < 12 ||
      m.positionStride % 4 != 0 || m.positionOffset % 4 != 0 || m.indexOffset % indexSize != 0 ||
      (m.indexType != VK_INDEX_TYPE_UINT16 && m.indexType != VK_INDEX_TYPE_UINT32) ||
      m.indexCount / 3 > (1u << 30) || m.positionOffset / 4 > UINT32_MAX ||
      m.indexOffset / indexSize > UINT32_MAX) {
    return Status::invalid_argument;
  }
  appMesh_ = m;
  meshSource_ = MeshSource::app;
  pseudoNormalSign_ = false;
  triangleCount_ = m.indexCount / 3;
  vertexCount_ = m.vertexCount;
  uploadPending_ = false;
  built_ = false;
  objects_->descriptorsDirty = true;
  return Status::ok;
}

Status VkSdfBuilder::submitBuild(const GridBox& box, const Pose& objectFromHand,
                                 std::span<const glm::vec3> points, bool readBackGrid) {
  if (Status s = checkUsable(); s != Status::ok) return s;
  if (box.validate() || !finitePose(objectFromHand)) return Status::invalid_argument;
  if (meshSource_ == MeshSource::none) return Status::invalid_argument;
  const size_t nodeCount = box.nodeCount();
  const uint32_t maxGroups = ctx_->properties().limits.maxComputeWorkGroupCount[0];
  if (ceilDiv(std::max<size_t>({nodeCount, triangleCount_, points.size()}), workGroupSize_) >
      maxGroups) {
    return Status::unsupported;
  }
  if (Status s = ensureBuffers(nodeCount, points.size(), readBackGrid); s != Status::ok) return s;

  const Hierarchy h = planHierarchy(triangleCount_);
  L::BuildParams params{};
  const Pose objectFromBox = objectFromHand * box.handFromBox;
  params.boxFromObject = poseMatrix(objectFromBox.inverse());
  const float diagonal = glm::length(box.size);
  params.boxHalf = glm::vec4(box.size * 0.5f, diagonal);
  params.spacing = glm::vec4(box.spacing(), diagonal);
  params.res = glm::uvec4(box.resolution, uint32_t(nodeCount));
  params.triangleCount = triangleCount_;
  params.vertexCount = vertexCount_;
  if (meshSource_ == MeshSource::app) {
    params.positionOffset = uint32_t(appMesh_.positionOffset / 4);
    params.positionStride = appMesh_.positionStride / 4;
    params.index16 = appMesh_.indexType == VK_INDEX_TYPE_UINT16 ? 1 : 0;
    params.indexOffset = uint32_t(appMesh_.indexOffset / (params.index16 ? 2 : 4));
  } else {
    params.positionOffset = 0;
    params.positionStride = 3;
    params.index16 = 0;
    params.indexOffset = 0;
  }
  params.nodeLevels = h.levels;
  params.topNodeCount = h.count[h.levels - 1];
  params.pointCount = uint32_t(points.size());
  for (uint32_t l = 0; l < L::kMaxLevels; ++l) {
    params.levelOffset[l] = h.offset[l];
    params.levelCount[l] = h.count[l];
  }
  params.windingBeta = options_.windingBeta;
  params.signMode = pseudoNormalSign_ ? 1 : 0;
  VkBufferAlloc& pb = objects_->buffers[kParamsBuf];
  std::memcpy(pb.mapped, &params, sizeof(params));
  if (VkResult r = flushBuffer(*ctx_, pb)) return fail(r, "vkFlushMappedMemoryRanges");

  VkBufferAlloc& pts = objects_->buffers[kPoints];
  auto* dst = static_cast<L::SamplePoint*>(pts.mapped);
  for (size_t i = 0; i < points.size(); ++i) dst[i].uvw = glm::vec4(points[i], 0.0f);
  if (VkResult r = flushBuffer(*ctx_, pts)) return fail(r, "vkFlushMappedMemoryRanges");

  box_ = box;
  if (Status s = record(true, points.size(), readBackGrid); s != Status::ok) return s;
  if (Status s = submitRecorded(); s != Status::ok) return s;
  uploadPending_ = false;
  built_ = true;
  readBackPending_ = readBackGrid;
  pointCount_ = points.size();
  return Status::ok;
}

Status VkSdfBuilder::submitSample(std::span<const glm::vec3> points) {
  if (Status s = checkUsable(); s != Status::ok) return s;
  if (!built_) return Status::invalid_argument;
  if (ceilDiv(points.size(), workGroupSize_) >
      ctx_->properties().limits.maxComputeWorkGroupCount[0]) {
    return Status::unsupported;
  }
  if (Status s = ensureBuffers(box_.nodeCount(), points.size(), false); s != Status::ok) return s;
  // Only the point count changes; the rest of the parameters still describe the built grid.
  VkBufferAlloc& pb = objects_->buffers[kParamsBuf];
  const uint32_t count = uint32_t(points.size());
  std::memcpy(static_cast<unsigned char*>(pb.mapped) + offsetof(L::BuildParams, pointCount), &count,
              sizeof(count));
  if (VkResult r = flushBuffer(*ctx_, pb)) return fail(r, "vkFlushMappedMemoryRanges");
  VkBufferAlloc& pts = objects_->buffers[kPoints];
  auto* dst = static_cast<L::SamplePoint*>(pts.mapped);
  for (size_t i = 0; i < points.size(); ++i) dst[i].uvw = glm::vec4(points[i], 0.0f);
  if (VkResult r = flushBuffer(*ctx_, pts)) return fail(r, "vkFlushMappedMemoryRanges");
  if (Status s = record(false, points.size(), false); s != Status::ok) return s;
  if (Status s = submitRecorded(); s != Status::ok) return s;
  readBackPending_ = false;
  pointCount_ = points.size();
  return Status::ok;
}

Status VkSdfBuilder::record(bool build, size_t pointCount, bool readBack) {
  updateDescriptors();
  const VkFunctions& fn = ctx_->fn();
  Objects& o = *objects_;
  VkCommandBuffer cmd = o.cmd;
  if (VkResult r = fn.vkResetCommandBuffer(cmd, 0)) return fail(r, "vkResetCommandBuffer");
  auto begin = vkStruct<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  if (VkResult r = fn.vkBeginCommandBuffer(cmd, &begin)) return fail(r, "vkBeginCommandBuffer");

  auto barrier = [&](VkPipelineStageFlags srcStage, VkAccessFlags srcAccess,
                     VkPipelineStageFlags dstStage, VkAccessFlags dstAccess) {
    auto mb = vkStruct<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
    mb.srcAccessMask = srcAccess;
    mb.dstAccessMask = dstAccess;
    fn.vkCmdPipelineBarrier(cmd, srcStage, dstStage, 0, 1, &mb, 0, nullptr, 0, nullptr);
  };
  constexpr VkPipelineStageFlags kCompute = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
  constexpr VkPipelineStageFlags kTransfer = VK_PIPELINE_STAGE_TRANSFER_BIT;
  constexpr VkAccessFlags kRead = VK_ACCESS_SHADER_READ_BIT;
  constexpr VkAccessFlags kWrite = VK_ACCESS_SHADER_WRITE_BIT;
  // Between two compute passes: the earlier pass's writes must be visible to the later pass's
  // reads (RAW), and the later pass may overwrite what the earlier one read (WAR: covered by the
  // execution dependency itself).
  auto computeToCompute = [&] { barrier(kCompute, kWrite, kCompute, kRead | kWrite); };

  fn.vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, o.pipelineLayout.get(), 0, 1,
                             &o.set, 0, nullptr);
  auto dispatch = [&](Pass pass, size_t items, L::PushConstants pc) {
    fn.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, o.pipelines[pass].get());
    fn.vkCmdPushConstants(cmd, o.pipelineLayout.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(pc),
                          &pc);
    // Rounded up to whole groups; every shader returns early past its item count.
    fn.vkCmdDispatch(cmd, ceilDiv(std::max<size_t>(items, 1), workGroupSize_), 1, 1);
  };

  const VkQueryPool queries = o.timestamps.get();
  if (queries) fn.vkCmdResetQueryPool(cmd, queries, 0, kTimestampCount);
  // Timestamp `index` once every earlier command has finished (bottom of pipe).
  auto stamp = [&](uint32_t index) {
    if (queries) {
      fn.vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries, index);
    }
  };
  stamp(0);

  const size_t nodeCount = box_.nodeCount();
  if (build) {
    if (uploadPending_) {
      const VkDeviceSize posBytes = VkDeviceSize(vertexCount_) * 12;
      const VkDeviceSize idxBytes = VkDeviceSize(triangleCount_) * 12;
      VkBufferCopy pos{0, 0, posBytes}, idx{posBytes, 0, idxBytes};
      fn.vkCmdCopyBuffer(cmd, o.buffers[kStaging].buffer.get(), o.buffers[kMeshPos].buffer.get(), 1,
                         &pos);
      fn.vkCmdCopyBuffer(cmd, o.buffers[kStaging].buffer.get(), o.buffers[kMeshIdx].buffer.get(), 1,
                         &idx);
      if (pseudoNormalSign_) {
        VkBufferCopy normals{posBytes + idxBytes, 0,
                             VkDeviceSize(triangleCount_) * sizeof(L::TrianglePseudoNormals)};
        fn.vkCmdCopyBuffer(cmd, o.buffers[kStaging].buffer.get(), o.buffers[kNormals].buffer.get(),
                           1, &normals);
      }
      // The uploaded mesh must land before the transform pass reads it.
      barrier(kTransfer, VK_ACCESS_TRANSFER_WRITE_BIT, kCompute, kRead);
    }
    if (meshSource_ == MeshSource::app) {
      // The app's skinning (a shader or a copy earlier on this queue) must be visible to the
      // transform pass.
      barrier(VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
              VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT, kCompute, kRead);
    }
    fn.vkCmdFillBuffer(cmd, o.buffers[kDistBits].buffer.get(), 0, nodeCount * 4, 0x7f800000u);
    fn.vkCmdFillBuffer(cmd, o.buffers[kIdsA].buffer.get(), 0, nodeCount * 4, L::kNoTriangle);
    // The clears (+inf distances, no triangle) must land before the splat's atomics and writes.
    barrier(kTransfer, VK_ACCESS_TRANSFER_WRITE_BIT, kCompute, kRead | kWrite);

    dispatch(kTransform, triangleCount_, {});
    // Box-space triangles are written before the hierarchy and splat passes read them.
    computeToCompute();
    stamp(1);
    // The hierarchy serves only the winding number.
    const Hierarchy h = planHierarchy(triangleCount_);
    for (uint32_t level = 0; level < h.levels && !pseudoNormalSign_; ++level) {
      dispatch(kCluster, h.count[level], {level, 0});
      // Level l's nodes are written before level l + 1 (and the final pass) reads them.
      computeToCompute();
    }
    stamp(2);
    dispatch(kSplat, triangleCount_, {0, 0});
    // Every atomic minimum must be done before mode 1 compares against the minimum.
    computeToCompute();
    dispatch(kSplat, triangleCount_, {1, 0});
    // Seed ids are written before the first flood step reads them.
    computeToCompute();
    stamp(3);
    uint32_t flip = 0;
    for (uint32_t step :
         jumpSteps(std::max({box_.resolution.x, box_.resolution.y, box_.resolution.z}))) {
      dispatch(kJfa, nodeCount, {step, flip});
      // This step's ids are written before the next step (or the final pass) reads them, and
      // the next step overwrites the buffer this one read.
      computeToCompute();
      flip ^= 1u;
    }
    stamp(4);
    dispatch(kFinalize, nodeCount, {0, flip});
    if (pseudoNormalSign_) {
      // The unrepaired values are written before the repair pass reads them.
      computeToCompute();
      dispatch(kRepair, nodeCount, {});
    }
    // The SDF is written before sampling and the host copy read it.
    barrier(kCompute, kWrite, kCompute | kTransfer, kRead | VK_ACCESS_TRANSFER_READ_BIT);
    stamp(5);
  }
  if (pointCount > 0) {
    dispatch(kSample, pointCount, {});
    // Sampled values are written before the host reads them after the fence.
    barrier(kCompute, kWrite, VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
  }
  stamp(6);
  profiledBuild_ = build && queries != VK_NULL_HANDLE;
  if (readBack) {
    VkBufferCopy copy{0, 0, nodeCount * 4};
    fn.vkCmdCopyBuffer(cmd, o.buffers[kValues].buffer.get(), o.buffers[kValuesHost].buffer.get(), 1,
                       &copy);
    // The host copy is written before the host reads it after the fence.
    barrier(kTransfer, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
            VK_ACCESS_HOST_READ_BIT);
  }
  if (VkResult r = fn.vkEndCommandBuffer(cmd)) return fail(r, "vkEndCommandBuffer");
  return Status::ok;
}

Status VkSdfBuilder::submitRecorded() {
  const VkFunctions& fn = ctx_->fn();
  if (simulateLost_) return fail(VK_ERROR_DEVICE_LOST, "vkQueueSubmit (simulated)");
  const VkFence fence = objects_->fence.get();
  if (VkResult r = fn.vkResetFences(ctx_->handle(), 1, &fence)) return fail(r, "vkResetFences");
  auto submit = vkStruct<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &objects_->cmd;
  if (VkResult r = fn.vkQueueSubmit(ctx_->queue(), 1, &submit, fence)) {
    return fail(r, "vkQueueSubmit");
  }
  pending_ = true;
  everSubmitted_ = true;
  gridValid_ = false;
  samples_.clear();
  return Status::ok;
}

void VkSdfBuilder::collectResults() {
  pending_ = false;
  Objects& o = *objects_;
  passTimesMs_.clear();
  if (profiledBuild_) {
    uint64_t ticks[kTimestampCount] = {};
    if (ctx_->fn().vkGetQueryPoolResults(ctx_->handle(), o.timestamps.get(), 0, kTimestampCount,
                                         sizeof(ticks), ticks, sizeof(uint64_t),
                                         VK_QUERY_RESULT_64_BIT) == VK_SUCCESS) {
      const double msPerTick = double(ctx_->properties().limits.timestampPeriod) * 1e-6;
      for (uint32_t i = 1; i < kTimestampCount; ++i) {
        passTimesMs_.push_back(double(ticks[i] - ticks[i - 1]) * msPerTick);
      }
    }
  }
  if (VkResult r = invalidateBuffer(*ctx_, o.buffers[kSamples])) {
    fail(r, "vkInvalidateMappedMemoryRanges");
    return;
  }
  const auto* s = static_cast<const float*>(o.buffers[kSamples].mapped);
  samples_.assign(s, s + pointCount_);
  if (readBackPending_) {
    if (VkResult r = invalidateBuffer(*ctx_, o.buffers[kValuesHost])) {
      fail(r, "vkInvalidateMappedMemoryRanges");
      return;
    }
    grid_ = SdfGrid(box_);
    std::memcpy(grid_.values().data(), o.buffers[kValuesHost].mapped, box_.nodeCount() * 4);
    gridValid_ = true;
    readBackPending_ = false;
  }
}

SdfPoll VkSdfBuilder::poll() {
  if (failed_) return SdfPoll::failed;
  if (!pending_) return everSubmitted_ ? SdfPoll::ready : SdfPoll::idle;
  const VkFence fence = objects_->fence.get();
  const VkResult r =
      simulateLost_ ? VK_ERROR_DEVICE_LOST : ctx_->fn().vkGetFenceStatus(ctx_->handle(), fence);
  if (r == VK_NOT_READY) return SdfPoll::pending;
  if (r != VK_SUCCESS) {
    fail(r, "vkGetFenceStatus");
    return SdfPoll::failed;
  }
  collectResults();
  return failed_ ? SdfPoll::failed : SdfPoll::ready;
}

SdfPoll VkSdfBuilder::wait(uint64_t timeoutNs) {
  if (failed_ || !pending_ || simulateLost_) return poll();
  const VkFence fence = objects_->fence.get();
  const VkResult r = ctx_->fn().vkWaitForFences(ctx_->handle(), 1, &fence, VK_TRUE, timeoutNs);
  if (r == VK_TIMEOUT) return SdfPoll::pending;
  if (r != VK_SUCCESS) {
    fail(r, "vkWaitForFences");
    return SdfPoll::failed;
  }
  collectResults();
  return failed_ ? SdfPoll::failed : SdfPoll::ready;
}

}  // namespace sdfg
