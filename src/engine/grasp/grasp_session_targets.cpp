// GraspSession's targets: the registry (meshes, shapes, device targets), their set-up on the
// worker, roles, hands and placements, vertex updates, and the broad phase they are indexed in.
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "grasp/grasp_session.h"

namespace sdfg {
namespace {

// Finite, and min <= max on every axis (a flat box is fine).
bool validBounds(const Aabb& bounds) {
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(bounds.min[a]) || !std::isfinite(bounds.max[a]) ||
        !(bounds.min[a] <= bounds.max[a]))
      return false;
  }
  return true;
}

}  // namespace

Status GraspSession::addTarget(uint64_t id, TriangleMesh mesh, SharedMesh deviceCopy) {
  if (targets_.count(id) != 0) return Status::invalid_argument;
  Target t;
  t.meshTarget = true;
  // The set-up (a second for a few hundred thousand triangles) is the worker's; the target is
  // graspable once it is ready (refreshSetups).
  if (deferredUsable() && deferredForMeshTargets_) {
    if (deviceCopy.positions == nullptr || deviceCopy.indices == nullptr) {
      deviceCopy.positions = std::make_shared<const std::vector<glm::vec3>>(mesh.positions);
      deviceCopy.indices = std::make_shared<const std::vector<uint32_t>>(mesh.indices);
    }
    t.deviceCopy = std::move(deviceCopy);
  }
  t.setup = TargetSetup::pending;
  t.vertexCount = mesh.positions.size();
  worker_->addTarget(id, std::move(mesh));
  targets_.emplace(id, std::move(t));
  pendingSetups_.push_back(id);
  return Status::ok;
}

TargetSetup GraspSession::targetSetup(uint64_t id) const {
  auto it = targets_.find(id);
  if (it == targets_.end()) return TargetSetup::unknown;
  if (it->second.setup == TargetSetup::pending) return worker_->targetInfo(id).setup;
  return it->second.setup;
}

std::vector<std::pair<uint64_t, std::string>> GraspSession::takeSetupFailures() {
  refreshSetups();
  return std::exchange(setupFailures_, {});
}

std::vector<std::pair<uint64_t, std::string>> GraspSession::takeRefusedUpdates() {
  return worker_->takeRefusedUpdates();
}

std::vector<std::pair<uint64_t, MeshSetupReport>> GraspSession::takeSetupReports() {
  refreshSetups();
  return std::exchange(setupReports_, {});
}

void GraspSession::refreshSetups() {
  // Only the targets still being set up: a room of a thousand ready targets costs nothing here.
  size_t kept = 0;
  for (const uint64_t id : pendingSetups_) {
    auto it = targets_.find(id);
    if (it == targets_.end() || it->second.setup != TargetSetup::pending) continue;
    Target& t = it->second;
    GraspWorker::TargetInfo info = worker_->targetInfo(id);
    if (info.setup == TargetSetup::ready) {
      // Bounds set by updateTargetVertices meanwhile are newer than the set-up's.
      if (t.version == 0) t.bounds = info.bounds;
      t.setup = TargetSetup::ready;
      // The GPU's copy takes the triangles as the set-up welded them and turned them outward.
      if (t.deviceCopy.indices != nullptr && info.orientedIndices != nullptr)
        t.deviceCopy.indices = info.orientedIndices;
      setupReports_.emplace_back(id, info.found);
      reindex(id, t);
    } else if (info.setup == TargetSetup::failed) {
      t.setup = TargetSetup::failed;
      ++failedSetups_;
      setupFailures_.emplace_back(id, std::move(info.error));
    } else {
      pendingSetups_[kept++] = id;
    }
  }
  pendingSetups_.resize(kept);
}

GraspSession::SetupCounts GraspSession::setupCounts() {
  refreshSetups();
  SetupCounts c;
  collectReadbacks();
  c.pending = pendingSetups_.size() + mirrorsPending_;
  c.failed = failedSetups_;
  // The depth scene's targets are the session's own, not the caller's to count.
  c.ready = targets_.size() - c.pending - c.failed - (depthOn_ ? 2 : 0);
  return c;
}

