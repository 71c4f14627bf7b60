// GraspSession's outer hand: per update, what the frame shows until the worker's result for it is
// in, and the frame's job for the worker (grasp/outer_view.h says how the two meet).
#include <algorithm>
#include <cmath>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "grasp/grasp_session.h"
#include "grasp/hand_clearance.h"
#include "grasp/shown_curls.h"
#include "hand/hand_synthesis.h"

namespace sdfg {
namespace {

// Targets whose bounds come within this of the palm (either the tracked or the last shown one)
// are kept out: a hand reaches about 0.2 m from its palm, and moves 2.2 cm in a frame at 2 m/s.
constexpr float kOuterReach = 0.15f;  // metres, half the box's edge

// A finger the fallback shows as given may be this much more closed than the last result's curl
// (the curl estimate's own noise on a tracked hand held still).
constexpr float kCurlSlack = 0.01f;
// A finger whose joints moved less than this in the hand since the last result (metres) is as it
// was then: no more closed.
constexpr float kFingerStill = 0.0005f;

}  // namespace

void GraspSession::outerMembers(const glm::vec3& centre, float half, uint64_t held,
                                std::vector<GraspWorker::JobMember>& out) const {
  std::vector<SceneHit> hits;
  index_.query(Pose{glm::quat(1, 0, 0, 0), centre}, glm::vec3(half), hits);
  for (const SceneHit& h : hits) {
    if (h.target == held) continue;
    if (std::any_of(out.begin(), out.end(),
                    [&](const GraspWorker::JobMember& m) { return m.target == h.target; }))
      continue;
    auto it = targets_.find(h.target);
    if (it == targets_.end() || it->second.setup != TargetSetup::ready ||
        it->second.role == TargetRole::ignored)
      continue;
    // A device target before its readback is set up has no CPU distance: not seen yet.
    if (!onCpu(it->second)) continue;
    GraspWorker::JobMember m;
    m.target = h.target;
    m.objectFromHand = h.worldFromObject.inverse();  // maps world points (OuterJob::members)
    out.push_back(m);
  }
}

bool GraspSession::mayTouchBounds(const Pose& worldFromWrist, const JointPoses& joints,
                                  const std::array<float, kJointCount>& radii, float margin,
                                  std::span<const GraspWorker::JobMember> members,
                                  const std::optional<Pose>& from, bool proving) const {
  HandParts parts;
  const int count = jointParts(joints, radii, parts);
  for (const GraspWorker::JobMember& m : members) {
    // A device target's bounds are the app's word: its vertices may have moved past them since
    // (the readback the worker keeps it out of is the truth). A depth scene's volume is a box
    // around the hand by construction: its bounds say nothing. Neither proves a hand clear; a
    // hand is withheld only on bounds that say where something is (a depth scene's hand that
    // appears is shown as given until the worker's answer, as before).
    auto t = targets_.find(m.target);
    if (t == targets_.end()) return true;
    if (t->second.volumeTarget || t->second.deviceTarget) {
      if (proving) return true;
      if (t->second.volumeTarget) continue;
    }
    bool plane = false;
    const std::optional<Aabb> box = index_.bounds(m.target, &plane);
    if (!box && !plane) return true;
    for (int i = 0; i < count; ++i) {
      const HandPart& part = parts[size_t(i)];
      // The part where it arrives, and where it starts from: the box around its motion. Where
      // it starts a result kept it `margin` clear of the surface (half of it here, for rounding):
      // a hand on a box's face that moves away from it is clear of its bounds.
      const float reach = part.coverRadius + margin;
      const glm::vec3 a =
          m.objectFromHand.transformPoint(worldFromWrist.transformPoint(part.centre));
      glm::vec3 lo = a - glm::vec3(reach), hi = a + glm::vec3(reach);
      if (from) {
        const float startReach = part.coverRadius + 0.5f * margin;
        const glm::vec3 b = m.objectFromHand.transformPoint(from->transformPoint(part.centre));
        lo = glm::min(lo, b - glm::vec3(startReach));
        hi = glm::max(hi, b + glm::vec3(startReach));
      }
      if (plane ? lo.y < 0.0f
                : glm::all(glm::lessThan(lo, box->max)) && glm::all(glm::greaterThan(hi, box->min)))
        return true;
    }
  }
  return false;
}

HandFrame GraspSession::updateOuter(Hand side, HandState& hand, const HandFrame& frame,
                                    JointPoses& moved) {
  const size_t slot = size_t(side);
  HandState::Outer& outer = hand.outer;
  auto stop = [&] {
    if (outer.engaged) {
      worker_->resetOuter(slot);
      outer.resetTicket = outer.ticket;
      outer.engaged = false;
    }
    outer.view.active = false;
    outer.view.fallback = OuterNow{};
    return frame;
  };
  if (!settings_.outerHand || !frame.valid) return stop();

  // The hand as it would be shown without the outer hand, wrist frame: tracked joints, or the
  // model closed by the squeeze; with a shown grasp's fingers on what they hold.
  JointPoses local;
  JointRadii radii;
  const bool tracked = frame.trackedJoints != nullptr && frame.trackedRadii != nullptr;
  if (tracked) {
    const Pose wristFromWorld = frame.worldFromWrist.inverse();
    for (int j = 0; j < kJointCount; ++j)
      local[size_t(j)] = wristFromWorld * (*frame.trackedJoints)[size_t(j)];
    radii = *frame.trackedRadii;
  } else {
    placeJoints(hand.model, curlsFromSqueeze(hand.squeeze, MotionRange::unobstructed), Pose{},
                local, radii);
  }
  JointPoses shown = local;
  if (hand.grasp.shown()) {
    const ShownCurls c = shownCurls(hand.grasp.result, hand.model.estimateCurls(local));
    replaceFingers(hand.model, c.curls, c.replace, Pose{}, shown);
  }

  // What is near: around the tracked palm and the last shown one.
  const uint64_t held = hand.grasp.holdsTarget() ? hand.grasp.target : 0;
  const glm::vec3 palm = local[size_t(Joint::palm)].position;
  std::vector<GraspWorker::JobMember> members;
  outerMembers(frame.worldFromWrist.transformPoint(palm), kOuterReach, held, members);
  const std::shared_ptr<const GraspWorker::OuterDone> latest =
      outer.engaged ? worker_->outerMailbox(slot)->latest.load() : nullptr;
  bool fresh =
      latest != nullptr && latest->ticket > outer.resetTicket && latest->status == Status::ok;
  // How far any part of the hand moved since that result (a joint's radius growth counted). A
  // jump (outer_hand.h, kJumpDistance) makes it a result of another place: the hand is shown
  // where it is now until the worker's answer for it.
  float sinceResult = 0.0f;
  if (fresh) {
    for (int j = 0; j < kJointCount; ++j) {
      const glm::vec3 now = frame.worldFromWrist.transformPoint(shown[size_t(j)].position);
      sinceResult =
          std::max(sinceResult, glm::length(now - latest->trackedJoints[size_t(j)]) +
                                    std::max(0.0f, radii[size_t(j)] - latest->radii[size_t(j)]));
    }
    if (sinceResult > kJumpDistance) fresh = false;
  }
  if (fresh)
    outerMembers(latest->result.worldFromShownWrist.transformPoint(palm), kOuterReach, held,
                 members);
  if (members.empty()) return stop();

  if (!outer.engaged) {
    // A tracked hand brings its own bones: the capped fingers take its shape.
    outer.view.model = hand.model;
    if (tracked) {
      if (auto fitted = HandModel::fitToJoints(side, *frame.trackedJoints, *frame.trackedRadii))
        outer.view.model = std::move(*fitted);
    }
  }

  // The fallback: the tracked hand when the last result was clear by more than any part moved
  // since, else the hand where the last result showed it.
  OuterView& view = outer.view;
  view.active = true;
  view.fallback = OuterNow{};
  // Whether the hand as given, where it is drawn, may touch a target's bounds now.
  auto mayTouch = [&](const std::optional<Pose>& from, bool proving) {
    JointPoses drawn;
    for (int j = 0; j < kJointCount; ++j) drawn[size_t(j)] = frame.graspOffset * shown[size_t(j)];
    return mayTouchBounds(frame.worldFromWrist, drawn, radii, settings_.outerOptions.margin,
                          members, from, proving);
  };
  if (!fresh) {
    // No result of this place (the hand's first frame near a target, tracking found again, a
    // jump): the hand as given where no target's bounds come near it, else none until the
    // worker's answer (a frame on an idle CPU), never a hand shown inside something.
    view.fallback.withhold = mayTouch(std::nullopt, false);
  } else {
    const OuterHandResult& r = latest->result;
    // How many of the worker's steps this frame is past that answer (a worker late by two frames
    // is two frames of the targets' motion behind).
    double steps = 1.0;
    if (latest->stepInterval > 0.0)
      steps = std::clamp((double(frame.time) * 1e-9 - latest->jobTime) / latest->stepInterval, 0.0,
                         double(GraspWorker::OuterDone::kPredictedSteps.back()));
    bool clear = !r.constrained;
    if (clear) {
      float motion = sinceResult;
      if (held != 0) {
        const Pose turn = latest->trackedWrist.inverse() * frame.worldFromWrist;
        motion = std::max(
            motion, glm::length(frame.worldFromWrist.position - latest->trackedWrist.position) +
                        rotationAngle(turn.orientation) * latest->attachedReach);
      }
      // The targets move too: as far as any moved since that answer (where they are now, against
      // where the job saw them), or as the worker's estimate of their motion says, the larger.
      float targetMotion = float(steps) * latest->sceneMotion;
      for (const GraspWorker::OuterDone::Placed& p : latest->placed) {
        const std::optional<Pose> now = index_.worldFromObject(p.id);
        if (!now) continue;
        const Pose delta = *now * p.worldFromObject.inverse();
        targetMotion = std::max(
            targetMotion, glm::length(now->position - p.worldFromObject.position) +
                              rotationAngle(delta.orientation) * (p.reach > 0.0f ? p.reach : 1.0f));
      }
      clear = motion + targetMotion + settings_.outerOptions.margin < r.clearance;
    }
    // A hand that left what the result held it on is the tracked hand as soon as it is clear
    // of every target's bounds (a hand lifted off a table, a box that moved away), not a frame
    // later: where it is, and all the way from where that result showed it (a hand pushed past
    // a thin plate stays on its side). Not with a held object: its parts are not in the test.
    if (!clear && held == 0) clear = !mayTouch(r.worldFromShownWrist, true);
    if (!clear) {
      // Where that result's hand must be to be out of the scene as it is now, with its moving
      // targets moved on as they moved (the same motion again, once per step since the answer):
      // the shortest prediction that reaches this frame (a hand pushed a little ahead of a
      // target is clear; one behind it is inside), or the longest.
      Pose push = latest->predicted.back();
      for (size_t h = 0; h < latest->predicted.size(); ++h) {
        if (double(GraspWorker::OuterDone::kPredictedSteps[h]) + 1e-6 >= steps) {
          push = latest->predicted[h];
          break;
        }
      }
      view.fallback.offset = frame.worldFromWrist.inverse() * (push * r.worldFromShownWrist);
      view.fallback.capped = r.capped;
      view.fallback.curl = r.curl;
      view.fallback.changes = true;
      // Fingers no further closed than that result left them: a finger the user closes more
      // while the answer is late could close into what the hand rests on (a grasp's fingers are
      // the solve's, and that result moved them as given).
      // Only a finger that moved in the hand since can have: the curl estimate is a search (tens
      // of microseconds for the hand) on the app's thread.
      if (!hand.grasp.shown()) {
        const Pose wristThen = latest->trackedWrist.inverse();
        for (int f = 0; f < kFingerCount; ++f) {
          if (view.fallback.capped[size_t(f)]) continue;
          float moved = 0.0f;
          for (const Joint j : fingerJoints(Finger(f)))
            moved = std::max(
                moved, glm::length(shown[size_t(j)].position -
                                   wristThen.transformPoint(latest->trackedJoints[size_t(j)])));
          if (moved > kFingerStill &&
              view.model.estimateCurl(Finger(f), shown) > r.curl[size_t(f)] + kCurlSlack)
            view.fallback.capped[size_t(f)] = true;
        }
      }
    }
  }

  GraspWorker::OuterJob job;
  job.ticket = ++outer.ticket;
  job.members = std::move(members);
  job.worldFromWrist = frame.worldFromWrist;
  job.joints = shown;
  job.radii = radii;
  job.time = double(frame.time) * 1e-9;
  job.model = view.model;
  // Every finger of a shown grasp is the solve's: clear of the whole scene from open to its
  // contact curl (the solver closed it along that path), so the outer hand moves them all with
  // the hand and re-curls none. (A finger it capped was capped against the grasp's offset of an
  // earlier frame, and drawn with today's: seen 2-10 mm inside what the hand held.)
  job.rigidFingers = hand.grasp.shown();
  job.drawnOffset = frame.graspOffset;
  job.options = settings_.outerOptions;
  const Pose worldFromShown = frame.worldFromWrist * view.fallback.offset;
  if (held != 0) {
    if (auto at = index_.worldFromObject(held)) {
      job.attached = held;
      // Held where the shown hand holds it (the app carries it with the hand it draws).
      job.wristFromAttached = worldFromShown.inverse() * *at;
    }
  }
  worker_->requestOuter(slot, std::move(job));
  outer.engaged = true;
  view.ticket = outer.ticket;
  view.mailbox = worker_->outerMailbox(slot);

  if (!view.fallback.changes) return frame;
  HandFrame out = frame;
  out.worldFromWrist = worldFromShown;
  if (tracked) {
    for (int j = 0; j < kJointCount; ++j) moved[size_t(j)] = worldFromShown * local[size_t(j)];
    out.trackedJoints = &moved;
  }
  return out;
}

}  // namespace sdfg
