// GraspWorker's outer-hand jobs: each hand kept outside the targets near it, one job per frame,
// the newest replacing one not yet started.
#include "grasp/grasp_worker.h"

#include "grasp/scene_exact_source.h"
#include "grasp/target_choice.h"
#include "scene/scene_field.h"

#include <algorithm>
#include <limits>
#include <new>
#include <utility>

namespace sdfg {

void GraspWorker::requestOuter(size_t slot, OuterJob job) {
  {
    std::lock_guard lock(mutex_);
    outer_[slot].queued = std::move(job);
  }
  wake_.notify_all();
}

void GraspWorker::resetOuter(size_t slot) {
  std::lock_guard lock(mutex_);
  outer_[slot].queued.reset();
  outer_[slot].reset = true;
}

void GraspWorker::runOuter(std::unique_lock<std::mutex>& lock, size_t slot, OuterJob job) {
  OuterSlot& o = outer_[slot];
  const bool reset = o.reset;
  o.reset = false;
  // The members as the exact source sees them (meshes, shapes, volumes; device targets have no CPU
  // mesh and are not kept out), looked up under the lock and read outside it: only this thread
  // touches a target's distance structure.
  // A mesh the app deformed since is refit first, as a grasp job would: the hand is kept out of
  // the shape the app last wrote, not the one a grab last built.
  std::vector<std::shared_ptr<Target>> keep;
  std::vector<SceneMember> scene;
  std::vector<uint64_t> versions;  // scene[k]'s vertex version
  std::vector<float> reaches;      // scene[k]'s farthest point from its origin (object frame)
  std::vector<Resolved> refits;
  for (const JobMember& m : job.members) {
    if (m.target == job.attached) continue;
    auto it = targets_.find(m.target);
    if (it == targets_.end() || it->second->setup != TargetSetup::ready) continue;
    const Target& t = *it->second;
    if (t.distance == nullptr && !t.shape && t.volume == nullptr) continue;
    keep.push_back(it->second);
    scene.push_back(sceneMember(m, t));
    if (t.positions && t.distance != nullptr) refits.push_back(resolve(m.target, it->second));
    versions.push_back(t.positions ? t.positionsVersion : t.appliedVersion);
    reaches.push_back(t.shape && !t.shape->bounded()
                          ? 0.0f
                          : std::max(glm::length(t.bounds.min), glm::length(t.bounds.max)));
    if (scene.size() == kMaxSceneMembers) break;
  }
  std::shared_ptr<Target> attached;
  uint64_t attachedVersion = 0;
  if (job.attached != 0) {
    auto it = targets_.find(job.attached);
    if (it != targets_.end() && it->second->setup == TargetSetup::ready) {
      attached = it->second;
      attachedVersion = attached->appliedVersion;
    }
  }
  const uint64_t setupsBefore = setupsDone_;
  lock.unlock();
  fillSpares(lock, refits);
  std::vector<std::pair<uint64_t, std::string>> refused;
  auto done = std::make_shared<OuterDone>();
  done->ticket = job.ticket;
  done->setupsBefore = setupsBefore;
  done->trackedWrist = job.worldFromWrist;
  for (int j = 0; j < kJointCount; ++j) {
    done->trackedJoints[size_t(j)] =
        job.worldFromWrist.transformPoint(job.joints[size_t(j)].position);
    done->radii[size_t(j)] = job.radii[size_t(j)];
  }
  try {
    if (refit(refits, refused) != Status::ok) {
      // A target being dropped: the job goes on without it.
      for (size_t k = 0; k < scene.size(); ++k) {
        if (!keep[k]->stop.load(std::memory_order_relaxed)) continue;
        scene.erase(scene.begin() + std::ptrdiff_t(k));
        versions.erase(versions.begin() + std::ptrdiff_t(k));
        reaches.erase(reaches.begin() + std::ptrdiff_t(k));
        keep.erase(keep.begin() + std::ptrdiff_t(k));
        --k;
      }
    }
    if (reset && o.hand != nullptr) o.hand->reset();
    if (o.hand == nullptr)
      o.hand = std::make_unique<OuterHand>(job.model, job.options);
    else
      o.hand->setModel(job.model);
    o.hand->setOptions(job.options);
    // The held object's surface, sampled once per target and shape.
    std::vector<HandPart> parts;
    if (attached != nullptr) {
      if (o.sampledTarget != job.attached || o.sampledVersion != attachedVersion) {
        o.samples = attached->shape                 ? surfaceParts(*attached->shape)
                    : attached->distance != nullptr ? surfaceParts(attached->distance->mesh())
                                                    : std::vector<HandPart>{};
        o.sampledTarget = job.attached;
        o.sampledVersion = attachedVersion;
      }
      parts.reserve(o.samples.size());
      for (HandPart p : o.samples) {
        p.centre = job.wristFromAttached.transformPoint(p.centre);
        done->attachedReach = std::max(done->attachedReach, glm::length(p.centre));
        parts.push_back(p);
      }
    }
    OuterHandInput in;
    in.worldFromWrist = job.worldFromWrist;
    in.joints = &job.joints;
    in.radii = &job.radii;
    in.time = job.time;
    in.attached = parts;
    in.rigidFingers = job.rigidFingers;
    in.drawnOffset = job.drawnOffset;
    // A target that moved, or that the app deformed, since the last job may now be in the hand
    // shown then. (One that only came within reach did not: the hand's own motion brought it.)
    // Each one that moved makes a step (W_now W_prev^-1; objectFromHand maps world points, so
    // a = W^-1) that the predictions repeat.
    std::vector<OuterSlot::Seen> now;
    std::vector<Pose> steps(scene.size());  // identity: still
    bool moving = false;
    in.sceneMoved = false;
    for (size_t k = 0; k < scene.size(); ++k) {
      now.push_back({scene[k].id, scene[k].objectFromHand, versions[k]});
      for (const OuterSlot::Seen& was : o.lastScene) {
        if (was.id != scene[k].id) continue;
        const Pose worldNow = scene[k].objectFromHand.inverse();
        steps[k] = worldNow * was.objectFromHand;
        const float turn = rotationAngle(steps[k].orientation);
        const float travel =
            glm::length(steps[k].transformPoint(worldNow.position) - worldNow.position);
        const bool moved = travel != 0.0f || turn != 0.0f;
        in.sceneMoved = in.sceneMoved || was.version != versions[k] ||
                        was.objectFromHand.position != scene[k].objectFromHand.position ||
                        was.objectFromHand.orientation != scene[k].objectFromHand.orientation;
        moving = moving || moved;
        // An unbounded shape (a plane) turning sweeps without bound: counted by its travel.
        if (moved) done->sceneMotion = std::max(done->sceneMotion, travel + turn * reaches[k]);
        break;
      }
    }
    done->jobTime = job.time;
    for (size_t k = 0; k < scene.size(); ++k)
      done->placed.push_back({scene[k].id, scene[k].objectFromHand.inverse(), reaches[k]});
    if (moving && job.time > o.lastJobTime) done->stepInterval = job.time - o.lastJobTime;
    o.lastScene = std::move(now);
    o.lastJobTime = job.time;
    const SceneExactSource source(scene);
    auto r = o.hand->update(in, scene.empty() ? nullptr : &source);
    if (r) {
      done->result = *r;
      // The scene kPredictedSteps[h] steps on, each member moved by its step that many times, and
      // the shown hand pushed out of it.
      for (size_t h = 0; h < OuterDone::kPredictedSteps.size() && done->stepInterval > 0.0; ++h) {
        std::vector<SceneMember> ahead = scene;
        for (size_t k = 0; k < scene.size(); ++k) {
          Pose w = scene[k].objectFromHand.inverse();
          for (int i = 0; i < OuterDone::kPredictedSteps[h]; ++i) w = steps[k] * w;
          ahead[k].objectFromHand = w.inverse();
        }
        if (auto c = o.hand->pushOutOf(SceneExactSource(ahead))) done->predicted[h] = *c;
      }
    } else {
      done->status = r.error().code;
    }
  } catch (const std::bad_alloc&) {
    done->status = Status::out_of_memory;
  } catch (...) {
    done->status = Status::internal;
  }
  o.mailbox->latest.store(std::move(done));
  lock.lock();
  commitRefits(refits, refused);
  lock.unlock();
  keep.clear();  // a target's last reference may go here, outside the lock as before
  refits.clear();
  attached.reset();
  lock.lock();
}

}  // namespace sdfg
