// VkSdfBuilder's Vulkan objects and meshes: create() makes the pipelines, layouts, pools and
// fence on the borrowed device; setMesh() uploads CPU arrays (with their pseudo-normals) or
// borrows the app's buffers. The submissions are in vk_sdf_submit.cpp.
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
#include "vulkan/vk_sdf_builder_detail.h"

namespace sdfg {

using namespace vk_sdf_detail;  // NOLINT: the builder's own files only

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
  auto error = vkCallError;

  const VkPhysicalDeviceLimits& limits = c.properties().limits;
  b->workGroupSize_ = std::clamp<uint32_t>(
      options.workGroupSize, 1u,
      std::min(limits.maxComputeWorkGroupSize[0], limits.maxComputeWorkGroupInvocations));

  if (auto e = createComputeLayouts(c, L::kBindingCount, sizeof(L::PushConstants), o.setLayout,
                                    o.pipelineLayout))
    return *e;
  const VkDescriptorSetLayout setLayout = o.setLayout.get();
  const VkPipelineLayout pipelineLayout = o.pipelineLayout.get();

  const std::array<std::span<const uint32_t>, kPassCount> code = {
      spirv::k_sdf_transform, spirv::k_sdf_cluster,  spirv::k_sdf_splat,
      spirv::k_sdf_jfa,       spirv::k_sdf_jfa_wide, spirv::k_sdf_flood_group,
      spirv::k_sdf_finalize,  spirv::k_sdf_repair,   spirv::k_sdf_sample};
  // The one-group flood has a fixed work-group size (and 16 KB of shared memory, which every
  // device has); a device with smaller groups floods step by step at every grid size.
  const bool groupFlood = limits.maxComputeWorkGroupSize[0] >= L::kFloodGroupThreads &&
                          limits.maxComputeWorkGroupInvocations >= L::kFloodGroupThreads;
  for (uint32_t p = 0; p < kPassCount; ++p) {
    if (p == kFloodGroup && !groupFlood) continue;
    auto pipeline = createComputePipeline(c, pipelineLayout, code[p], b->workGroupSize_);
    if (!pipeline) return pipeline.error();
    o.pipelines[p] = std::move(pipeline.value());
  }

  if (auto e = createSubmitObjects(c, setLayout, L::kBindingCount, o.submit)) return *e;

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
    const VkFence fence = objects_->submit.fence.get();
    const VkResult r =
        ctx_->fn().vkWaitForFences(ctx_->handle(), 1, &fence, VK_TRUE, 2'000'000'000ull);
    if (r == VK_TIMEOUT) {
      // A hung device: leaking is the only safe choice.
      for (VkBufferAlloc& b : objects_->buffers) {
        b.buffer.release();
        b.memory.release();
      }
      objects_->submit.commandPool.release();
      objects_->submit.descriptorPool.release();
      for (auto& p : objects_->pipelines) p.release();
      objects_->submit.fence.release();
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
    writes[i].dstSet = objects_->submit.set;
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

bool validMeshBuffers(const VkMeshBuffers& m) {
  const VkDeviceSize indexSize = m.indexType == VK_INDEX_TYPE_UINT16 ? 2 : 4;
  return m.positions != VK_NULL_HANDLE && m.indices != VK_NULL_HANDLE && m.vertexCount != 0 &&
         m.indexCount >= 3 && m.indexCount % 3 == 0 && m.positionStride >= 12 &&
         m.positionStride % 4 == 0 && m.positionOffset % 4 == 0 && m.indexOffset % indexSize == 0 &&
         (m.indexType == VK_INDEX_TYPE_UINT16 || m.indexType == VK_INDEX_TYPE_UINT32) &&
         m.indexCount / 3 <= (1u << 30) && m.positionOffset / 4 <= UINT32_MAX &&
         m.indexOffset / indexSize <= UINT32_MAX;
}

Status VkSdfBuilder::setMesh(const VkMeshBuffers& m) {
  if (Status s = checkUsable(); s != Status::ok) return s;
  if (!validMeshBuffers(m)) return Status::invalid_argument;
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

}  // namespace sdfg
