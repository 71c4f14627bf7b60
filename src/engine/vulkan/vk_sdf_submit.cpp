// VkSdfBuilder's submissions: submitBuild() and submitSample() record one command buffer (the
// passes of shaders/ in order, with their barriers) and submit it; poll() and wait() collect the
// results without blocking the frame.
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
  VkCommandBuffer cmd = o.submit.cmd;
  if (VkResult r = fn.vkResetCommandBuffer(cmd, 0)) return fail(r, "vkResetCommandBuffer");
  auto begin = vkStruct<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  if (VkResult r = fn.vkBeginCommandBuffer(cmd, &begin)) return fail(r, "vkBeginCommandBuffer");

  auto barrier = [&](VkPipelineStageFlags srcStage, VkAccessFlags srcAccess,
                     VkPipelineStageFlags dstStage, VkAccessFlags dstAccess) {
    recordMemoryBarrier(*ctx_, cmd, srcStage, srcAccess, dstStage, dstAccess);
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
                             &o.submit.set, 0, nullptr);
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
  const uint32_t maxGroups = ctx_->properties().limits.maxComputeWorkGroupCount[0];
  // The flood (FloodPath). On a CPU device (Mesa's lavapipe) grids of up to kFloodGroupNodes
  // nodes flood in one work group, which halves build times there; with pseudo-normal signs that
  // dispatch also finalizes, repairs and samples (fusedFinal). On a GPU one multiprocessor doing
  // all the work is slower than the whole device step by step (NVIDIA H200, 16^3 grid, 100k
  // triangles: 0.41 ms against 0.09 ms), so every other device type floods step by step. Small
  // grids there take a lane per neighbour (sdf_jfa_wide.comp: one invocation per node left 64
  // groups of 64 waiting on 26 serial triangle distances; 0.05 ms against 0.09 on the H200 at
  // 16^3); larger ones fill the device with one invocation per node, whose early outs then save
  // more than the lanes gain (H200 at 32^3: 0.12 ms per node against 0.26 wide; at 64^3 0.4
  // against 2.2). Larger grids on a CPU take sdf_jfa.comp too.
  const bool cpuDevice = ctx_->properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
  const bool groupFits = o.pipelines[kFloodGroup] && nodeCount <= L::kFloodGroupNodes;
  const bool wideFits = ceilDiv(nodeCount, L::kWideFloodNodesPerGroup) <= maxGroups;
  FloodPath flood = floodTestHooks.force.load(std::memory_order_relaxed);
  if (flood == FloodPath::automatic) {
    flood = cpuDevice                          ? FloodPath::group
            : nodeCount <= L::kFloodGroupNodes ? FloodPath::wide
                                               : FloodPath::perNode;
  }
  if (flood == FloodPath::group && !groupFits) {
    flood = cpuDevice ? FloodPath::perNode : FloodPath::wide;
  }
  if (flood == FloodPath::wide && !wideFits) flood = FloodPath::perNode;
  const bool groupFlood = build && flood == FloodPath::group;
  const bool fusedFinal = groupFlood && pseudoNormalSign_;
  if (groupFlood) floodTestHooks.groupFloods.fetch_add(1, std::memory_order_relaxed);
  if (build && flood == FloodPath::wide) {
    floodTestHooks.wideFloods.fetch_add(1, std::memory_order_relaxed);
  }
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
    // The transform pass also clears the splat's per-node minimum and ids (see its shader).
    dispatch(kTransform, std::max<size_t>(triangleCount_, nodeCount), {});
    // Box-space triangles and the cleared nodes are written before the hierarchy and splat
    // passes read them.
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
    // Several invocations per triangle, unless that many exceed the device's group count.
    const uint32_t split =
        ceilDiv(size_t(triangleCount_) << L::kSplatSplitLog2, workGroupSize_) <= maxGroups
            ? L::kSplatSplitLog2
            : 0;
    const size_t splatItems = size_t(triangleCount_) << split;
    dispatch(kSplat, splatItems, {0, split});
    // Every atomic minimum must be done before mode 1 compares against the minimum.
    computeToCompute();
    dispatch(kSplat, splatItems, {1, split});
    // Seed ids are written before the first flood step reads them.
    computeToCompute();
    stamp(3);
    if (groupFlood) {
      // One work group floods in shared memory (shaders/sdf_flood_group.comp); with
      // pseudo-normals it also writes the values and samples the points.
      fn.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, o.pipelines[kFloodGroup].get());
      fn.vkCmdDispatch(cmd, 1, 1, 1);
      if (!fusedFinal) {
        // The final ids (binding 7) are written before the final pass reads them.
        computeToCompute();
        stamp(4);
        dispatch(kFinalize, nodeCount, {0, 1});
      }
    } else {
      uint32_t flip = 0;
      for (uint32_t step :
           jumpSteps(std::max({box_.resolution.x, box_.resolution.y, box_.resolution.z}))) {
        if (flood == FloodPath::wide) {
          fn.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, o.pipelines[kJfaWide].get());
          const L::PushConstants pc{step, flip};
          fn.vkCmdPushConstants(cmd, o.pipelineLayout.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0,
                                sizeof(pc), &pc);
          fn.vkCmdDispatch(cmd, ceilDiv(nodeCount, L::kWideFloodNodesPerGroup), 1, 1);
        } else {
          dispatch(kJfa, nodeCount, {step, flip});
        }
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
    }
    if (fusedFinal) {
      stamp(4);
      stamp(5);
      // The values and samples are written before the host copy, the host and a later
      // submitSample() read them.
      barrier(kCompute, kWrite, kCompute | kTransfer | VK_PIPELINE_STAGE_HOST_BIT,
              kRead | VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_HOST_READ_BIT);
    } else {
      // The SDF is written before sampling and the host copy read it.
      barrier(kCompute, kWrite, kCompute | kTransfer, kRead | VK_ACCESS_TRANSFER_READ_BIT);
      stamp(5);
    }
  }
  if (pointCount > 0 && !fusedFinal) {
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
  const VkFence fence = objects_->submit.fence.get();
  if (VkResult r = fn.vkResetFences(ctx_->handle(), 1, &fence)) return fail(r, "vkResetFences");
  auto submit = vkStruct<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &objects_->submit.cmd;
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
  const VkFence fence = objects_->submit.fence.get();
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
  const VkFence fence = objects_->submit.fence.get();
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
