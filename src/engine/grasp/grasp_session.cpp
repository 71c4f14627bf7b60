// GraspSession's grab state machine: the settings, each hand's update (open -> closed -> open),
// the scene in a hand's grab box and when it changed. The targets are grasp_session_targets.cpp,
// the work handed to the worker and the device grasp_session_jobs.cpp, the outer hand
// grasp_session_outer.cpp, device targets read back grasp_session_readback.cpp.
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "grasp/grasp_session.h"

namespace sdfg {
namespace {

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

bool GraspSession::waitWorkerIdle(std::chrono::milliseconds timeout) const {
  return worker_->waitIdle(timeout);
}

void GraspSession::holdWorker(bool held) {
  worker_->hold(held);
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
  if (depthOn_) index_.locate(kDepthWorldSpace, Pose{});
  const size_t slot = size_t(side);
  HandState& hand = hands_[slot];
  hand.squeeze = std::isfinite(tracked.squeeze) ? tracked.squeeze : 0.0f;
  hand.frameTime = tracked.time;
  if (tracked.valid) hand.lastWrist = tracked.worldFromWrist;
  refreshSetups();
  collectReadbacks();
  collectDepth();
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
    // The depth scene changes with every frame fused and stays where it was seen when the app
    // carries what the hand took: the first solve is kept (enableDepthScene).
    if (isDepthTarget(held) && hand.grasp.solves > 0) return collected;
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
