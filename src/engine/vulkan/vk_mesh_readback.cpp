#define VK_NO_PROTOTYPES  // every call goes through the borrowed device's function table
#include "vulkan/vk_mesh_readback.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <iostream>

#include "sdfg_spirv.h"

namespace sdfg {

namespace {

constexpr uint64_t kDestroyWaitNs = 2'000'000'000ull;

struct PushConstants {
  uint32_t positionOffset, positionStride, vertexCount, indexOffset, indexCount, index16;
};

}  // namespace

struct VkMeshReadback::Objects {
  VkOwned<VkDescriptorSetLayout> setLayout;
  VkOwned<VkPipelineLayout> pipelineLayout;
  VkOwned<VkPipeline> pipeline;
  VkSubmitObjects submit;  // the descriptor set, command buffer and fence
  VkBufferAlloc gathered;  // grown to the largest mesh gathered
};

VkMeshReadback::VkMeshReadback() = default;

Result<std::unique_ptr<VkMeshReadback>> VkMeshReadback::create(
    const VulkanDevice& device, std::function<void(const std::string&)> log) {
  auto ctx = VkContext::create(device);
  if (!ctx) return ctx.error();
  std::unique_ptr<VkMeshReadback> b(new VkMeshReadback());
  b->ctx_ = std::move(ctx.value());
  b->log_ = std::move(log);
  b->objects_ = std::make_unique<Objects>();
  const VkContext& c = *b->ctx_;
  Objects& o = *b->objects_;
  const VkPhysicalDeviceLimits& limits = c.properties().limits;
  b->groupSize_ =
      std::min({64u, limits.maxComputeWorkGroupSize[0], limits.maxComputeWorkGroupInvocations});

  if (auto e = createComputeLayouts(c, 3, sizeof(PushConstants), o.setLayout, o.pipelineLayout))
    return *e;
  const VkDescriptorSetLayout setLayout = o.setLayout.get();
  const VkPipelineLayout pipelineLayout = o.pipelineLayout.get();

  auto pipeline = createComputePipeline(c, pipelineLayout, spirv::k_mesh_gather, b->groupSize_);
  if (!pipeline) return pipeline.error();
  o.pipeline = std::move(pipeline.value());

  if (auto e = createSubmitObjects(c, setLayout, 3, o.submit)) return *e;
  return b;
}

VkMeshReadback::~VkMeshReadback() {
  if (!ctx_ || !objects_ || !pending_) return;
  // The GPU may still write our buffer and read the app's: wait before anything goes.
  const VkFence fence = objects_->submit.fence.get();
  if (ctx_->fn().vkWaitForFences(ctx_->handle(), 1, &fence, VK_TRUE, kDestroyWaitNs) ==
      VK_TIMEOUT) {
    // Destroying what a hung device still uses is worse than leaking it.
    objects_->gathered.buffer.release();
    objects_->gathered.memory.release();
    objects_->submit.commandPool.release();
    objects_->submit.fence.release();
  }
}

Status VkMeshReadback::fail(VkResult result, const char* what) {
  const Error e = vkCallError(result, what);
  if (!failed_) {
    const std::string line = "sdfg: mesh readback disabled: " + e.message;
    if (log_)
      log_(line);
    else
      std::cerr << line << std::endl;
  }
  failed_ = true;
  return e.code;
}

Status VkMeshReadback::submit(uint64_t id, uint64_t generation, const VkMeshBuffers& buffers,
                              bool withIndices) {
  if (failed_) return Status::device_lost;
  if (pending_) return Status::unsupported;
  if (!validMeshBuffers(buffers)) return Status::invalid_argument;
  const uint32_t indexSize = buffers.indexType == VK_INDEX_TYPE_UINT16 ? 2 : 4;
  if (simulateLost_) return fail(VK_ERROR_DEVICE_LOST, "vkQueueSubmit (simulated)");
  const VkContext& c = *ctx_;
  const VkFunctions& fn = c.fn();
  Objects& o = *objects_;
  const uint32_t indexCount = withIndices ? buffers.indexCount : 0;
  const VkDeviceSize bytes = (VkDeviceSize(buffers.vertexCount) * 3 + indexCount) * 4;
  if (o.gathered.size < bytes) {
    o.gathered = VkBufferAlloc{};
    auto made = createBuffer(c, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, VkMemoryKind::readback);
    if (!made) {
      failed_ = true;
      if (log_) log_("sdfg: mesh readback disabled: " + made.error().message);
      return made.error().code;
    }
    o.gathered = std::move(made.value());
  }
  std::array<VkDescriptorBufferInfo, 3> infos{};
  infos[0] = {buffers.positions, 0, VK_WHOLE_SIZE};
  infos[1] = {buffers.indices, 0, VK_WHOLE_SIZE};
  infos[2] = {o.gathered.buffer.get(), 0, VK_WHOLE_SIZE};
  std::array<VkWriteDescriptorSet, 3> writes{};
  for (uint32_t i = 0; i < writes.size(); ++i) {
    writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    writes[i].dstSet = o.submit.set;
    writes[i].dstBinding = i;
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[i].pBufferInfo = &infos[i];
  }
  // The set is not in use: no gather is in flight (pending_ is false).
  fn.vkUpdateDescriptorSets(c.handle(), uint32_t(writes.size()), writes.data(), 0, nullptr);

  VkCommandBuffer cmd = o.submit.cmd;
  if (VkResult r = fn.vkResetCommandBuffer(cmd, 0)) return fail(r, "vkResetCommandBuffer");
  auto begin = vkStruct<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  if (VkResult r = fn.vkBeginCommandBuffer(cmd, &begin)) return fail(r, "vkBeginCommandBuffer");
  // The app's skinning (a shader or a copy earlier on this queue) is visible to the gather.
  recordMemoryBarrier(c, cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                      VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT,
                      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
  fn.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, o.pipeline.get());
  fn.vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, o.pipelineLayout.get(), 0, 1,
                             &o.submit.set, 0, nullptr);
  const PushConstants pc{uint32_t(buffers.positionOffset / 4),
                         buffers.positionStride / 4,
                         buffers.vertexCount,
                         uint32_t(buffers.indexOffset / indexSize),
                         indexCount,
                         indexSize == 2 ? 1u : 0u};
  fn.vkCmdPushConstants(cmd, o.pipelineLayout.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(pc),
                        &pc);
  const uint64_t items = std::max(buffers.vertexCount, indexCount);
  fn.vkCmdDispatch(cmd, uint32_t((items + groupSize_ - 1) / groupSize_), 1, 1);
  recordMemoryBarrier(c, cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                      VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
  if (VkResult r = fn.vkEndCommandBuffer(cmd)) return fail(r, "vkEndCommandBuffer");

  const VkFence fence = o.submit.fence.get();
  if (VkResult r = fn.vkResetFences(c.handle(), 1, &fence)) return fail(r, "vkResetFences");
  auto submitInfo = vkStruct<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
  submitInfo.commandBufferCount = 1;
  submitInfo.pCommandBuffers = &o.submit.cmd;
  if (VkResult r = fn.vkQueueSubmit(c.queue(), 1, &submitInfo, fence))
    return fail(r, "vkQueueSubmit");
  pending_ = true;
  id_ = id;
  generation_ = generation;
  vertexCount_ = buffers.vertexCount;
  indexCount_ = indexCount;
  return Status::ok;
}

std::optional<MeshReadback> VkMeshReadback::collect() {
  pending_ = false;
  const VkBufferAlloc& out = objects_->gathered;
  if (VkResult r = invalidateBuffer(*ctx_, out)) {
    fail(r, "vkInvalidateMappedMemoryRanges");
    return std::nullopt;
  }
  MeshReadback mesh;
  mesh.id = id_;
  mesh.generation = generation_;
  mesh.positions.resize(vertexCount_);
  mesh.indices.resize(indexCount_);
  const auto* words = static_cast<const char*>(out.mapped);
  std::memcpy(mesh.positions.data(), words, size_t(vertexCount_) * 12);
  // Positions only: no indices to copy (and memcpy must not see the empty vector's null data).
  if (indexCount_ > 0)
    std::memcpy(mesh.indices.data(), words + size_t(vertexCount_) * 12, size_t(indexCount_) * 4);
  return mesh;
}

std::optional<MeshReadback> VkMeshReadback::poll() {
  if (failed_ || !pending_) return std::nullopt;
  const VkFence fence = objects_->submit.fence.get();
  const VkResult r =
      simulateLost_ ? VK_ERROR_DEVICE_LOST : ctx_->fn().vkGetFenceStatus(ctx_->handle(), fence);
  if (r == VK_NOT_READY) return std::nullopt;
  if (r != VK_SUCCESS) {
    fail(r, "vkGetFenceStatus");
    return std::nullopt;
  }
  return collect();
}

std::optional<MeshReadback> VkMeshReadback::wait(uint64_t timeoutNs) {
  if (failed_ || !pending_ || simulateLost_) return poll();
  const VkFence fence = objects_->submit.fence.get();
  const VkResult r = ctx_->fn().vkWaitForFences(ctx_->handle(), 1, &fence, VK_TRUE, timeoutNs);
  if (r == VK_TIMEOUT) return std::nullopt;
  if (r != VK_SUCCESS) {
    fail(r, "vkWaitForFences");
    return std::nullopt;
  }
  return collect();
}

}  // namespace sdfg
