#include "grasp/grasp_worker.h"

#include "grasp/scene_exact_source.h"
#include "grasp/target_choice.h"
#include "scene/scene_field.h"

#include <algorithm>
#include <limits>
#include <new>
#include <utility>

#ifdef __linux__
#include <pthread.h>
#include <sched.h>
#endif

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

GraspWorker::GraspWorker(std::unique_ptr<SdfBackend> backend) : backend_(std::move(backend)) {
  thread_ = std::thread([this] { run(); });
}

GraspWorker::~GraspWorker() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
    for (auto& flag : stopBuild_) flag.store(true, std::memory_order_relaxed);
    for (auto& [id, target] : targets_) target->stop.store(true, std::memory_order_relaxed);
  }
  wake_.notify_all();
  thread_.join();
}

void GraspWorker::addTarget(uint64_t id, TriangleMesh mesh) {
  auto t = std::make_shared<Target>();
  t->setupMesh = std::move(mesh);
  {
    std::lock_guard lock(mutex_);
    std::shared_ptr<Target>& slot = targets_[id];
    if (slot != nullptr) slot->stop.store(true, std::memory_order_relaxed);  // replaced
    slot = std::move(t);
    setups_.push_back(id);
  }
  wake_.notify_all();
}

void GraspWorker::addShape(uint64_t id, const AnalyticShape& shape) {
  auto t = std::make_shared<Target>();
  t->shape = shape;
  t->bounds = shape.bounds();
  t->setup = TargetSetup::ready;
  std::shared_ptr<Target> replaced;
  {
    std::lock_guard lock(mutex_);
    auto it = targets_.find(id);
    if (it != targets_.end()) {
      replaced = std::move(it->second);
      replaced->stop.store(true, std::memory_order_relaxed);
    }
    targets_[id] = std::move(t);
  }
}

void GraspWorker::updateVertices(uint64_t id, std::vector<glm::vec3> positions, uint64_t version) {
  std::lock_guard lock(mutex_);
  auto it = targets_.find(id);
  if (it == targets_.end()) return;
  Target& t = *it->second;
  // Positions nobody built with yet are replaced; their buffer is kept for the next update.
  if (t.positions) t.spares.push_back(std::move(*t.positions));
  t.positions = std::move(positions);
  t.positionsVersion = version;
}

std::vector<glm::vec3> GraspWorker::spareBuffer(uint64_t id) {
  std::lock_guard lock(mutex_);
  auto it = targets_.find(id);
  if (it == targets_.end() || it->second->spares.empty()) return {};
  std::vector<glm::vec3> out = std::move(it->second->spares.back());
  it->second->spares.pop_back();
  return out;
}

void GraspWorker::removeTarget(uint64_t id) {
  std::shared_ptr<Target> dropped;  // freed outside the lock: a big mesh takes a while
  {
    std::lock_guard lock(mutex_);
    auto it = targets_.find(id);
    if (it == targets_.end()) return;
    dropped = std::move(it->second);
    dropped->stop.store(true, std::memory_order_relaxed);
    targets_.erase(it);
    // A build for a scene it is in is of no use to anyone now.
    for (size_t slot = 0; slot < kSlots; ++slot) {
      const auto& running = slots_[slot].runningTargets;
      if (slots_[slot].running && std::find(running.begin(), running.end(), id) != running.end())
        stopBuild_[slot].store(true, std::memory_order_relaxed);
    }
  }
}

std::vector<std::pair<uint64_t, std::string>> GraspWorker::takeRefusedUpdates() {
  std::lock_guard lock(mutex_);
  return std::exchange(refusedUpdates_, {});
}

GraspWorker::TargetInfo GraspWorker::targetInfo(uint64_t id) const {
  std::lock_guard lock(mutex_);
  auto it = targets_.find(id);
  if (it == targets_.end()) return {};
  return {it->second->setup, it->second->bounds, it->second->error, it->second->found,
          it->second->orientedIndices};
}

void GraspWorker::request(size_t slot, Job job) {
  {
    std::lock_guard lock(mutex_);
    slots_[slot].queued = std::move(job);
  }
  wake_.notify_all();
}

void GraspWorker::cancel(size_t slot) {
  std::lock_guard lock(mutex_);
  Slot& s = slots_[slot];
  s.queued.reset();
  s.done.reset();
  if (s.running) {
    s.cancelledBelow = s.runningTicket + 1;
    stopBuild_[slot].store(true, std::memory_order_relaxed);
  }
}

