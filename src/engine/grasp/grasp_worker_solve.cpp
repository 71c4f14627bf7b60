// GraspWorker's grasp jobs: the union field of a job's scene (built, reused rigidly, or merged
// with a device's field), the solve with its exact check, the target the fingers touch and the
// contacts reported on it.
#include "grasp/grasp_worker.h"

#include "grasp/scene_exact_source.h"
#include "grasp/target_choice.h"
#include "scene/scene_field.h"

#include <algorithm>
#include <limits>
#include <new>
#include <utility>

namespace sdfg {
namespace {

// The box a field is built in when the target already moved in the hand: the same box grown by
// kFieldMargin spacings on every side (same spacing, more nodes), so the next rigid motions of up
// to that margin still find every node of the job's own box inside it (reuseMap).
constexpr int kFieldMargin = 2;
// Members of a reused field's scene must have moved together within this (metres, and one
// minus the quaternions' dot product): a scene whose parts moved apart needs a new field.
constexpr float kRigidTolerance = 1e-5f;
// A finger's contact is on the member whose surface is within its largest joint radius plus
// this of the touching sphere's centre.
constexpr float kTouchReach = 0.002f;  // metres

GridBox grownBox(const GridBox& box) {
  GridBox grown = box;
  const glm::vec3 spacing = box.spacing();
  grown.resolution = box.resolution + glm::uvec3(2 * kFieldMargin);
  if (glm::any(glm::greaterThan(grown.resolution, glm::uvec3(kMaxGridResolution)))) return box;
  grown.size = box.size + spacing * float(2 * kFieldMargin);
  return grown;
}

}  // namespace

std::optional<Pose> GraspWorker::reuseMap(const BuiltField& built, const Job& job,
                                          std::span<const uint64_t> versions) {
  if (!built.valid || job.members.empty() || built.targets.size() != job.members.size() ||
      !std::equal(built.versions.begin(), built.versions.end(), versions.begin(), versions.end()))
    return std::nullopt;
  for (size_t i = 0; i < job.members.size(); ++i)
    if (built.targets[i] != job.members[i].target) return std::nullopt;
  if (!job.solver->reusesFields || built.jobBox.resolution != job.box.resolution ||
      built.jobBox.size != job.box.size ||
      built.jobBox.handFromBox.position != job.box.handFromBox.position ||
      built.jobBox.handFromBox.orientation != job.box.handFromBox.orientation)
    return std::nullopt;
  // field hand <- object <- job hand: the same surface, seen from where the field was built.
  const Pose fieldFromHand = built.objectFromHand[0].inverse() * job.members[0].objectFromHand;
  // Every other member must have moved with the first: the scene, not one object, moved rigidly.
  for (size_t i = 1; i < job.members.size(); ++i) {
    const Pose expected = built.objectFromHand[i] * fieldFromHand;
    const Pose& now = job.members[i].objectFromHand;
    if (glm::length(expected.position - now.position) > kRigidTolerance ||
        1.0f - std::abs(glm::dot(expected.orientation, now.orientation)) > kRigidTolerance)
      return std::nullopt;
  }
  // Every node of the job's own box must lie inside the built one, so everything a fresh field
  // would tell the solver, this one tells too (beyond the job's box it tells more: the solver
  // reads real values there instead of the border's). Its corners are the extreme points.
  const GridBox& box = built.grid.box();
  const Pose builtFromJobBox = box.handFromBox.inverse() * fieldFromHand * job.box.handFromBox;
  const glm::vec3 half = job.box.size * 0.5f;
  const glm::vec3 limit = box.size * 0.5f + glm::vec3(1e-6f);
  for (int c = 0; c < 8; ++c) {
    const glm::vec3 corner((c & 1) ? half.x : -half.x, (c & 2) ? half.y : -half.y,
                           (c & 4) ? half.z : -half.z);
    const glm::vec3 p = builtFromJobBox.transformPoint(corner);
    if (glm::any(glm::greaterThan(glm::abs(p), limit))) return std::nullopt;
  }
  return fieldFromHand;
}

SceneMember GraspWorker::sceneMember(const JobMember& m, const Target& t) {
  SceneMember out;
  out.id = m.target;
  out.mesh = t.distance.get();
  out.shape = t.shape ? &*t.shape : nullptr;
  out.volume = t.volume;
  out.objectFromHand = m.objectFromHand;
  out.graspable = m.graspable;
  return out;
}

void GraspWorker::runJob(std::unique_lock<std::mutex>& lock, size_t slot, Job job) {
  Slot& s = slots_[slot];
  s.running = true;
  s.runningTicket = job.ticket;
  s.runningTargets.clear();
  for (const JobMember& m : job.members) s.runningTargets.push_back(m.target);
  stopBuild_[slot].store(false, std::memory_order_relaxed);
  // Each member's target as it is now, with new positions to apply before the build.
  std::vector<Resolved> resolved(job.members.size());
  for (size_t i = 0; i < job.members.size(); ++i) {
    auto it = targets_.find(job.members[i].target);
    if (it == targets_.end() || it->second->setup != TargetSetup::ready) continue;
    resolved[i] = resolve(job.members[i].target, it->second);
  }
  lock.unlock();
  fillSpares(lock, resolved);

  const auto start = std::chrono::steady_clock::now();
  Done done;
  done.ticket = job.ticket;
  done.time = job.time;
  done.versions.resize(job.members.size());
  for (size_t i = 0; i < resolved.size(); ++i) done.versions[i] = resolved[i].version;
  std::vector<std::pair<uint64_t, std::string>> refused;  // the first of each run of refusals
  try {
    if (job.members.empty()) done.status = Status::invalid_argument;
    if (done.status == Status::ok) done.status = refit(resolved, refused);
    // The scene as the CPU sees it: every member with a mesh or a shape.
    std::vector<SceneMember> scene;
    std::vector<size_t> sceneIndex;  // scene[k] is job.members[sceneIndex[k]]
    for (size_t i = 0; i < resolved.size(); ++i) {
      const Resolved& r = resolved[i];
      if (r.target == nullptr ||
          (r.target->distance == nullptr && !r.target->shape && r.target->volume == nullptr))
        continue;
      scene.push_back(sceneMember(job.members[i], *r.target));
      sceneIndex.push_back(i);
      if (scene.size() == kMaxSceneMembers) break;
    }
    const SdfGrid* field = nullptr;
    BuiltField& built = fields_[slot];
    Pose fieldFromHand{};
    std::optional<SdfGrid> merged;
    const WorkLimit limit = WorkLimit::after(job.buildTimeLimit, &stopBuild_[slot]);
    if (done.status == Status::ok && job.field) {
      // members[0] built on the GPU; the others are merged into it here.
      merged = std::move(job.field);
      job.field.reset();
      std::vector<SceneMember> rest;
      for (size_t k = 0; k < scene.size(); ++k)
        if (sceneIndex[k] != 0) rest.push_back(scene[k]);
      if (!rest.empty()) {
        SdfGrid restField, scratch;
        done.status = buildSceneField(rest, merged->box(), *backend_, restField, scratch, limit);
        if (done.status == Status::ok) {
          std::span<float> dst = merged->values();
          std::span<const float> src = restField.values();
          for (size_t n = 0; n < dst.size(); ++n) dst[n] = std::min(dst[n], src[n]);
          done.built = true;
        }
      }
      field = &*merged;
    } else if (done.status == Status::ok) {
      if (scene.empty()) {
        done.status = Status::invalid_argument;  // removed, or not set up
      } else if (const auto map = reuseMap(built, job, done.versions)) {
        fieldFromHand = *map;
        field = &built.grid;
        done.reused = true;
      } else {
        // A re-solve of the same scene means it moves in the hand: build a grown box, which the
        // next motions reuse. A first grab builds the plain box (the fastest).
        bool moving = job.solver->reusesFields && built.valid &&
                      built.targets.size() == job.members.size() && built.versions == done.versions;
        for (size_t i = 0; moving && i < job.members.size(); ++i)
          moving = built.targets[i] == job.members[i].target;
        built.valid = false;
        built.jobBox = job.box;
        done.status = buildSceneField(scene, moving ? grownBox(job.box) : job.box, *backend_,
                                      built.grid, scratch_[slot], limit);
        done.built = done.status == Status::ok;
        if (done.built) {
          built.valid = true;
          built.targets.clear();
          built.objectFromHand.clear();
          for (const JobMember& m : job.members) {
            built.targets.push_back(m.target);
            built.objectFromHand.push_back(m.objectFromHand);
          }
          built.versions = done.versions;
        }
        field = &built.grid;
      }
    }
    if (done.status == Status::ok && job.solver == nullptr) done.status = Status::internal;
    if (done.status == Status::ok && !job.solver->prepared) {
      SolverSetup& setup = *job.solver;
      setup.prepareStatus = setup.solver->prepare(setup.model, setup.box, setup.options);
      setup.prepared = true;
      setup.reusesFields = setup.solver->name() == "ours" && !setup.options.approach;
    }
    if (done.status == Status::ok) done.status = job.solver->prepareStatus;
    if (done.status == Status::ok) {
      GraspScene graspScene;
      graspScene.field = field;
      graspScene.objectFromHand = job.members[0].objectFromHand;
      graspScene.fieldFromHand = fieldFromHand;
      graspScene.extraParts =
          std::span<const HandPart>(job.extraParts.data(), size_t(job.extraPartCount));
      const SceneExactSource exact(scene);
      if (job.exactCheck && !scene.empty()) graspScene.exact = &exact;
      done.status = job.solver->solver->solve(graspScene, done.result);
      if (done.status == Status::ok)
        chooseAndContact(job, scene, sceneIndex, exact, done.reused ? nullptr : field, done);
    }
  } catch (const std::bad_alloc&) {
    done.status = Status::out_of_memory;
  } catch (...) {
    done.status = Status::internal;
  }
  done.duration = std::chrono::duration_cast<std::chrono::microseconds>(
      std::chrono::steady_clock::now() - start);
  job = Job{};  // the solver reference and any field go before the lock

  lock.lock();
  ++jobsDone_;
  commitRefits(resolved, refused);
  s.running = false;
  s.runningTargets.clear();
  if (done.ticket >= s.cancelledBelow) s.done = std::move(done);
}

void GraspWorker::chooseAndContact(const Job& job, std::span<const SceneMember> scene,
                                   std::span<const size_t> sceneIndex,
                                   const SceneExactSource& exact, const SdfGrid* field,
                                   Done& done) {
  const HandModel& model = job.solver->model;
  // What each finger touches; the rule takes the graspable target most of them touch.
  JointPoses open;
  model.pose(FingerCurls{}, open);
  float reach = 0.0f;
  for (int j = 0; j < kJointCount; ++j) reach = std::max(reach, model.jointRadius(Joint(j)));
  const GraspChoice choice =
      scene.empty() ? GraspChoice{}
                    : chooseTarget(scene, exact, done.result, open[size_t(Joint::palm)].position,
                                   model.jointRadius(Joint::palm),
                                   palmFacing(open[size_t(Joint::palm)]), reach + kTouchReach);
  for (int f = 0; f < kFingerCount; ++f) {
    const int m = choice.touched[size_t(f)];
    done.touched[size_t(f)] = m >= 0 ? scene[size_t(m)].id : 0;
    // A device target alone in the box (no CPU mesh yet): what a finger stopped on is it.
    if (scene.empty() && job.members.size() == 1 && done.result.fingers[size_t(f)].contact)
      done.touched[size_t(f)] = job.members[0].target;
  }
  // A held target stays held; else the choice (none: the hand holds nothing).
  size_t chosenMember = job.members.size();
  if (job.held != 0) {
    for (size_t i = 0; i < job.members.size(); ++i)
      if (job.members[i].target == job.held) chosenMember = i;
  } else if (choice.member >= 0) {
    chosenMember = sceneIndex[size_t(choice.member)];
  } else if (scene.empty() && job.members[0].graspable) {
    // A device target alone (no CPU mesh to say what is touched): the grab takes it when a finger
    // stopped on it, as before scenes.
    for (const FingerState& fs : done.result.fingers)
      if (fs.contact) chosenMember = 0;
  }
  if (chosenMember >= job.members.size()) return;
  done.chosen = job.members[chosenMember].target;
  done.objectFromHand = job.members[chosenMember].objectFromHand;
  done.version = done.versions[chosenMember];
  // Contacts on the chosen target: its exact mesh where it has one, else the field (of the
  // whole scene: trusted only for fingers that touch the chosen target).
  const MeshDistance* mesh = nullptr;
  for (const SceneMember& m : scene)
    if (m.id == done.chosen) mesh = m.mesh;
  done.contacts = computeContacts(model, done.result, done.objectFromHand, mesh, field);
  for (int f = 0; f < kFingerCount; ++f) {
    if (!scene.empty() && done.touched[size_t(f)] != done.chosen)
      done.contacts[size_t(f)] = FingerContact{};
  }
}

}  // namespace sdfg
