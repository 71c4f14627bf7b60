#include "grasp/grasp_session.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

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

float angleBetween(const glm::quat& a, const glm::quat& b) {
  const float d = std::min(1.0f, std::abs(glm::dot(a, b)));
  return 2.0f * std::acos(d);
}

// The space of a target located on its own (update() with TargetFrames): keys the layer's
// XrSpace values never take (their top bit is clear: non-canonical x86-64 addresses apart,
// handles are small integers or user-space pointers).
uint64_t ownSpace(uint64_t target) {
  return target | (uint64_t(1) << 63);
}

}  // namespace

std::optional<Error> GraspSettings::validate() const {
  if (auto e = box.validate()) return e;
  if (!(grabThreshold > 0.0f && grabThreshold <= 1.0f))
    return makeError(Status::invalid_argument, "grasp settings: grabThreshold must be in (0, 1]");
  if (!(releaseRatio >= 0.0f && releaseRatio <= 1.0f))
    return makeError(Status::invalid_argument, "grasp settings: releaseRatio must be in [0, 1]");
  if (!(moveTolerance >= 0.0f) || !(turnTolerance >= 0.0f))
    return makeError(Status::invalid_argument, "grasp settings: tolerances must be >= 0");
  if (buildTimeLimit.count() <= 0)
    return makeError(Status::invalid_argument, "grasp settings: buildTimeLimit must be positive");
  if (auto e = outerOptions.validate()) return e;
  return std::nullopt;
}

GraspSession::GraspSession(std::unique_ptr<SdfBackend> backend,
                           std::unique_ptr<DeferredSdfBackend> deferred)
    : deferred_(std::move(deferred)) {
  hands_[0].model = HandModel::defaultAdult(Hand::left);
  hands_[1].model = HandModel::defaultAdult(Hand::right);
  (void)configure(settings_);
  // The CPU builder is the worker's alone.
  worker_ = std::make_unique<GraspWorker>(std::move(backend));
}

GraspSession::~GraspSession() = default;

Status GraspSession::configure(const GraspSettings& settings) {
  if (settings.validate()) return Status::invalid_argument;
  // The strategy must exist and read the SDF; the worker gets its own instances (prepareSolver).
  auto made = createSolver(settings.solver);
  if (!made) return made.error().code;
  if (!(*made)->needsField() || (*made)->needsCollider()) return Status::unsupported;
  settings_ = settings;
  for (size_t h = 0; h < 2; ++h) {
    // A build in flight was made for the old box: drop it, a held hand asks again.
    cancelPending(hands_[h], h);
    hands_[h].prepared = false;
  }
  return Status::ok;
}

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

bool GraspSession::waitWorkerIdle(std::chrono::milliseconds timeout) const {
  return worker_->waitIdle(timeout);
}

void GraspSession::holdWorker(bool held) {
  worker_->hold(held);
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
  c.ready = targets_.size() - c.pending - c.failed;
  return c;
}