std::optional<GraspWorker::Done> GraspWorker::take(size_t slot) {
  // Polled every frame from the app's thread: never wait for the worker (which may have been
  // preempted while holding the lock); the result is taken at the next poll instead.
  std::unique_lock lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock()) return std::nullopt;
  std::optional<Done> out = std::move(slots_[slot].done);
  slots_[slot].done.reset();
  return out;
}

void GraspWorker::hold(bool held) {
  {
    std::lock_guard lock(mutex_);
    held_ = held;
  }
  wake_.notify_all();
}

bool GraspWorker::waitIdle(std::chrono::milliseconds timeout) const {
  std::unique_lock lock(mutex_);
  return idle_.wait_for(lock, timeout, [&] { return !busy_ && !anyQueued(); });
}

uint64_t GraspWorker::setupsDone() const {
  std::lock_guard lock(mutex_);
  return setupsDone_;
}

uint64_t GraspWorker::jobsDone() const {
  std::lock_guard lock(mutex_);
  return jobsDone_;
}

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

void GraspWorker::run() {
#ifdef __linux__
  // SCHED_BATCH: the kernel does not let this thread preempt the one that woke it, so handing a
  // job over never costs the app's thread the rest of its time slice (measured: a 0.7 ms stall
  // in xrSyncActions on a busy 2-core machine without it). Same nice value, same share of CPU.
  // Best effort: the default policy is kept where it is refused.
  sched_param param{};
  param.sched_priority = 0;
  (void)pthread_setschedparam(pthread_self(), SCHED_BATCH, &param);
#endif
  std::unique_lock lock(mutex_);
  for (;;) {
    wake_.wait(lock, [&] { return stop_ || (!held_ && anyQueued()); });
    if (stop_) break;
    busy_ = true;
    const bool otherWork = !setups_.empty() || slots_[0].queued || slots_[1].queued;
    if ((outer_[0].queued || outer_[1].queued) && !(lastRanOuter_ && otherWork)) {
      // The outer hand first: one frame's short solve, which the hand shows at once, before a
      // set-up or a build of a grab (milliseconds, up to seconds for a big mesh) that the hand
      // waits frames for anyway. Outer jobs come every frame: after one, a queued set-up or grab
      // runs before the next, so a worker slower than the frames starves neither. An outer job
      // waits at most for the job in progress and the other hand's outer job.
      size_t slot = nextOuter_;
      if (!outer_[slot].queued) slot = 1 - slot;
      nextOuter_ = 1 - slot;
      lastRanOuter_ = true;
      OuterJob job = std::move(*outer_[slot].queued);
      outer_[slot].queued.reset();
      runOuter(lock, slot, std::move(job));
    } else if (!setups_.empty()) {
      // Set-ups before grabs: a target must be ready before any hand can grab it.
      lastRanOuter_ = false;
      const uint64_t id = setups_.front();
      setups_.pop_front();
      auto it = targets_.find(id);
      if (it != targets_.end() && it->second->setupMesh) runSetup(lock, id, it->second);
    } else {
      // The slots take turns, so one hand's stream of re-solves cannot starve the other's grab.
      size_t slot = nextSlot_;
      if (!slots_[slot].queued) slot = 1 - slot;
      nextSlot_ = 1 - slot;
      lastRanOuter_ = false;
      Job job = std::move(*slots_[slot].queued);
      slots_[slot].queued.reset();
      runJob(lock, slot, std::move(job));
    }
    busy_ = false;
    if (!anyQueued()) idle_.notify_all();
  }
  busy_ = false;
  idle_.notify_all();
}

SceneMember GraspWorker::sceneMember(const JobMember& m, const Target& t) {
  SceneMember out;
  out.id = m.target;
  out.mesh = t.distance.get();
  out.shape = t.shape ? &*t.shape : nullptr;
  out.objectFromHand = m.objectFromHand;
  out.graspable = m.graspable;
  return out;
}

