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

Status GraspSession::addTarget(uint64_t id, TriangleMesh mesh) {
  if (targets_.count(id) != 0) return Status::invalid_argument;
  Target t;
  t.meshTarget = true;
  // The set-up (a second for a few hundred thousand triangles) is the worker's; the target is
  // graspable once it is ready (refreshSetups).
  if (deferredUsable() && deferredForMeshTargets_)
    t.deviceCopy = std::make_unique<TriangleMesh>(mesh);
  t.setup = TargetSetup::pending;
  t.vertexCount = mesh.positions.size();
  worker_->addTarget(id, std::move(mesh));
  targets_.emplace(id, std::move(t));
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

std::vector<std::pair<uint64_t, MeshOrientation>> GraspSession::takeSetupOrientations() {
  refreshSetups();
  return std::exchange(setupOrientations_, {});
}

bool GraspSession::waitWorkerIdle(std::chrono::milliseconds timeout) const {
  return worker_->waitIdle(timeout);
}

void GraspSession::refreshSetups() {
  for (auto& [id, t] : targets_) {
    if (t.setup != TargetSetup::pending) continue;
    GraspWorker::TargetInfo info = worker_->targetInfo(id);
    if (info.setup == TargetSetup::ready) {
      // Bounds set by updateTargetVertices meanwhile are newer than the set-up's.
      if (t.version == 0) t.bounds = info.bounds;
      t.setup = TargetSetup::ready;
      // The GPU's copy takes the triangles as the set-up turned them outward.
      if (t.deviceCopy != nullptr && info.orientedIndices != nullptr)
        t.deviceCopy->indices = *info.orientedIndices;
      setupOrientations_.emplace_back(id, info.orientation);
    } else if (info.setup == TargetSetup::failed) {
      t.setup = TargetSetup::failed;
      setupFailures_.emplace_back(id, std::move(info.error));
    }
  }
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
  targets_.emplace(id, std::move(t));
  return Status::ok;
}

Status GraspSession::updateTargetBounds(uint64_t id, const Aabb& bounds) {
  auto it = targets_.find(id);
  if (it == targets_.end() || it->second.meshTarget) return Status::invalid_argument;
  if (!validBounds(bounds)) return Status::invalid_argument;
  it->second.bounds = bounds;
  return Status::ok;
}

Status GraspSession::touchTarget(uint64_t id) {
  auto it = targets_.find(id);
  if (it == targets_.end()) return Status::invalid_argument;
  ++it->second.version;
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
  if (t.deviceCopy != nullptr) {
    std::copy(positions.begin(), positions.end(), t.deviceCopy->positions.begin());
  }
  t.bounds = computeBounds(positions);
  ++t.version;
  worker_->updateVertices(id, std::vector<glm::vec3>(positions.begin(), positions.end()),
                          t.version);
  return Status::ok;
}

Status GraspSession::updateTargetVertices(uint64_t id, std::vector<glm::vec3>&& positions,
                                          const Aabb& bounds) {
  auto it = targets_.find(id);
  if (it == targets_.end() || !it->second.meshTarget) return Status::invalid_argument;
  Target& t = it->second;
  if (positions.size() != t.vertexCount) return Status::invalid_argument;
  if (t.deviceCopy != nullptr)
    std::copy(positions.begin(), positions.end(), t.deviceCopy->positions.begin());
  t.bounds = bounds;
  ++t.version;
  worker_->updateVertices(id, std::move(positions), t.version);
  return Status::ok;
}

std::vector<glm::vec3> GraspSession::vertexBuffer(uint64_t id) {
  return worker_->spareBuffer(id);
}

bool GraspSession::removeTarget(uint64_t id) {
  for (size_t h = 0; h < 2; ++h) {
    if (hands_[h].grasp.holding && hands_[h].grasp.target == id) {
      cancelPending(hands_[h], h);
      hands_[h].grasp = HandGrasp{};
    }
  }
  worker_->removeTarget(id);
  return targets_.erase(id) != 0;
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

std::optional<uint64_t> GraspSession::pickTarget(Hand side, const Pose& worldFromWrist,
                                                 std::span<const TargetFrame> targets) const {
  const GridBox& box = settings_.box;
  const Pose boxFromWorld = (worldFromWrist * box.handFromBox).inverse();
  const glm::vec3 half = box.size * 0.5f;
  std::optional<uint64_t> best;
  float bestDistance = std::numeric_limits<float>::infinity();
  for (const TargetFrame& t : targets) {
    auto it = targets_.find(t.id);
    if (!t.valid || it == targets_.end() || it->second.setup != TargetSetup::ready ||
        !it->second.hands[size_t(side)])
      continue;
    const Pose boxFromObject = boxFromWorld * t.worldFromObject;
    // The target's bounds, as a box-space AABB of its 8 corners, must overlap the grab box.
    glm::vec3 lo(std::numeric_limits<float>::infinity()), hi(-lo);
    for (int c = 0; c < 8; ++c) {
      const glm::vec3 corner((c & 1) ? it->second.bounds.max.x : it->second.bounds.min.x,
                             (c & 2) ? it->second.bounds.max.y : it->second.bounds.min.y,
                             (c & 4) ? it->second.bounds.max.z : it->second.bounds.min.z);
      const glm::vec3 p = boxFromObject.transformPoint(corner);
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
    if (glm::any(glm::greaterThan(lo, half)) || glm::any(glm::lessThan(hi, -half))) continue;
    const float d = glm::length(boxFromObject.transformPoint(it->second.bounds.center()));
    if (d < bestDistance) bestDistance = d, best = t.id;
  }
  return best;
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

void GraspSession::post(HandState& hand, size_t slot, uint64_t id, const Pose& objectFromHand,
                        std::optional<SdfGrid> field, bool gpu, int64_t time) {
  GraspWorker::Job job;
  job.time = time;
  job.extraParts = hand.trackedParts;
  job.extraPartCount = hand.trackedPartCount;
  job.ticket = ++hand.ticket;
  job.target = id;
  job.objectFromHand = objectFromHand;
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
  hand.grasp.result = done->result;
  hand.grasp.contacts = done->contacts;
  hand.grasp.time = done->time;
  hand.grasp.objectFromHand = done->objectFromHand;
  hand.grasp.builtOnGpu = hand.jobOnGpu;
  hand.solvedVersion = done->version;
  ++hand.grasp.solves;
  return Status::ok;
}

Status GraspSession::solve(HandState& hand, size_t slot, uint64_t id, const Target& target,
                           const Pose& objectFromHand) {
  if (Status s = prepareSolver(hand); s != Status::ok) return s;
  const bool onDevice = deferredUsable() && (!target.meshTarget || deferredForMeshTargets_);
  if (onDevice && !deferredReady()) {
    // Still preparing (pipelines made at session start): a device target waits for it, asked
    // again at the next update; a target with a CPU mesh is built on the CPU below rather than
    // keep the hand waiting. A preparation that failed leaves the CPU only.
    if (!target.meshTarget && deferredUsable()) return Status::ok;
  } else if (onDevice) {
    const TriangleMesh* mesh = target.deviceCopy.get();
    const Status s =
        deferred_->request(slot, id, target.version, mesh, objectFromHand, settings_.box);
    if (s == Status::ok) {
      hand.pending = true;
      hand.pendingSince = std::chrono::steady_clock::now();
      hand.pendingPose = objectFromHand;
      hand.pendingVersion = target.version;
      hand.pendingTime = hand.frameTime;
      return Status::ok;
    }
    // Busy with a cancelled build still on the device: ask again at the next update.
    if (s == Status::unsupported) return Status::ok;
    if (s == Status::invalid_argument) return s;
    stats_.gpuFailed = true;  // the device failed: this and every later build on the CPU
  }
  if (!target.meshTarget) return Status::device_lost;
  post(hand, slot, id, objectFromHand, std::nullopt, false, hand.frameTime);
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
  auto it = hand.grasp.holding ? targets_.find(hand.grasp.target) : targets_.end();
  if (it == targets_.end()) return Status::ok;
  if (p == BuildPoll::ready) {
    // The solve, with its exact check, is the worker's too; the build counts once its grasp is
    // taken (collectJob), so the count says the grasp shown has it.
    post(hand, slot, it->first, hand.pendingPose, hand.grid, true, hand.pendingTime);
    return Status::ok;
  }
  // The device failed (or lost the request): the worker redoes the build on the CPU now.
  if (p == BuildPoll::failed) stats_.gpuFailed = true;
  if (!it->second.meshTarget) {
    hand.grasp = HandGrasp{};
    return Status::device_lost;
  }
  post(hand, slot, it->first, hand.pendingPose, std::nullopt, false, hand.pendingTime);
  return Status::ok;
}

Status GraspSession::update(Hand side, const HandFrame& frame,
                            std::span<const TargetFrame> targets) {
  const size_t slot = size_t(side);
  HandState& hand = hands_[slot];
  hand.squeeze = std::isfinite(frame.squeeze) ? frame.squeeze : 0.0f;
  hand.frameTime = frame.time;
  refreshSetups();
  Status collected = collectJob(hand, slot);
  // A failed job left the hand open: it stays so for this frame (the caller logs why).
  if (collected != Status::ok) return collected;
  collected = collect(hand, slot);
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
    auto it = targets_.find(hand.grasp.target);
    if (it == targets_.end() || !it->second.hands[slot] ||
        hand.squeeze < settings_.grabThreshold * settings_.releaseRatio) {
      cancelPending(hand, slot);
      hand.grasp = HandGrasp{};
      return collected;
    }
    const TargetFrame* located = nullptr;
    for (const TargetFrame& t : targets) {
      if (t.id == hand.grasp.target && t.valid) located = &t;
    }
    if (!frame.valid || located == nullptr) return collected;  // keep the last solve
    const Pose objectFromHand = located->worldFromObject.inverse() * frame.worldFromWrist;
    hand.objectFromHandNow = objectFromHand;
    // The build in flight first, then re-check.
    if (hand.pending || hand.jobPending) return collected;
    const bool moved =
        glm::length(objectFromHand.position - hand.grasp.objectFromHand.position) >
            settings_.moveTolerance ||
        angleBetween(objectFromHand.orientation, hand.grasp.objectFromHand.orientation) >
            settings_.turnTolerance;
    if (hand.grasp.solves > 0 && !moved && hand.solvedVersion == it->second.version)
      return collected;
    noteTrackedParts(hand, frame);
    const Status s = solve(hand, slot, it->first, it->second, objectFromHand);
    if (s != Status::ok) giveUp(hand, slot);
    return s;
  }

  if (!frame.valid || hand.squeeze < settings_.grabThreshold) return collected;
  const std::optional<uint64_t> id = pickTarget(side, frame.worldFromWrist, targets);
  if (!id) return collected;
  const Target& target = targets_.at(*id);
  const TargetFrame* located = nullptr;
  for (const TargetFrame& t : targets) {
    if (t.id == *id) located = &t;
  }
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
  hand.grasp.target = *id;
  noteTrackedParts(hand, frame);
  const Pose objectFromHand = located->worldFromObject.inverse() * frame.worldFromWrist;
  hand.objectFromHandNow = objectFromHand;
  const Status s = solve(hand, slot, *id, target, objectFromHand);
  if (s != Status::ok) giveUp(hand, slot);
  return s;
}

}  // namespace sdfg
