#include "eval/scene_quality.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <thread>
#include <vector>

#include <glm/geometric.hpp>

#include "eval/approaching.h"
#include "eval/evaluator.h"
#include "eval/percentile.h"
#include "eval/placements.h"
#include "eval/solver_physics.h"
#include "eval/strategies.h"
#include "grasp/contact.h"
#include "grasp/scene_exact_source.h"
#include "grasp/target_choice.h"
#include "mesh/mesh_distance.h"
#include "scene/scene_field.h"
#include "sdf/sdf_backend.h"

namespace sdfg {

namespace {

// How far past a touching sphere's radius its surface may be for target_choice.h: the worker's
// reach (grasp_worker.cpp, kTouchReach), restated because the engine keeps it private.
constexpr float kTouchReach = 0.002f;  // metres
constexpr float kFacingHit = 0.001f;   // metres: the ray has met a surface
constexpr int kFacingSteps = 200;

// An object as the graders and the solvers see it.
struct Prepared {
  TriangleMesh world;                      // the mesh in world space
  Aabb bounds;                             // of `world`
  std::unique_ptr<ExactMeshQuery> exact;   // grader (CGAL), world space
  std::unique_ptr<MeshDistance> distance;  // the engine's, object frame (meshes only)
};

// Index of the nearest object at `p` (world), and its unsigned distance.
std::pair<int, double> nearestObject(const std::vector<Prepared>& objects, const glm::vec3& p) {
  int best = -1;
  double bestDistance = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < objects.size(); ++i) {
    const double d = objects[i].exact->unsignedDistance(p);
    if (d < bestDistance) {
      bestDistance = d;
      best = int(i);
    }
  }
  return {best, bestDistance};
}

// The object the palm faces: sphere tracing from the palm joint along the palm's normal (the
// hand's -Y, the palm side), on the grader's exact distances, as far as the engine's rule looks
// (target_choice.h, kFacingRange). -1: nothing within it.
int facedObject(const std::vector<Prepared>& objects, const Pose& worldFromPalm) {
  const glm::vec3 direction = palmFacing(worldFromPalm);
  float t = 0.0f;
  for (int step = 0; step < kFacingSteps && t < kFacingRange; ++step) {
    const auto [object, distance] = nearestObject(objects, worldFromPalm.position + direction * t);
    if (object < 0) return -1;
    if (distance < kFacingHit) return object;
    t += float(distance);
  }
  return -1;
}

// The physics rule: the graspable object most fingers in contact are nearest to; ties to the one
// nearest the palm, then the lowest index. -1 when no finger touches a graspable object.
int physicsTaken(const std::vector<Prepared>& objects, const BenchScene& scene,
                 const Pose& worldFromHand, const GraspResult& result, const glm::vec3& palm) {
  std::vector<int> fingers(objects.size(), 0);
  const Pose worldFromShown = worldFromHand * result.handCorrection;
  for (const FingerState& f : result.fingers) {
    if (!f.contact) continue;
    const int o = nearestObject(objects, worldFromShown.transformPoint(f.contactPoint)).first;
    if (o >= 0) fingers[size_t(o)]++;
  }
  int best = -1;
  double bestPalm = 0.0;
  for (size_t i = 0; i < objects.size(); ++i) {
    if (!scene.objects[i].graspable || fingers[i] == 0) continue;
    const double palmDistance = objects[i].exact->unsignedDistance(palm);
    if (best < 0 || fingers[i] > fingers[size_t(best)] ||
        (fingers[i] == fingers[size_t(best)] && palmDistance < bestPalm)) {
      best = int(i);
      bestPalm = palmDistance;
    }
  }
  return best;
}

// The single-target rule before scenes: the graspable object whose bounds are nearest the palm.
int nearestBoundsTarget(const std::vector<Prepared>& objects, const BenchScene& scene,
                        const glm::vec3& palm) {
  int best = -1;
  float bestDistance = std::numeric_limits<float>::infinity();
  for (size_t i = 0; i < objects.size(); ++i) {
    if (!scene.objects[i].graspable) continue;
    const glm::vec3 outside = glm::max(objects[i].bounds.min - palm, palm - objects[i].bounds.max);
    const float d = glm::length(glm::max(outside, glm::vec3(0.0f)));
    if (d < bestDistance) {
      bestDistance = d;
      best = int(i);
    }
  }
  return best;
}

struct Graded {
  std::optional<Error> error;
  int taken = -1;
  int faced = -1;
  float otherPenetrationMm = 0.0f;
  int deepestObject = -1;
  GraspMetrics metrics;  // on the graded object, with the fingers judged on every object
  std::array<int, kFingerCount> fingerOn{-1, -1, -1, -1, -1};  // nearest object to each contact
  float wholeMm = 0.0f;  // approaching, open hand inside: the whole hand into any object
  bool exceeded = false;
  int v1Contacts = 0;
  float v1ResidualMm = 0.0f;
};

// The single-object metrics of the graded object, with what a finger does judged on every
// object: its contact residual and touching on the nearest one (a finger resting on the table is
// in contact, not 30 mm off the torus), a pass-through through any, and an early stop only where
// nothing else is within the early-stop gap either (a finger stopped on the table is not early).
GraspMetrics combine(const std::vector<GraspMetrics>& perObject, size_t gradedObject) {
  GraspMetrics out = perObject[gradedObject];
  out.contacts = out.earlyStops = out.passThroughs = 0;
  for (int f = 0; f < kFingerCount; ++f) {
    FingerMetrics& m = out.fingers[size_t(f)];
    float clearance = std::numeric_limits<float>::infinity();
    bool passThrough = false;
    for (const GraspMetrics& o : perObject) {
      clearance = std::min(clearance, o.fingers[size_t(f)].clearanceMm);
      passThrough = passThrough || o.fingers[size_t(f)].passThrough;
    }
    m.clearanceMm = clearance;
    m.contactResidualMm = std::abs(clearance);
    m.touching = clearance <= kTouchingMm;
    m.passThrough = passThrough;
    m.earlyStop = m.earlyStop && clearance > kEarlyStopGapMm;
    out.contacts += m.touching ? 1 : 0;
    out.earlyStops += m.earlyStop ? 1 : 0;
    out.passThroughs += m.passThrough ? 1 : 0;
  }
  return out;
}

}  // namespace