bool GraspWorker::anyQueued() const {
  return !setups_.empty() || slots_[0].queued || slots_[1].queued || outer_[0].queued ||
         outer_[1].queued;
}

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
  // The members as the exact source sees them (meshes and shapes; device targets have no CPU
  // mesh and are not kept out), looked up under the lock and read outside it: only this thread
  // touches a target's distance structure.
  std::vector<std::shared_ptr<Target>> keep;
  std::vector<SceneMember> scene;
  for (const JobMember& m : job.members) {
    if (m.target == job.attached) continue;
    auto it = targets_.find(m.target);
    if (it == targets_.end() || it->second->setup != TargetSetup::ready) continue;
    const Target& t = *it->second;
    if (t.distance == nullptr && !t.shape) continue;
    keep.push_back(it->second);
    scene.push_back(sceneMember(m, t));
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
    // A target that moved since the last job may now be in the hand shown then. (One that only
    // came within reach did not: the hand's own motion brought it.)
    std::vector<std::pair<uint64_t, Pose>> now;
    for (const SceneMember& m : scene) now.emplace_back(m.id, m.objectFromHand);
    in.sceneMoved = std::any_of(now.begin(), now.end(), [&](const auto& m) {
      return std::any_of(o.lastScene.begin(), o.lastScene.end(), [&](const auto& was) {
        return was.first == m.first && (was.second.position != m.second.position ||
                                        was.second.orientation != m.second.orientation);
      });
    });
    o.lastScene = std::move(now);
    const SceneExactSource source(scene);
    auto r = o.hand->update(in, scene.empty() ? nullptr : &source);
    if (r)
      done->result = *r;
    else
      done->status = r.error().code;
  } catch (const std::bad_alloc&) {
    done->status = Status::out_of_memory;
  } catch (...) {
    done->status = Status::internal;
  }
  keep.clear();
  attached.reset();
  o.mailbox->latest.store(std::move(done));
  lock.lock();
}

void GraspWorker::keepSpares(Target& target, std::vector<std::vector<glm::vec3>>& buffers) {
  for (auto& b : buffers)
    if (target.spares.size() < kMaxSpares) target.spares.push_back(std::move(b));
}

void GraspWorker::runSetup(std::unique_lock<std::mutex>& lock, uint64_t id,
                           std::shared_ptr<Target> target) {
  TriangleMesh mesh = std::move(*target->setupMesh);
  target->setupMesh.reset();
  lock.unlock();
  std::shared_ptr<MeshDistance> distance;
  std::string error;
  Aabb bounds;
  MeshSetupReport found;
  std::shared_ptr<const std::vector<uint32_t>> orientedIndices;
  // Every step looks at the target's stop flag (removed, replaced, or the worker destroyed).
  const WorkLimit limit{WorkLimit::Clock::time_point::max(), &target->stop};
  try {
    // The app's thread checked counts, coordinates and indices in its one copying pass; the
    // triangles' areas (a gather over the whole mesh, milliseconds for 400k triangles) are
    // checked here, before the winding vote reads them.
    if (auto refused = validateMesh(mesh.positions, mesh.indices, limit)) {
      error = refused->message;
    } else {
      bounds = computeBounds(mesh.positions);
      // Game meshes split their vertices at seams and hard edges: the winding repair below and
      // every sign need the topology of the surface, not of the indices. The app's positions stay
      // as they are (its vertex updates apply one for one); only this copy of the indices
      // changes.
      found.weld = weldByPosition(mesh.positions, mesh.indices, limit);
      // Meshes come wound either way, or both: the SDF's sign needs outward triangles. An open
      // part's winding-number vote costs O(samples x triangles), so it runs here, not in the
      // app's create call.
      if (!found.weld.stopped)
        found.orientation = orientOutward(mesh.positions, mesh.indices, limit);
      if (found.weld.stopped || found.orientation.stopped) {
        error = "the set-up was stopped";
      } else {
        if (found.orientation.flipped > 0 || found.weld.changed())
          orientedIndices = std::make_shared<const std::vector<uint32_t>>(mesh.indices);
        auto made = MeshDistance::create(mesh, limit);
        if (made)
          distance = std::move(*made);
        else
          error = made.error().message;
      }
    }
  } catch (const std::bad_alloc&) {
    error = "out of memory";
  } catch (...) {
    error = "internal error";
  }
  // Two buffers for the app's first vertex updates, filled here so that the first updates of a
  // deforming target neither allocate nor fault in fresh pages on the app's thread: the set-up's
  // own positions, already in memory, and one more.
  std::vector<std::vector<glm::vec3>> spares;
  if (distance != nullptr && !target->stop.load(std::memory_order_relaxed)) {
    try {
      spares.push_back(std::move(mesh.positions));
      spares.emplace_back(spares.front().size());
    } catch (const std::bad_alloc&) {
      // The app's thread allocates then, as without a pool.
    }
  }
  mesh = TriangleMesh{};  // freed before the lock
  lock.lock();
  ++setupsDone_;
  // Removed (or replaced by a new target of the same id) while it was set up: nothing to publish.
  auto it = targets_.find(id);
  if (it == targets_.end() || it->second != target) return;
  if (distance != nullptr) {
    target->distance = std::move(distance);
    target->bounds = bounds;
    target->found = found;
    target->orientedIndices = std::move(orientedIndices);
    keepSpares(*target, spares);
    target->setup = TargetSetup::ready;
  } else {
    target->setup = TargetSetup::failed;
    target->error = error.empty() ? "the mesh was refused" : error;
  }
}

