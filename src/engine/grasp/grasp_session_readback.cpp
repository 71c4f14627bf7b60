// GraspSession's device targets read back to the CPU (see addDeviceTarget): what it asks of the
// deferred backend, and how a readback becomes a mesh on the worker.
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "grasp/grasp_session.h"

namespace sdfg {

void GraspSession::askReadback(uint64_t id, Target& t) {
  if (!deferredUsable()) return;
  const uint64_t generation = ++readbackGeneration_;
  const Status s = deferred_->requestReadback(id, generation);
  if (s != Status::ok) {
    // No readback on this backend (or the device failed): the field only, as before readbacks.
    if (t.mirror == Mirror::asked) {
      t.mirror = Mirror::none;
      --mirrorsPending_;
    }
    return;
  }
  t.readbackStale = false;
  if (t.mirror == Mirror::none) {
    t.mirror = Mirror::asked;
    ++mirrorsPending_;
  }
}

bool GraspSession::nearHand(uint64_t id, const Target& t) const {
  const std::optional<Pose> worldFromObject = index_.worldFromObject(id);
  if (!worldFromObject) return false;  // not placed: asked again when it comes near a hand
  const glm::vec3 centre = worldFromObject->transformPoint(t.bounds.center());
  const float radius = 0.5f * glm::length(t.bounds.max - t.bounds.min);
  for (const HandState& hand : hands_) {
    if (hand.lastWrist && glm::length(hand.lastWrist->position - centre) - radius < kReadbackReach)
      return true;
  }
  return false;
}

void GraspSession::collectReadbacks() {
  if (!deferredUsable() && mirrorsPending_ > 0) {
    // The device failed or went: readbacks asked will never come. Those targets go on as before
    // readbacks (a device target is lost with its device anyway).
    for (auto& [id, t] : targets_) {
      if (t.mirror != Mirror::asked) continue;
      t.mirror = Mirror::none;
      --mirrorsPending_;
    }
  }
  if (deferred_ == nullptr) return;
  // Changes made while far from every hand, now that a hand is near.
  if (!staleTargets_.empty()) {
    size_t kept = 0;
    for (const uint64_t id : staleTargets_) {
      auto it = targets_.find(id);
      if (it == targets_.end() || !it->second.readbackStale) continue;
      if (nearHand(id, it->second))
        askReadback(id, it->second);
      else
        staleTargets_[kept++] = id;
    }
    staleTargets_.resize(kept);
  }
  for (MeshReadback& r : deferred_->takeReadbacks()) {
    auto it = targets_.find(r.id);
    if (it == targets_.end() || !it->second.deviceTarget) continue;  // removed meanwhile
    Target& t = it->second;
    if (r.positions.empty()) {
      // Refused by the device: a target still waiting for its first copy goes on without one.
      if (t.mirror == Mirror::asked) {
        t.mirror = Mirror::none;
        --mirrorsPending_;
      }
      continue;
    }
    if (r.generation <= t.readbackApplied || t.mirror == Mirror::failed) continue;
    t.readbackApplied = r.generation;
    ++t.version;
    if (!r.indices.empty()) {
      // The first readback (or new index buffers): a set-up, as for a CPU mesh. The worker
      // checks what the device held (a NaN or an index out of range refuses it).
      // Triangles that name an index the device could not give (out of range, or in the last
      // two bytes of a 16-bit index buffer whose size is not a multiple of four, which no
      // 32-bit shader read reaches) are left out, as the device's own builds leave them out.
      const size_t before = r.indices.size() / 3;
      const size_t vertices = r.positions.size();
      size_t kept = 0;
      for (size_t i = 0; i + 2 < r.indices.size(); i += 3) {
        if (r.indices[i] >= vertices || r.indices[i + 1] >= vertices ||
            r.indices[i + 2] >= vertices)
          continue;
        for (size_t k = 0; k < 3; ++k) r.indices[3 * kept + k] = r.indices[i + k];
        ++kept;
      }
      r.indices.resize(3 * kept);
      if (kept < before)
        readbackNotes_.emplace_back(
            r.id, std::to_string(before - kept) + " of its " + std::to_string(before) +
                      " triangles name an index its buffers do not hold (out of range, or in the "
                      "last two bytes of a 16-bit index buffer whose size is not a multiple of 4, "
                      "which shaders cannot read): they are left out");
      t.vertexCount = vertices;
      TriangleMesh mesh{std::move(r.positions), std::move(r.indices)};
      // The GPU's copy, where it builds meshes too, is the one copy made (this runs in the app's
      // xrSyncActions); otherwise the worker takes the arrays as they came.
      if (deferredForMeshTargets_)
        t.deviceCopy = SharedMesh{std::make_shared<const std::vector<glm::vec3>>(mesh.positions),
                                  std::make_shared<const std::vector<uint32_t>>(mesh.indices)};
      worker_->addTarget(r.id, std::move(mesh));
      if (t.mirror != Mirror::settingUp) mirrorSetups_.push_back(r.id);
      t.mirror = Mirror::settingUp;
    } else if (t.mirror == Mirror::ready || t.mirror == Mirror::settingUp) {
      if (r.positions.size() != t.vertexCount) continue;
      if (t.deviceCopy.positions != nullptr)
        t.deviceCopy.positions = std::make_shared<const std::vector<glm::vec3>>(r.positions);
      // The worker refits before its next build of the target (and refuses a pose that collapses
      // a triangle, keeping the last one, as for a CPU mesh).
      worker_->updateVertices(r.id, std::move(r.positions), t.version);
    }
  }
  if (mirrorSetups_.empty()) return;
  size_t kept = 0;
  for (const uint64_t id : mirrorSetups_) {
    auto it = targets_.find(id);
    if (it == targets_.end() || it->second.mirror != Mirror::settingUp) continue;
    Target& t = it->second;
    GraspWorker::TargetInfo info = worker_->targetInfo(id);
    if (info.setup == TargetSetup::ready) {
      t.mirror = Mirror::ready;
      --mirrorsPending_;
      ++t.version;  // a hand holding it solves again, now with its exact distance
      if (t.deviceCopy.indices != nullptr && info.orientedIndices != nullptr)
        t.deviceCopy.indices = info.orientedIndices;
    } else if (info.setup == TargetSetup::failed) {
      t.mirror = Mirror::failed;
      --mirrorsPending_;
      t.deviceCopy = SharedMesh{};
      worker_->removeTarget(id);
      readbackNotes_.emplace_back(
          id, "the mesh read back from its Vulkan buffers was refused (" + info.error +
                  "): it is grasped through its grab-box field only (no exact contacts, not seen "
                  "by the outer hand)");
    } else {
      mirrorSetups_[kept++] = id;
    }
  }
  mirrorSetups_.resize(kept);
}

std::vector<std::pair<uint64_t, std::string>> GraspSession::takeReadbackNotes() {
  collectReadbacks();
  return std::exchange(readbackNotes_, {});
}

}  // namespace sdfg