Status GraspSession::addDeviceTarget(uint64_t id, const Aabb& bounds) {
  if (targets_.count(id) != 0) return Status::invalid_argument;
  if (!validBounds(bounds)) return Status::invalid_argument;
  if (!deferredUsable() || !deferred_->hasDeviceMesh(id)) return Status::unsupported;
  Target t;
  t.bounds = bounds;
  t.deviceTarget = true;
  auto [it, inserted] = targets_.emplace(id, std::move(t));
  (void)inserted;
  reindex(id, it->second);
  // Read back at once, as a CPU mesh is set up at once: most of a scene is still.
  askReadback(id, it->second);
  return Status::ok;
}

Status GraspSession::addShapeTarget(uint64_t id, const AnalyticShape& shape) {
  if (targets_.count(id) != 0 || shape.validate()) return Status::invalid_argument;
  Target t;
  t.shapeTarget = true;
  t.shape = shape;
  t.bounds = shape.bounds();
  worker_->addShape(id, shape);
  auto [it, inserted] = targets_.emplace(id, std::move(t));
  (void)inserted;
  reindex(id, it->second);
  return Status::ok;
}

Status GraspSession::setTargetRole(uint64_t id, TargetRole role) {
  auto it = targets_.find(id);
  if (it == targets_.end()) return Status::invalid_argument;
  it->second.role = role;
  reindex(id, it->second);
  return Status::ok;
}

TargetRole GraspSession::targetRole(uint64_t id) const {
  auto it = targets_.find(id);
  return it == targets_.end() ? TargetRole::ignored : it->second.role;
}

Status GraspSession::placeTarget(uint64_t id, uint64_t space, const Pose& spaceFromObject) {
  if (isDepthTarget(id)) return Status::invalid_argument;  // placed by the session
  auto it = targets_.find(id);
  if (it == targets_.end()) return Status::invalid_argument;
  Target& t = it->second;
  t.placed = true;
  t.space = space;
  t.spaceFromObject = spaceFromObject;
  t.indexed = false;  // placed anew below
  index_.remove(id);
  reindex(id, t);
  return Status::ok;
}

Status GraspSession::unplaceTarget(uint64_t id) {
  if (isDepthTarget(id)) return Status::invalid_argument;  // placed by the session
  auto it = targets_.find(id);
  if (it == targets_.end()) return Status::invalid_argument;
  it->second.placed = false;
  reindex(id, it->second);
  return Status::ok;
}

std::vector<SceneHit> GraspSession::targetsNear(const Pose& worldFromBox,
                                                const glm::vec3& half) const {
  std::vector<SceneHit> out;
  index_.query(worldFromBox, half, out);
  return out;
}

void GraspSession::reindex(uint64_t id, Target& t) {
  const bool wanted = t.placed && t.setup == TargetSetup::ready && t.role != TargetRole::ignored;
  if (!wanted) {
    if (t.indexed) index_.remove(id);
    t.indexed = false;
    return;
  }
  std::optional<Aabb> bounds;
  if (!t.shapeTarget || t.shape->bounded()) bounds = t.bounds;
  if (!t.indexed || !index_.contains(id)) {
    index_.place(id, t.space, t.spaceFromObject, bounds);
  } else if (bounds) {
    index_.setBounds(id, *bounds);
  }
  t.indexed = true;
}

Status GraspSession::updateTargetBounds(uint64_t id, const Aabb& bounds) {
  if (isDepthTarget(id)) return Status::invalid_argument;  // placed by the session
  auto it = targets_.find(id);
  if (it == targets_.end() || it->second.meshTarget) return Status::invalid_argument;
  if (!validBounds(bounds)) return Status::invalid_argument;
  it->second.bounds = bounds;
  reindex(id, it->second);
  return Status::ok;
}

Status GraspSession::touchTarget(uint64_t id) {
  auto it = targets_.find(id);
  if (it == targets_.end()) return Status::invalid_argument;
  Target& t = it->second;
  // A target built from the device's buffers sees the change at its next build; one built from
  // its readback, once the readback of the change is in (collectReadbacks).
  if (t.mirror != Mirror::ready) ++t.version;
  if (t.mirror == Mirror::none || t.mirror == Mirror::failed) return Status::ok;
  if (nearHand(id, t)) {
    askReadback(id, t);
  } else if (!t.readbackStale) {
    t.readbackStale = true;
    staleTargets_.push_back(id);
  }
  return Status::ok;
}

