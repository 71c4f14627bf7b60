#include "vulkan/vk_grasp_backend.h"

#include <iostream>

namespace sdfg {

namespace {
constexpr uint64_t kDestroyWaitNs = 2'000'000'000ull;
}

Result<std::unique_ptr<VkSdfBuilder>> VkGraspBackend::makeBuilder(const VulkanDevice& device) {
  VkSdfOptions options;
  // Every builder reports through the backend, which writes the session's one failure line.
  options.log = [this](const std::string& line) { logOnce(line); };
  return VkSdfBuilder::create(device, options);
}

Result<std::unique_ptr<VkGraspBackend>> VkGraspBackend::create(
    const VulkanDevice& appQueue, const VulkanDevice* ownQueue,
    const VkGraspBackendOptions& options) {
  std::unique_ptr<VkGraspBackend> b(new VkGraspBackend());
  b->options_ = options;
  b->appQueue_ = appQueue;
  b->ownQueue_ = ownQueue != nullptr;
  for (Slot& slot : b->slots_) {
    auto builder = b->makeBuilder(ownQueue != nullptr ? *ownQueue : appQueue);
    if (!builder) return builder.error();
    slot.main.builder = std::move(builder.value());
    slot.main.shared = ownQueue == nullptr;
  }
  return b;
}

VkGraspBackend::~VkGraspBackend() {
  // Each builder's destructor waits for its submission in flight before freeing anything.
  for (Slot& slot : slots_) {
    slot.main.builder.reset();
    slot.app.builder.reset();
  }
}

void VkGraspBackend::logOnce(const std::string& line) {
  if (logged_) return;
  logged_ = true;
  if (options_.log) {
    options_.log(line);
  } else {
    std::cerr << line << std::endl;
  }
}

Status VkGraspBackend::markFailed(Status status) {
  if (!failed_) {
    failed_ = true;
    // A builder has usually logged the cause already; this covers failures found here.
    logOnce(std::string("sdfg: Vulkan SDF backend disabled, falling back to the CPU (") +
            toString(status) + ")");
  }
  for (Slot& slot : slots_) slot.recorded = false;
  return status == Status::ok ? Status::device_lost : status;
}

Status VkGraspBackend::request(size_t slot, uint64_t id, uint64_t version, const TriangleMesh* mesh,
                               const Pose& objectFromHand, const GridBox& box) {
  if (failed_) return Status::device_lost;
  if (slot >= kSlots || box.validate()) return Status::invalid_argument;
  Slot& s = slots_[slot];
  if (s.recorded) return Status::unsupported;
  if (s.inFlight) {
    // A cancelled build may have finished: collect it before reusing the builder.
    const SdfPoll p = s.active->builder->poll();
    if (p == SdfPoll::pending) return Status::unsupported;
    s.inFlight = false;
    if (p == SdfPoll::failed) return markFailed(Status::device_lost);
  }
  if (mesh == nullptr) {
    auto it = deviceMeshes_.find(id);
    if (it == deviceMeshes_.end()) return Status::invalid_argument;
    Builder& b = s.app.builder ? s.app : s.main;
    if (!b.meshOnDevice || b.meshId != id || b.meshVersion != it->second.version) {
      const Status st = b.builder->setMesh(it->second.buffers);
      if (st == Status::invalid_argument) return st;
      if (st != Status::ok) return markFailed(st);
      b.meshId = id;
      b.meshVersion = it->second.version;
      b.meshOnDevice = true;
    }
    s.active = &b;
  } else {
    Builder& b = s.main;
    if (b.meshOnDevice || b.meshId != id || b.meshVersion != version) {
      // Copied now into the builder's staging; uploaded by the build that follows.
      const Status st = b.builder->setMesh(*mesh);
      if (st == Status::invalid_argument) return st;
      if (st != Status::ok) return markFailed(st);
      b.meshId = id;
      b.meshVersion = version;
      b.meshOnDevice = false;
    }
    s.active = &b;
  }
  s.box = box;
  s.objectFromHand = objectFromHand;
  s.recorded = true;
  s.discard = false;
  return Status::ok;
}

bool VkGraspBackend::needsSubmit(bool sharedQueueFree) const {
  if (failed_) return false;
  for (const Slot& s : slots_) {
    if (s.recorded && (sharedQueueFree || !s.active->shared)) return true;
  }
  return false;
}

Status VkGraspBackend::submit(bool sharedQueueFree) {
  if (failed_) return Status::device_lost;
  for (Slot& s : slots_) {
    if (!s.recorded || (s.active->shared && !sharedQueueFree)) continue;
    VkSdfBuilder& builder = *s.active->builder;
    if (fault_ == VkGraspFault::lostAtSubmit) builder.simulateDeviceLostForTesting();
    // No sample points: the solver reads the whole grid, which comes back with the fence.
    const Status st = builder.submitBuild(s.box, s.objectFromHand, {}, true);
    if (st == Status::unsupported) continue;  // still busy; next time
    s.recorded = false;
    if (st != Status::ok) return markFailed(st);
    s.inFlight = true;
    if (fault_ == VkGraspFault::lostAtPoll) builder.simulateDeviceLostForTesting();
  }
  return Status::ok;
}

BuildPoll VkGraspBackend::poll(size_t slot, SdfGrid& out) {
  if (failed_) return BuildPoll::failed;
  if (slot >= kSlots) return BuildPoll::idle;
  Slot& s = slots_[slot];
  if (s.recorded) return BuildPoll::pending;
  if (!s.inFlight) return BuildPoll::idle;
  const SdfPoll p = s.active->builder->poll();
  if (p == SdfPoll::pending) return BuildPoll::pending;
  s.inFlight = false;
  if (p == SdfPoll::failed) {
    markFailed(Status::device_lost);
    return BuildPoll::failed;
  }
  if (s.discard) {
    s.discard = false;
    return BuildPoll::idle;
  }
  const SdfGrid* grid = s.active->builder->grid();
  if (grid == nullptr) {
    markFailed(Status::internal);
    return BuildPoll::failed;
  }
  out = *grid;
  return BuildPoll::ready;
}

void VkGraspBackend::cancel(size_t slot) {
  if (slot >= kSlots) return;
  Slot& s = slots_[slot];
  s.recorded = false;
  if (s.inFlight) s.discard = true;
}

Status VkGraspBackend::setDeviceMesh(uint64_t id, const VkMeshBuffers& buffers) {
  if (failed_) return Status::device_lost;
  const VkDeviceSize indexSize = buffers.indexType == VK_INDEX_TYPE_UINT16 ? 2 : 4;
  // The builder's checks, made here too so that a bad description fails at registration.
  if (buffers.positions == VK_NULL_HANDLE || buffers.indices == VK_NULL_HANDLE ||
      buffers.vertexCount == 0 || buffers.indexCount < 3 || buffers.indexCount % 3 != 0 ||
      buffers.positionStride < 12 || buffers.positionStride % 4 != 0 ||
      buffers.positionOffset % 4 != 0 || buffers.indexOffset % indexSize != 0 ||
      (buffers.indexType != VK_INDEX_TYPE_UINT16 && buffers.indexType != VK_INDEX_TYPE_UINT32) ||
      buffers.indexCount / 3 > (1u << 30) || buffers.positionOffset / 4 > UINT32_MAX ||
      buffers.indexOffset / indexSize > UINT32_MAX)
    return Status::invalid_argument;
  if (ownQueue_) {
    // App buffers are read on the app's queue (see the header): builders there, made once.
    for (Slot& slot : slots_) {
      if (slot.app.builder) continue;
      auto builder = makeBuilder(appQueue_);
      if (!builder) return builder.error().code;
      slot.app.builder = std::move(builder.value());
      slot.app.shared = true;
    }
  }
  auto [it, inserted] = deviceMeshes_.try_emplace(id);
  if (!inserted) ++it->second.version;
  it->second.buffers = buffers;
  return Status::ok;
}

void VkGraspBackend::removeDeviceMesh(uint64_t id) {
  for (Slot& s : slots_) {
    for (Builder* b : {&s.main, &s.app}) {
      if (!b->builder || !b->meshOnDevice || b->meshId != id) continue;
      if (s.active == b) {
        s.recorded = false;
        if (s.inFlight) {
          // The GPU may still read the app's buffers: wait, so the app can destroy them next.
          const SdfPoll p = b->builder->wait(kDestroyWaitNs);
          if (p != SdfPoll::pending) s.inFlight = false;
          if (p == SdfPoll::failed) markFailed(Status::device_lost);
        }
      }
      b->meshId = 0;
      b->meshOnDevice = false;
    }
  }
  deviceMeshes_.erase(id);
}

}  // namespace sdfg
