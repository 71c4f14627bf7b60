// GraspSession's solves handed on: the solver each hand's jobs use, the deferred (device) build
// or the worker's CPU build a solve goes to, and collecting what either finished.
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "grasp/grasp_session.h"

namespace sdfg {

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

}  // namespace sdfg
