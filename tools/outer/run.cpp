#include "run.h"

#include <chrono>
#include <thread>

#include <glm/geometric.hpp>

#include "grasp/grasp_session.h"
#include "grasp/shown_hand.h"
#include "sdf/sdf_backend.h"

namespace sdfg::outer_bench {
namespace {

using Clock = std::chrono::steady_clock;
constexpr auto kFramePeriod = std::chrono::nanoseconds(11'111'111);  // 90 Hz

double ms(Clock::duration d) {
  return std::chrono::duration<double, std::milli>(d).count();
}

bool samePose(const Pose& a, const Pose& b) {
  return a.position == b.position && a.orientation == b.orientation;
}

bool past(const PassCheck& check, const JointPoses& joints) {
  const Pose checkFromWorld = check.worldFromCheck.inverse();
  for (const Pose& j : joints) {
    const glm::vec3 p = checkFromWorld.transformPoint(j.position);
    if (p.y < -check.farSide && std::abs(p.x) < check.half.x && std::abs(p.z) < check.half.y)
      return true;
  }
  return false;
}

}  // namespace

RunRecord runTrajectory(const Trajectory& trajectory, const TrackedHand& hand,
                        const RunOptions& options) {
  RunRecord out;
  GraspSession session(makeCpuSdfBackend(1));
  GraspSettings settings;
  settings.outerHand = options.outer;
  if (Status s = session.configure(settings); s != Status::ok) {
    out.error = "configure refused the settings";
    return out;
  }
  std::vector<TargetFrame> targets;
  for (const SceneObject& o : trajectory.objects) {
    const Status added =
        o.shape ? session.addShapeTarget(o.id, *o.shape) : session.addTarget(o.id, *o.mesh);
    if (added != Status::ok || session.setTargetRole(o.id, o.role) != Status::ok) {
      out.error = o.name + ": the session refused the target";
      return out;
    }
    targets.push_back(TargetFrame{o.id, true, o.worldFromObject});
  }
  // The mesh set-ups run on the worker; the trajectory starts once every target is ready.
  if (!session.waitWorkerIdle(std::chrono::seconds(30))) {
    out.error = "the targets' set-up did not finish in 30 s";
    return out;
  }
  for (const SceneObject& o : trajectory.objects) {
    if (session.targetSetup(o.id) != TargetSetup::ready) {
      out.error = o.name + ": set-up failed";
      return out;
    }
  }

  JointPoses tracked{}, shown{}, lastShown{};
  std::array<bool, kJointCount> changed{};
  int still = 0;
  Clock::time_point frameStart = Clock::now();
  for (size_t k = 0; k < trajectory.hand.size(); ++k) {
    const std::vector<SceneObject> objects = trajectory.objectsAt(k);
    for (size_t i = 0; i < targets.size(); ++i)
      targets[i].worldFromObject = objects[i].worldFromObject;
    hand.world(trajectory.hand[k], tracked);
    HandFrame frame;
    frame.valid = trajectory.validAt(k);
    frame.worldFromWrist = tracked[size_t(Joint::wrist)];
    frame.trackedJoints = &tracked;
    frame.trackedRadii = &hand.radii;
    // Scripted time: the outer hand's blend clock does not depend on the machine's speed.
    frame.time = int64_t(k) * kFramePeriod.count();

    const auto t0 = Clock::now();
    const Status updated =
        session.update(Hand::right, frame, std::span<const TargetFrame>(targets));
    const ShownHand view = takeShownHand(session, Hand::right, HandOffset{}, 0.0f);
    const auto t1 = Clock::now();
    if (updated != Status::ok) {
      out.error = "update failed at frame " + std::to_string(k);
      return out;
    }
    // The frame's record is in: on to the next frame's slot (paced).
    auto nextFrame = [&] {
      if (!options.waitWorker) {
        frameStart += kFramePeriod;
        std::this_thread::sleep_until(frameStart);
      }
    };
    if (!frame.valid) {
      // Tracking lost: the app draws no hand.
      FrameRecord r;
      r.valid = false;
      r.updateMs = ms(t1 - t0);
      out.frames.push_back(r);
      still = 0;
      nextFrame();
      continue;
    }
    if (options.waitWorker) {
      if (!session.waitWorkerIdle(std::chrono::seconds(10))) {
        out.error = "the worker was still busy 10 s after frame " + std::to_string(k);
        return out;
      }
    } else {
      std::this_thread::sleep_until(
          frameStart + std::chrono::duration_cast<Clock::duration>(
                           std::chrono::duration<double, std::milli>(options.drawAtMs)));
    }
    shown = tracked;
    const auto t2 = Clock::now();
    const bool drawn = drawTrackedHand(view, shown, changed);
    const auto t3 = Clock::now();
    if (!drawn) {
      FrameRecord r;
      r.withheld = true;
      const PartClearance trackedParts = smallestPartClearance(tracked, hand.radii, objects);
      r.trackedClearance = smallestClearance(tracked, hand.radii, objects);
      r.trackedPartClearance = trackedParts.radius;
      r.trackedKeepOut = trackedParts.cover;
      r.updateMs = ms(t1 - t0);
      r.drawMs = ms(t3 - t2);
      r.outerActive = true;
      out.frames.push_back(r);
      still = 0;
      nextFrame();
      continue;
    }

    FrameRecord r;
    r.updateMs = ms(t1 - t0);
    r.drawMs = ms(t3 - t2);
    r.outerActive = view.outer.active;
    r.onTime = view.outer.active && resolveOuter(view.outer).onTime;
    r.shownClearance = smallestClearance(shown, hand.radii, objects);
    r.trackedClearance = smallestClearance(tracked, hand.radii, objects);
    r.shownPartClearance = smallestPartClearance(shown, hand.radii, objects).radius;
    const PartClearance trackedParts = smallestPartClearance(tracked, hand.radii, objects);
    r.trackedPartClearance = trackedParts.radius;
    r.trackedKeepOut = trackedParts.cover;
    r.identical = true;
    for (int j = 0; j < kJointCount; ++j) {
      const Pose& a = shown[size_t(j)];
      const Pose& b = tracked[size_t(j)];
      r.offTracking = std::max(r.offTracking, glm::length(a.position - b.position));
      r.identical = r.identical && samePose(a, b);
    }
    // Still: the hand and everything near it (a hand pushed by a moving target is meant to move).
    r.trackedStill = k > 0 && out.frames.back().valid && !out.frames.back().withheld &&
                     samePose(trajectory.hand[k], trajectory.hand[k - 1]);
    if (r.trackedStill && k < trajectory.objectPoses.size()) {
      const std::vector<Pose>& now = trajectory.objectPoses[k];
      const std::vector<Pose>& before = trajectory.objectPoses[k - 1];
      for (size_t i = 0; i < now.size() && r.trackedStill; ++i)
        r.trackedStill = samePose(now[i], before[i]);
    }
    still = r.trackedStill ? still + 1 : 0;
    r.stillFrames = still;
    if (k > 0 && out.frames.back().valid && !out.frames.back().withheld)
      for (int j = 0; j < kJointCount; ++j)
        r.shownMotion = std::max(
            r.shownMotion, glm::length(shown[size_t(j)].position - lastShown[size_t(j)].position));
    if (trajectory.pass) {
      const PassCheck check = trajectory.passAt(k);
      r.shownPast = past(check, shown);
      r.trackedPast = past(check, tracked);
    }
    lastShown = shown;
    out.frames.push_back(r);
    nextFrame();
  }
  out.ok = true;
  return out;
}

}  // namespace sdfg::outer_bench