void GraspWorker::runJob(std::unique_lock<std::mutex>& lock, size_t slot, Job job) {
  Slot& s = slots_[slot];
  s.running = true;
  s.runningTicket = job.ticket;
  s.runningTargets.clear();
  for (const JobMember& m : job.members) s.runningTargets.push_back(m.target);
  stopBuild_[slot].store(false, std::memory_order_relaxed);
  // Each member's target as it is now, with new positions to apply before the build.
  struct Resolved {
    std::shared_ptr<Target> target;  // null: removed, or not set up
    std::optional<std::vector<glm::vec3>> positions;
    uint64_t version = 0;
    size_t missingSpares = 0;
    std::optional<Aabb> refitBounds;
  };
  std::vector<Resolved> resolved(job.members.size());
  for (size_t i = 0; i < job.members.size(); ++i) {
    auto it = targets_.find(job.members[i].target);
    if (it == targets_.end() || it->second->setup != TargetSetup::ready) continue;
    Resolved& r = resolved[i];
    r.target = it->second;
    r.positions = std::move(r.target->positions);
    r.target->positions.reset();
    r.version = r.positions ? r.target->positionsVersion : r.target->appliedVersion;
    // A deforming target: fill its pool of buffers here, off the app's thread.
    if (r.positions && r.target->spares.size() < kMinSpares)
      r.missingSpares = kMinSpares - r.target->spares.size();
  }
  lock.unlock();
  for (Resolved& r : resolved) {
    if (r.missingSpares == 0) continue;
    std::vector<std::vector<glm::vec3>> newSpares;
    try {
      for (size_t i = 0; i < r.missingSpares; ++i) newSpares.emplace_back(r.positions->size());
    } catch (const std::bad_alloc&) {
      newSpares.clear();  // the app's thread allocates then, as without a pool
    }
    // Handed over now, not after the job: a refit and build of a large mesh outlast a frame or
    // two, and the app's next updates must find a buffer meanwhile (else one allocates and
    // faults in its pages on the app's thread: 5.7 ms once for 200k vertices).
    lock.lock();
    keepSpares(*r.target, newSpares);
    lock.unlock();
  }

  const auto start = std::chrono::steady_clock::now();
  Done done;
  done.ticket = job.ticket;
  done.time = job.time;
  done.versions.resize(job.members.size());
  for (size_t i = 0; i < resolved.size(); ++i) done.versions[i] = resolved[i].version;
  std::vector<std::pair<uint64_t, std::string>> refused;  // the first of each run of refusals
  try {
    if (job.members.empty()) done.status = Status::invalid_argument;
    // Deformed meshes: refit each hierarchy (O(n)). Positions that collapse a triangle are
    // refused by updatePositions, which leaves the last shape whole: the hand goes on with it.
    for (size_t i = 0; i < resolved.size() && done.status == Status::ok; ++i) {
      Resolved& r = resolved[i];
      if (r.target == nullptr || r.target->distance == nullptr || !r.positions) continue;
      const Status refit = r.target->distance->updatePositions(
          *r.positions, WorkLimit{WorkLimit::Clock::time_point::max(), &r.target->stop});
      if (refit == Status::ok) {
        r.refitBounds = computeBounds(*r.positions);
        r.target->lastUpdateRefused = false;
      } else if (refit == Status::timed_out) {
        // The target is being dropped (removed, or the worker destroyed): the half-refit object
        // goes with it; nothing is built on it.
        done.status = Status::timed_out;
      } else if (!r.target->lastUpdateRefused) {
        r.target->lastUpdateRefused = true;
        auto why = findDegenerateTriangle(*r.positions, r.target->distance->mesh().indices);
        refused.emplace_back(job.members[i].target,
                             why ? why->message : std::string("the positions were refused"));
      }
    }
    // The scene as the CPU sees it: every member with a mesh or a shape.
    std::vector<SceneMember> scene;
    std::vector<size_t> sceneIndex;  // scene[k] is job.members[sceneIndex[k]]
    for (size_t i = 0; i < resolved.size(); ++i) {
      const Resolved& r = resolved[i];
      if (r.target == nullptr || (r.target->distance == nullptr && !r.target->shape)) continue;
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
  for (auto& r : refused) refusedUpdates_.push_back(std::move(r));
  for (Resolved& r : resolved) {
    if (r.target == nullptr || !r.positions) continue;
    r.target->appliedVersion = r.version;
    if (r.refitBounds) r.target->bounds = *r.refitBounds;
    // The app's next updates fill these again.
    r.target->spares.push_back(std::move(*r.positions));
  }
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