std::optional<Pose> GraspSession::reposeCorrection(Hand side) const {
  const HandState& hand = hands_[size_t(side)];
  if (!hand.grasp.shown() || !hand.objectFromHandNow) return std::nullopt;
  const Pose& now = *hand.objectFromHandNow;
  const Pose& solved = hand.grasp.objectFromHand;
  if (glm::length(now.position - solved.position) <= settings_.moveTolerance &&
      angleBetween(now.orientation, solved.orientation) <= settings_.turnTolerance)
    return std::nullopt;
  return now.inverse() * solved;
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

Status GraspSession::submitDeferred(bool sharedQueueFree) {
  if (!deferredUsable()) return Status::ok;
  const Status s = deferred_->submit(sharedQueueFree);
  if (deferred_->failed()) stats_.gpuFailed = true;
  return s;
}

bool GraspSession::deferredReady() {
  if (deferred_ == nullptr) return false;
  const bool ready = !deferred_->failed() && deferred_->ready();
  if (deferred_->failed()) stats_.gpuFailed = true;  // its preparation failed
  return ready;
}

void GraspSession::dropDeferred() {
  for (size_t h = 0; h < 2; ++h) hands_[h].pending = false;
  deferred_.reset();
}

void GraspSession::cancelPending(HandState& hand, size_t slot) {
  if (hand.pending && deferred_ != nullptr) deferred_->cancel(slot);
  hand.pending = false;
  if (hand.jobPending) worker_->cancel(slot);
  hand.jobPending = false;
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

void GraspSession::giveUp(HandState& hand, size_t slot) {
  cancelPending(hand, slot);
  hand.grasp = HandGrasp{};
  hand.waitForRelease = true;
}

void GraspSession::release(Hand hand) {
  cancelPending(hands_[size_t(hand)], size_t(hand));
  hands_[size_t(hand)].grasp = HandGrasp{};
  hands_[size_t(hand)].waitForRelease = false;
}

Status GraspSession::setTargetHands(uint64_t id, bool left, bool right) {
  auto it = targets_.find(id);
  if (it == targets_.end()) return Status::invalid_argument;
  it->second.hands = {left, right};
  return Status::ok;
}

std::vector<GraspWorker::JobMember> GraspSession::sceneInBox(Hand side, const Pose& worldFromWrist,
                                                             uint64_t held) const {
  const GridBox& box = settings_.box;
  const Pose worldFromBox = worldFromWrist * box.handFromBox;
  std::vector<SceneHit> hits;
  index_.query(worldFromBox, box.size * 0.5f, hits);
  // The held target takes part wherever it is (the app may not carry it).
  if (held != 0 &&
      std::none_of(hits.begin(), hits.end(), [&](const SceneHit& h) { return h.target == held; })) {
    if (auto at = index_.worldFromObject(held)) hits.push_back(SceneHit{held, *at});
  }
  const Pose wristFromWorld = worldFromWrist.inverse();
  struct Candidate {
    GraspWorker::JobMember member;
    int rank = 0;  // held first, then device targets (a deferred build takes members[0])
    float distance = 0.0f;
  };
  std::vector<Candidate> found;
  for (const SceneHit& h : hits) {
    auto it = targets_.find(h.target);
    if (it == targets_.end() || it->second.setup != TargetSetup::ready ||
        it->second.role == TargetRole::ignored)
      continue;
    const Target& t = it->second;
    Candidate c;
    c.member.target = h.target;
    c.member.objectFromHand = h.worldFromObject.inverse() * worldFromWrist;
    c.member.graspable = t.role == TargetRole::graspable && t.hands[size_t(side)];
    c.rank = h.target == held ? 0 : (!onCpu(t) ? 1 : 2);
    const glm::vec3 centre =
        t.shapeTarget && !t.shape->bounded()
            ? glm::vec3(0.0f)
            : (wristFromWorld * h.worldFromObject).transformPoint(t.bounds.center());
    c.distance = glm::length(box.handFromBox.inverse().transformPoint(centre));
    found.push_back(c);
  }
  // Deterministic: held, device, then by target id (the index answers in id order); the nearest
  // kept when there are too many.
  std::stable_sort(found.begin(), found.end(),
                   [](const Candidate& a, const Candidate& b) { return a.rank < b.rank; });
  if (found.size() > kMaxSceneMembers) {
    std::stable_sort(found.begin() + 1, found.end(), [](const Candidate& a, const Candidate& b) {
      return a.distance < b.distance;
    });
    found.resize(kMaxSceneMembers);
  }
  std::vector<GraspWorker::JobMember> out;
  out.reserve(found.size());
  for (const Candidate& c : found) out.push_back(c.member);
  return out;
}

bool GraspSession::sceneChanged(const HandState& hand,
                                std::span<const GraspWorker::JobMember> now) const {
  if (now.size() != hand.members.size()) return true;
  for (size_t i = 0; i < now.size(); ++i) {
    const GraspWorker::JobMember& a = now[i];
    const GraspWorker::JobMember& b = hand.members[i];
    if (a.target != b.target || a.graspable != b.graspable) return true;
    auto it = targets_.find(a.target);
    if (it == targets_.end() || it->second.version != hand.memberVersions[i]) return true;
    if (glm::length(a.objectFromHand.position - b.objectFromHand.position) >
            settings_.moveTolerance ||
        angleBetween(a.objectFromHand.orientation, b.objectFromHand.orientation) >
            settings_.turnTolerance)
      return true;
  }
  return false;
}

Status GraspSession::prepareSolver(HandState& hand) {
  if (hand.prepared) return Status::ok;
  // The worker may be solving with the current one: a new one, prepared by the worker.
  auto made = createSolver(settings_.solver);
  if (!made) return made.error().code;
  auto setup = std::make_shared<GraspWorker::SolverSetup>();
  setup->solver = std::move(*made);
  setup->model = hand.model;
  setup->box = settings_.box;
  setup->options = settings_.solverOptions;
  hand.workerSolver = std::move(setup);
  hand.prepared = true;
  return Status::ok;
}

void GraspSession::post(HandState& hand, size_t slot, std::vector<GraspWorker::JobMember> members,
                        std::optional<SdfGrid> field, bool gpu, int64_t time) {
  GraspWorker::Job job;
  job.time = time;
  job.extraParts = hand.trackedParts;
  job.extraPartCount = hand.trackedPartCount;
  job.ticket = ++hand.ticket;
  job.members = std::move(members);
  job.held = hand.decided ? hand.grasp.target : 0;
  job.box = settings_.box;
  job.solver = hand.workerSolver;
  job.exactCheck = settings_.exactCheck;
  job.buildTimeLimit = settings_.buildTimeLimit;
  job.field = std::move(field);
  worker_->request(slot, std::move(job));
  hand.jobPending = true;
  hand.jobOnGpu = gpu;
}

Status GraspSession::collectJob(HandState& hand, size_t slot) {
  if (!hand.jobPending) return Status::ok;
  std::optional<GraspWorker::Done> done = worker_->take(slot);
  if (!done) return Status::ok;
  if (done->ticket != hand.ticket) return Status::ok;  // of a cancelled job
  hand.jobPending = false;
  if (done->built) ++stats_.cpuBuilds;
  if (done->reused) ++stats_.reusedFields;
  if (hand.jobOnGpu) ++stats_.gpuBuilds;
  if (!hand.grasp.holding) return Status::ok;
  if (done->status != Status::ok) {
    giveUp(hand, slot);
    return done->status;
  }
  // The first solve that takes a target decides; later ones keep it. A hand that holds nothing
  // (its fingers on scene geometry) takes a graspable target as soon as they touch one.
  if (!hand.decided) {
    hand.grasp.target = done->chosen;
    hand.decided = done->chosen != 0;
  }
  hand.grasp.result = done->result;
  hand.grasp.contacts = done->contacts;
  hand.grasp.touched = done->touched;
  hand.grasp.time = done->time;
  hand.grasp.objectFromHand = done->objectFromHand;
  hand.grasp.builtOnGpu = hand.jobOnGpu;
  hand.solvedVersion = done->version;
  ++hand.grasp.solves;
  return Status::ok;
}

Status GraspSession::solve(HandState& hand, size_t slot,
                           std::vector<GraspWorker::JobMember> members) {
  if (Status s = prepareSolver(hand); s != Status::ok) return s;
  hand.memberVersions.clear();
  for (const GraspWorker::JobMember& m : members)
    hand.memberVersions.push_back(targets_.at(m.target).version);
  hand.members = members;
  const uint64_t id = members[0].target;
  const Target& first = targets_.at(id);
  const bool device = !onCpu(first);
  // The deferred (GPU) backend builds one mesh: a device target (first in the scene when there is
  // one; the worker merges the rest on the CPU), or a mesh target alone when meshes go there too
  // (a device target's readback among them: built from that copy, so that its field and its
  // exact distance are of the same vertices).
  const bool onDevice =
      deferredUsable() && (device || (first.deviceCopy.positions != nullptr &&
                                      deferredForMeshTargets_ && members.size() == 1));
  if (onDevice && !deferredReady()) {
    // Still preparing (pipelines made at session start): a device target waits for it, asked
    // again at the next update; a target with a CPU mesh is built on the CPU below rather than
    // keep the hand waiting. A preparation that failed leaves the CPU only.
    if (device && deferredUsable()) return Status::ok;
  } else if (onDevice) {
    // The arrays are shared with the backend, not copied: this runs under the owner's lock.
    const Status s = first.deviceCopy.positions != nullptr
                         ? deferred_->requestShared(slot, id, first.version, first.deviceCopy,
                                                    members[0].objectFromHand, settings_.box)
                         : deferred_->request(slot, id, first.version, nullptr,
                                              members[0].objectFromHand, settings_.box);
    if (s == Status::ok) {
      hand.pending = true;
      hand.pendingSince = std::chrono::steady_clock::now();
      hand.pendingPose = members[0].objectFromHand;
      hand.pendingVersion = first.version;
      hand.pendingTime = hand.frameTime;
      hand.pendingMembers = std::move(members);
      return Status::ok;
    }
    // Busy with a cancelled build still on the device: ask again at the next update.
    if (s == Status::unsupported) return Status::ok;
    if (s == Status::invalid_argument) return s;
    stats_.gpuFailed = true;  // the device failed: this and every later build on the CPU
  }
  // On the CPU, device targets (no CPU mesh) cannot take part.
  std::erase_if(members,
                [&](const GraspWorker::JobMember& m) { return !onCpu(targets_.at(m.target)); });
  if (members.empty()) return Status::device_lost;
  post(hand, slot, std::move(members), std::nullopt, false, hand.frameTime);
  return Status::ok;
}

void GraspSession::noteTrackedParts(HandState& hand, const HandFrame& frame) {
  hand.trackedPartCount = 0;
  if (!frame.valid || frame.trackedJoints == nullptr || frame.trackedRadii == nullptr) return;
  const Pose wristFromWorld = frame.worldFromWrist.inverse();
  JointPoses local;
  for (int j = 0; j < kJointCount; ++j)
    local[size_t(j)] = wristFromWorld * (*frame.trackedJoints)[size_t(j)];
  hand.trackedPartCount = jointParts(local, *frame.trackedRadii, hand.trackedParts);
}

Status GraspSession::collect(HandState& hand, size_t slot) {
  if (!hand.pending) return Status::ok;
  if (deferred_ == nullptr) {
    hand.pending = false;
    return Status::ok;
  }
  const BuildPoll p = deferred_->poll(slot, hand.grid);
  if (p == BuildPoll::pending) return Status::ok;
  hand.pending = false;
  std::vector<GraspWorker::JobMember> members = std::move(hand.pendingMembers);
  hand.pendingMembers.clear();
  // Members gone meanwhile do not take part.
  std::erase_if(members,
                [&](const GraspWorker::JobMember& m) { return !targets_.count(m.target); });
  if (!hand.grasp.holding || members.empty() || members[0].target != hand.members[0].target)
    return Status::ok;
  if (p == BuildPoll::ready) {
    // The solve, with its exact check, is the worker's too; the build counts once its grasp is
    // taken (collectJob), so the count says the grasp shown has it.
    post(hand, slot, std::move(members), hand.grid, true, hand.pendingTime);
    return Status::ok;
  }
  // The device failed (or lost the request): the worker redoes the build on the CPU now.
  if (p == BuildPoll::failed) stats_.gpuFailed = true;
  std::erase_if(members,
                [&](const GraspWorker::JobMember& m) { return !onCpu(targets_.at(m.target)); });
  if (members.empty()) {
    hand.grasp = HandGrasp{};
    return Status::device_lost;
  }
  post(hand, slot, std::move(members), std::nullopt, false, hand.pendingTime);
  return Status::ok;
}

Status GraspSession::update(Hand side, const HandFrame& frame,
                            std::span<const TargetFrame> targets) {
  std::vector<SpaceFrame> spaces;
  spaces.reserve(targets.size());
  for (const TargetFrame& t : targets) {
    auto it = targets_.find(t.id);
    if (it == targets_.end()) continue;
    if (!it->second.placed || it->second.space != ownSpace(t.id))
      placeTarget(t.id, ownSpace(t.id), Pose{});
    spaces.push_back(SpaceFrame{ownSpace(t.id), t.valid, t.worldFromObject});
  }
  return update(side, frame, std::span<const SpaceFrame>(spaces));
}

Status GraspSession::update(Hand side, const HandFrame& tracked,
                            std::span<const SpaceFrame> spaces) {
  index_.setSpaces(spaces);
  const size_t slot = size_t(side);
  HandState& hand = hands_[slot];
  hand.squeeze = std::isfinite(tracked.squeeze) ? tracked.squeeze : 0.0f;
  hand.frameTime = tracked.time;
  if (tracked.valid) hand.lastWrist = tracked.worldFromWrist;
  refreshSetups();
  collectReadbacks();
  const Status jobStatus = collectJob(hand, slot);
  Status collected = jobStatus == Status::ok ? collect(hand, slot) : jobStatus;
  // A grasp that ends this frame ends before the outer hand looks: the object let go is scene
  // again at once, and one taken this frame is part of the hand at once.
  bool released = false;
  if (jobStatus == Status::ok && !hand.waitForRelease && hand.grasp.holding) {
    const uint64_t held = hand.grasp.target;
    bool keep = hand.squeeze >= settings_.grabThreshold * settings_.releaseRatio;
    if (held != 0) {
      auto it = targets_.find(held);
      keep = keep && it != targets_.end() && it->second.hands[slot] &&
             it->second.role == TargetRole::graspable;
    }
    if (!keep) {
      cancelPending(hand, slot);
      hand.grasp = HandGrasp{};
      released = true;
    }
  }
  // From here on the hand is where it is shown: kept out of the scene by the outer hand.
  JointPoses moved;
  const HandFrame frame = updateOuter(side, hand, tracked, moved);
  // A failed job left the hand open: it stays so for this frame (the caller logs why).
  if (jobStatus != Status::ok || released) return collected;
  if (hand.waitForRelease) {
    if (hand.squeeze >= settings_.grabThreshold * settings_.releaseRatio) return collected;
    hand.waitForRelease = false;
  }
  if (hand.pending &&
      std::chrono::steady_clock::now() - hand.pendingSince > settings_.buildTimeLimit) {
    giveUp(hand, slot);
    return Status::timed_out;
  }
  if (hand.grasp.holding) {
    const uint64_t held = hand.grasp.target;
    if (!frame.valid) return collected;  // keep the last solve
    std::vector<GraspWorker::JobMember> members = sceneInBox(side, frame.worldFromWrist, held);
    if (held != 0) {
      if (members.empty() || members[0].target != held) return collected;  // not located
      hand.objectFromHandNow = members[0].objectFromHand;
    }
    // The build in flight first, then re-check.
    if (members.empty() || hand.pending || hand.jobPending) return collected;
    if (hand.grasp.solves > 0 && !sceneChanged(hand, members)) return collected;
    noteTrackedParts(hand, frame);
    const Status s = solve(hand, slot, std::move(members));
    if (s != Status::ok) giveUp(hand, slot);
    return s;
  }

  if (!frame.valid || hand.squeeze < settings_.grabThreshold) return collected;
  std::vector<GraspWorker::JobMember> members = sceneInBox(side, frame.worldFromWrist, 0);
  if (members.empty()) return collected;
  // A tracked hand brings its own bone lengths: fit the model to it at the start of the grab.
  if (frame.trackedJoints != nullptr && frame.trackedRadii != nullptr) {
    auto fitted = HandModel::fitToJoints(side, *frame.trackedJoints, *frame.trackedRadii);
    if (fitted) {
      hand.model = std::move(*fitted);
      hand.prepared = false;
    }
  }
  hand.grasp = HandGrasp{};
  hand.grasp.holding = true;
  hand.decided = false;
  hand.objectFromHandNow.reset();
  noteTrackedParts(hand, frame);
  const Status s = solve(hand, slot, std::move(members));
  if (s != Status::ok) giveUp(hand, slot);
  return s;
}

}  // namespace sdfg