Result<SceneFigures> measureScene(const BenchScene& scene, const SceneRun& run) {
  if (run.placements <= 0 || run.threads == 0) {
    return makeError(Status::invalid_argument, "scene: placements and threads must be positive");
  }
  if (scene.objects.empty() || scene.reachedFor >= scene.objects.size() ||
      !scene.objects[scene.reachedFor].graspable) {
    return makeError(Status::invalid_argument,
                     "scene " + scene.name + ": the object reached for must be graspable");
  }
  const HandModel hand = HandModel::defaultAdult(Hand::right);
  std::vector<Prepared> objects(scene.objects.size());
  std::vector<TriangleMesh> worldMeshes;
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const SceneObject& o = scene.objects[i];
    Prepared& p = objects[i];
    p.world = o.mesh;
    transformMesh(p.world, o.worldFromObject);
    p.bounds = computeBounds(p.world.positions);
    auto exact = ExactMeshQuery::create(p.world);
    if (!exact) return makeError(exact.error().code, o.name + ": " + exact.error().message);
    p.exact = std::move(*exact);
    if (!o.shape) {
      auto distance = MeshDistance::create(o.mesh);
      if (!distance)
        return makeError(distance.error().code, o.name + ": " + distance.error().message);
      p.distance = std::move(*distance);
    }
    worldMeshes.push_back(p.world);
  }

  // One solver (and collider) per thread: solve() is const, but nothing promises reentrance.
  std::vector<std::unique_ptr<GraspSolver>> solvers;
  std::vector<std::unique_ptr<PhysicsCollider>> colliders;
  for (unsigned t = 0; t < run.threads; ++t) {
    auto solver = createAnySolver(run.method);
    if (!solver) return solver.error();
    if (Status s = (*solver)->prepare(hand, run.box, run.options); s != Status::ok) {
      return makeError(s, "scene: " + std::string((*solver)->prepareError()));
    }
    if ((*solver)->needsCollider()) {
      const auto kind = run.method == "physics-convex" ? PhysicsCollider::Kind::convexHull
                                                       : PhysicsCollider::Kind::triangleMesh;
      auto collider = PhysicsCollider::create(worldMeshes, kind);
      if (!collider) return collider.error();
      colliders.push_back(std::move(*collider));
    }
    solvers.push_back(std::move(*solver));
  }
  const bool physics = !colliders.empty();
  const bool sceneAware = run.method == "ours";

  const Prepared& reached = objects[scene.reachedFor];
  auto inAnother = [&](const Pose& worldFromHand) {
    for (size_t i = 0; i < objects.size(); ++i) {
      if (i != scene.reachedFor && openHandIntersects(*objects[i].exact, hand, worldFromHand))
        return true;
    }
    return false;
  };
  std::vector<Placement> placements;
  std::vector<char> openInside;
  std::vector<float> openMm;  // the open hand's depth in the object reached for
  if (run.approaching) {
    // Drawn in order, those whose open hand is in another object left out: a seed gives the same
    // placements on every machine. Ten times as many draws as asked covers the scenes' losses
    // (in mug-near-mug, about half the hands reaching for the mug are in the table or the other).
    for (const ApproachPlacement& a : generateApproachingPlacements(
             reached.world, *reached.exact, hand, run.box, 10 * run.placements, run.seed)) {
      if (placements.size() == size_t(run.placements)) break;
      if (inAnother(a.placement.objectFromHand)) continue;
      placements.push_back(a.placement);
      openInside.push_back(a.openInside ? 1 : 0);
      openMm.push_back(a.openPenetrationMm);
    }
  } else {
    placements = generatePlacements(reached.world, *reached.exact, hand, run.box, run.placements,
                                    run.seed, inAnother);
    openInside.assign(placements.size(), 0);
    openMm.assign(placements.size(), 0.0f);
  }
  if (placements.size() < size_t(run.placements)) {
    return makeError(Status::invalid_argument, "scene " + scene.name + ": only " +
                                                   std::to_string(placements.size()) + " of " +
                                                   std::to_string(run.placements) +
                                                   " placements have room for an open hand");
  }

  JointPoses openPose;
  hand.pose(FingerCurls{}, openPose);
  const Pose handFromPalm = openPose[size_t(Joint::palm)];
  float reach = 0.0f;
  for (int j = 0; j < kJointCount; ++j) reach = std::max(reach, hand.jointRadius(Joint(j)));

  // Solves placement `p` with the method's own rule for what it takes (see the header).
  auto solveHere = [&](unsigned t, size_t p, const glm::vec3& palm, SdfGrid& grid, SdfGrid& scratch,
                       SdfBackend& backend, SceneSolve& out) -> std::optional<Error> {
    const Pose& worldFromHand = placements[p].objectFromHand;
    GraspScene graspScene;
    graspScene.objectFromHand = worldFromHand;
    if (physics) graspScene.collider = colliders[t].get();
    std::vector<SceneMember> members;
    int paperTarget = -1;
    if (sceneAware) {
      for (size_t i = 0; i < objects.size(); ++i) {
        SceneMember m;
        m.id = i + 1;
        m.mesh = objects[i].distance.get();
        m.shape = scene.objects[i].shape ? &*scene.objects[i].shape : nullptr;
        m.objectFromHand = scene.objects[i].worldFromObject.inverse() * worldFromHand;
        m.graspable = scene.objects[i].graspable;
        members.push_back(m);
      }
    } else if (!physics) {
      paperTarget = nearestBoundsTarget(objects, scene, palm);
      SceneMember m;
      m.id = size_t(paperTarget) + 1;
      m.mesh = objects[size_t(paperTarget)].distance.get();
      m.objectFromHand =
          scene.objects[size_t(paperTarget)].worldFromObject.inverse() * worldFromHand;
      m.graspable = true;
      members.push_back(m);
    }
    if (!members.empty()) {
      if (Status s = buildSceneField(members, run.box, backend, grid, scratch); s != Status::ok) {
        return makeError(
            s, "scene " + scene.name + ": SDF build failed on placement " + std::to_string(p));
      }
      graspScene.field = &grid;
    }
    const SceneExactSource exact(members);
    if (sceneAware && run.exactCheck) graspScene.exact = &exact;
    GraspResult& result = out.result;
    if (Status s = solvers[t]->solve(graspScene, result); s != Status::ok) {
      return makeError(s, "scene " + scene.name + ": " + run.method +
                              " solve failed on placement " + std::to_string(p) + " (" +
                              toString(s) + ")");
    }
    if (sceneAware) {
      const GraspChoice choice =
          chooseTarget(members, exact, result, handFromPalm.position, hand.jointRadius(Joint::palm),
                       palmFacing(handFromPalm), reach + kTouchReach);
      out.taken = choice.member;  // members are the objects, in order
      out.touched = choice.touched;
      if (out.taken >= 0) {
        // The contacts as the worker computes them (grasp_worker.cpp).
        const size_t o = size_t(out.taken);
        out.contacts = computeContacts(hand, result, members[o].objectFromHand,
                                       objects[o].distance.get(), &grid);
      }
    } else if (physics) {
      out.taken = physicsTaken(objects, scene, worldFromHand, result, palm);
    } else {
      bool contact = false;
      for (const FingerState& f : result.fingers) contact = contact || f.contact;
      out.taken = contact ? paperTarget : -1;
    }
    return std::nullopt;
  };

  std::vector<SceneSolve> solvedElsewhere;
  if (run.solves) {
    Result<std::vector<SceneSolve>> solved = run.solves(scene, placements);
    if (!solved) return solved.error();
    if (solved->size() != placements.size()) {
      return makeError(Status::internal, "scene " + scene.name + ": " +
                                             std::to_string(solved->size()) + " solves for " +
                                             std::to_string(placements.size()) + " placements");
    }
    solvedElsewhere = std::move(*solved);
  }

  std::vector<Graded> graded(placements.size());
  std::atomic<size_t> next{0};
  auto work = [&](unsigned t) {
    const std::unique_ptr<SdfBackend> backend = makeCpuSdfBackend(1);
    SdfGrid grid(run.box), scratch(run.box);
    for (size_t p = next++; p < placements.size(); p = next++) {
      Graded& g = graded[p];
      const Pose& worldFromHand = placements[p].objectFromHand;
      const glm::vec3 palm = worldFromHand.transformPoint(handFromPalm.position);
      SceneSolve solved;
      if (!solvedElsewhere.empty()) {
        solved = solvedElsewhere[p];
      } else if (std::optional<Error> e = solveHere(t, p, palm, grid, scratch, *backend, solved)) {
        g.error = std::move(e);
        continue;
      }
      const GraspResult& result = solved.result;
      g.exceeded = result.clearanceExceeded;
      g.taken = solved.taken;
      if (sceneAware && g.taken >= 0) {
        // What XrGraspFingerStateSDFG reports: the contacts on the object taken, checked against
        // the grader's exact distance.
        const size_t o = size_t(g.taken);
        for (int f = 0; f < kFingerCount; ++f) {
          const FingerContact& c = solved.contacts[size_t(f)];
          if (!c.valid || solved.touched[size_t(f)] != g.taken) continue;
          const glm::vec3 world = scene.objects[o].worldFromObject.transformPoint(c.center);
          const double d = objects[o].exact->signedDistance(world);
          g.v1ResidualMm = std::max(g.v1ResidualMm, float(1000.0 * std::abs(d - c.distance)));
          ++g.v1Contacts;
        }
      }
      g.faced = facedObject(objects, worldFromHand * handFromPalm);
      for (size_t i = 0; i < objects.size(); ++i) {
        if (int(i) == g.taken) continue;
        const float mm = graspPenetrationMm(*objects[i].exact, hand, worldFromHand, result);
        if (mm > g.otherPenetrationMm) {
          g.otherPenetrationMm = mm;
          g.deepestObject = int(i);
        }
      }
      if (openInside[p]) {
        for (const Prepared& o : objects) {
          g.wholeMm =
              std::max(g.wholeMm, graspPenetrationMm(*o.exact, hand, worldFromHand, result));
        }
      }
      const size_t gradedObject = g.taken >= 0 ? size_t(g.taken) : scene.reachedFor;
      std::vector<GraspMetrics> perObject;
      for (const Prepared& o : objects) {
        perObject.push_back(evaluateGrasp(*o.exact, hand, worldFromHand, result));
      }
      g.metrics = combine(perObject, gradedObject);
      const Pose worldFromShown = worldFromHand * result.handCorrection;
      for (int f = 0; f < kFingerCount; ++f) {
        const FingerState& fs = result.fingers[size_t(f)];
        if (fs.contact) {
          g.fingerOn[size_t(f)] =
              nearestObject(objects, worldFromShown.transformPoint(fs.contactPoint)).first;
        }
      }
    }
  };
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < run.threads; ++t) pool.emplace_back(work, t);
  work(0);
  for (std::thread& th : pool) th.join();

  SceneFigures out;
  std::vector<double> other, inside;
  QualityTally held;
  for (size_t p = 0; p < graded.size(); ++p) {
    const Graded& g = graded[p];
    if (g.error) return *g.error;
    ++out.grasps;
    other.push_back(g.otherPenetrationMm);
    if (g.otherPenetrationMm > 0.0f) {
      ++out.otherPenetrating;
      if (g.otherPenetrationMm > out.otherPenetrationMaxMm) {
        out.otherPenetrationMaxMm = g.otherPenetrationMm;
        out.deepestPlacement = int(p);
        out.deepestObject = scene.objects[size_t(g.deepestObject)].name;
      }
    }
    if (g.faced >= 0 && scene.objects[size_t(g.faced)].graspable) {
      ++out.facingGraspable;
      if (g.taken < 0) {
        ++out.heldNothing;
      } else if (g.taken != g.faced) {
        ++out.wrongObject;
        if (out.firstWrongPlacement < 0) out.firstWrongPlacement = int(p);
        bool onFaced = false;
        for (int on : g.fingerOn) {
          out.wrongFingersOnTaken += on == g.taken ? 1 : 0;
          out.wrongFingersOnFaced += on == g.faced ? 1 : 0;
          onFaced = onFaced || on == g.faced;
        }
        out.wrongWithFingerOnFaced += onFaced ? 1 : 0;
      }
    }
    held.add(int(p), g.metrics);
    out.clearanceExceeded += g.exceeded ? 1 : 0;
    out.v1Contacts += g.v1Contacts;
    out.v1ResidualMaxMm = std::max(out.v1ResidualMaxMm, double(g.v1ResidualMm));
    if (openInside[p]) {
      ++out.openInside;
      if (g.exceeded) {
        const double deeper = double(g.wholeMm) - double(openMm[p]);
        if (out.exceededDeeperPlacement < 0 || deeper > out.exceededDeeperMaxMm) {
          out.exceededDeeperMaxMm = deeper;
          out.exceededDeeperPlacement = int(p);
        }
      } else {
        inside.push_back(g.wholeMm);
        if (g.wholeMm > out.insideWholeMaxMm) {
          out.insideWholeMaxMm = g.wholeMm;
          out.insideDeepestPlacement = int(p);
        }
      }
    }
  }
  out.otherPenetrationP99Mm = percentile(other, 0.99);
  if (!inside.empty()) out.insideWholeP99Mm = percentile(inside, 0.99);
  out.held = held.figures();
  return out;
}

}  // namespace sdfg
