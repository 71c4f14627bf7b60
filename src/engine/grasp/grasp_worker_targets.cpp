// GraspWorker's targets: a mesh's set-up (checks, weld, winding, BVH, exact distance), shapes,
// new vertices refitted before the next build, and removal.
#include "grasp/grasp_worker.h"

#include "grasp/scene_exact_source.h"
#include "grasp/target_choice.h"
#include "scene/scene_field.h"

#include <algorithm>
#include <limits>
#include <new>
#include <utility>

namespace sdfg {

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

GraspWorker::Resolved GraspWorker::resolve(uint64_t id, std::shared_ptr<Target> target) {
  Resolved r;
  r.id = id;
  r.target = std::move(target);
  r.positions = std::move(r.target->positions);
  r.target->positions.reset();
  r.version = r.positions ? r.target->positionsVersion : r.target->appliedVersion;
  // A deforming target: its pool of buffers is filled by the job, off the app's thread.
  if (r.positions && r.target->spares.size() < kMinSpares)
    r.missingSpares = kMinSpares - r.target->spares.size();
  return r;
}

void GraspWorker::fillSpares(std::unique_lock<std::mutex>& lock, std::span<Resolved> resolved) {
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
}

Status GraspWorker::refit(std::span<Resolved> resolved,
                          std::vector<std::pair<uint64_t, std::string>>& refused) {
  // Deformed meshes: refit each hierarchy (O(n)). Positions that collapse a triangle are
  // refused by updatePositions, which leaves the last shape whole: the hand goes on with it.
  for (Resolved& r : resolved) {
    if (r.target == nullptr || r.target->distance == nullptr || !r.positions) continue;
    const Status s = r.target->distance->updatePositions(
        *r.positions, WorkLimit{WorkLimit::Clock::time_point::max(), &r.target->stop});
    if (s == Status::ok) {
      r.refitBounds = computeBounds(*r.positions);
      r.target->lastUpdateRefused = false;
    } else if (s == Status::timed_out) {
      // The target is being dropped (removed, or the worker destroyed): the half-refit object
      // goes with it; nothing is built on it.
      return Status::timed_out;
    } else if (!r.target->lastUpdateRefused) {
      r.target->lastUpdateRefused = true;
      auto why = findDegenerateTriangle(*r.positions, r.target->distance->mesh().indices);
      refused.emplace_back(r.id, why ? why->message : std::string("the positions were refused"));
    }
  }
  return Status::ok;
}

void GraspWorker::commitRefits(std::span<Resolved> resolved,
                               std::vector<std::pair<uint64_t, std::string>>& refused) {
  for (auto& r : refused) refusedUpdates_.push_back(std::move(r));
  refused.clear();
  for (Resolved& r : resolved) {
    if (r.target == nullptr || !r.positions) continue;
    r.target->appliedVersion = r.version;
    if (r.refitBounds) r.target->bounds = *r.refitBounds;
    // The app's next updates fill these again.
    r.target->spares.push_back(std::move(*r.positions));
  }
}

}  // namespace sdfg