Status GraspSession::updateTargetVertices(uint64_t id, std::span<const glm::vec3> positions) {
  auto it = targets_.find(id);
  if (it == targets_.end() || !it->second.meshTarget) return Status::invalid_argument;
  Target& t = it->second;
  // The refit is the worker's, before its next build of this target (latest positions win).
  if (positions.size() != t.vertexCount) return Status::invalid_argument;
  if (t.deviceCopy.positions != nullptr) {
    t.deviceCopy.positions =
        std::make_shared<const std::vector<glm::vec3>>(positions.begin(), positions.end());
  }
  t.bounds = computeBounds(positions);
  ++t.version;
  reindex(id, t);
  worker_->updateVertices(id, std::vector<glm::vec3>(positions.begin(), positions.end()),
                          t.version);
  return Status::ok;
}

Status GraspSession::updateTargetVertices(uint64_t id, std::vector<glm::vec3>&& positions,
                                          const Aabb& bounds) {
  std::shared_ptr<const std::vector<glm::vec3>> devicePositions;
  return updateTargetVertices(id, std::move(positions), bounds, devicePositions);
}

bool GraspSession::wantsDevicePositions(uint64_t id) const {
  auto it = targets_.find(id);
  return it != targets_.end() && it->second.deviceCopy.positions != nullptr && deferredUsable();
}

Status GraspSession::updateTargetVertices(
    uint64_t id, std::vector<glm::vec3>&& positions, const Aabb& bounds,
    std::shared_ptr<const std::vector<glm::vec3>>& devicePositions) {
  auto it = targets_.find(id);
  if (it == targets_.end() || !it->second.meshTarget) return Status::invalid_argument;
  Target& t = it->second;
  if (positions.size() != t.vertexCount) return Status::invalid_argument;
  if (t.deviceCopy.positions != nullptr) {
    // The copy the mailbox may still hold is replaced, never written: it goes back to the caller.
    if (devicePositions == nullptr || devicePositions->size() != positions.size())
      devicePositions = std::make_shared<const std::vector<glm::vec3>>(positions);
    std::swap(t.deviceCopy.positions, devicePositions);
  }
  t.bounds = bounds;
  ++t.version;
  reindex(id, t);
  worker_->updateVertices(id, std::move(positions), t.version);
  return Status::ok;
}

std::vector<glm::vec3> GraspSession::vertexBuffer(uint64_t id) {
  return worker_->spareBuffer(id);
}

bool GraspSession::removeTarget(uint64_t id) {
  if (isDepthTarget(id)) return false;  // the session's own (enableDepthScene)
  for (size_t h = 0; h < 2; ++h) {
    HandState& hand = hands_[h];
    // The hand lets go of a target it holds, and of a grab not yet decided that saw it (a squeeze
    // still held starts a new grab on what is left).
    const bool inScene =
        std::any_of(hand.members.begin(), hand.members.end(),
                    [&](const GraspWorker::JobMember& m) { return m.target == id; });
    if (hand.grasp.holding && (hand.grasp.target == id || (!hand.decided && inScene))) {
      cancelPending(hand, h);
      hand.grasp = HandGrasp{};
    }
  }
  worker_->removeTarget(id);
  index_.remove(id);
  auto it = targets_.find(id);
  if (it == targets_.end()) return false;
  if (it->second.setup == TargetSetup::failed) --failedSetups_;
  if (it->second.mirror == Mirror::asked || it->second.mirror == Mirror::settingUp)
    --mirrorsPending_;
  targets_.erase(it);
  return true;
}

Status GraspSession::setTargetHands(uint64_t id, bool left, bool right) {
  auto it = targets_.find(id);
  if (it == targets_.end()) return Status::invalid_argument;
  it->second.hands = {left, right};
  return Status::ok;
}

}  // namespace sdfg
