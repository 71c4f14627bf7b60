// A strategy's grasps in a scene (eval/scenes.h): what the whole hand does to the objects it does
// not hold, whether it took the object the palm faces, and the single-object figures on the
// object it holds. Deterministic for a seed, so the quality tests gate it and the benchmark
// publishes it.
//
// Per placement (open hand clear of every object, palm facing a surface point of the object
// reached for, 1 to 4 cm off it: eval/placements.h with the other objects added to the
// rejection), each strategy closes the hand as it would in an app:
//  - "ours": through the engine's GraspWorker, exactly as the layer's session runs it: every
//    object a target (scene geometry as analytic shape targets of role scene), the union field of
//    all of them, the scene's exact distance, and the target the closing hand touches
//    (grasp/target_choice.h);
//  - "physics-convex", "physics-mesh": one Bullet world with a collider per object (a convex hull
//    each, or the triangles); the hand takes the graspable object most touching fingertips are on
//    (nearest surface to each contact), ties to the one nearest the palm;
//  - "paper": it sees one target by design: the graspable object whose bounding box is nearest
//    the palm (the rule before scenes), its field alone; it takes it when a finger stopped.
// Then, against the exact meshes (eval/evaluator.h, CGAL, independent of what the solvers read):
//  - the whole hand's penetration (eval/approaching.h: palm and every bone, where the strategy
//    moved the hand) into every object it does not hold, the deepest per grasp;
//  - the object the palm faces: the first surface a ray from the palm joint along the palm's
//    normal meets (sphere tracing on the exact distances, up to 30 cm); a grasp is "wrong" when
//    that object is graspable and the hand took another graspable object;
//  - evaluateGrasp() on the object held (or, holding nothing, the one reached for): contacts,
//    residuals, finger penetration, early stops, pass-throughs, as the single-object benchmark,
//    except that what a finger does is judged on every object (evaluateGrasp() on each): its
//    contact residual and touching on the nearest object, a pass-through through any object, and
//    an early stop only where no other object is within the early-stop gap either.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "base/status.h"
#include "eval/placements.h"
#include "eval/quality.h"
#include "eval/scenes.h"
#include "grasp/contact.h"
#include "grasp/solver.h"
#include "sdf/sdf_grid.h"

namespace sdfg {

// What "ours" did at one placement, when something other than measureScene() solved it.
struct SceneSolve {
  GraspResult result;  // hand space, as a solver returns it
  int taken = -1;      // the object held (index into BenchScene::objects); -1: none
  // Per finger, the object its contact is on (-1: none), and where it touches the object taken
  // (that object's frame): what XrGraspTouchesSDFG and XrGraspFingerStateSDFG report.
  std::array<int, kFingerCount> touched{-1, -1, -1, -1, -1};
  FingerContacts contacts{};
};

// Solves every placement of a scene, in order, one SceneSolve each: "ours" run somewhere else
// than in measureScene() (eval/buffer_scene.h: through a GraspSession whose meshes live in a
// Vulkan device's buffers, as the layer runs an app's buffer targets). The placements' hand
// frames are in the scene's world frame.
using SceneSolves = std::function<Result<std::vector<SceneSolve>>(
    const BenchScene& scene, std::span<const Placement> placements)>;

struct SceneRun {
  std::string method = "ours";  // any strategy of createAnySolver()
  int placements = 100;
  uint64_t seed = 1;
  unsigned threads = 1;  // grading threads; no effect on the figures
  SolverOptions options{};
  bool exactCheck = true;  // "ours": the scene's exact distance (GraspSettings::exactCheck)
  GridBox box = GridBox::referenceDefault();
  // Approaching hands (eval/approaching.h): the palm from 1 cm inside to 5 cm outside the object
  // reached for, open hands inside it kept (those inside another object are drawn again).
  bool approaching = false;
  // "ours" only: where the placements are solved (empty: here, on the CPU, as the worker does).
  // The grading is the same either way.
  SceneSolves solves;
};

struct SceneFigures {
  int grasps = 0;
  // The whole hand inside objects it does not hold, per grasp's deepest (mm).
  double otherPenetrationP99Mm = 0.0;
  double otherPenetrationMaxMm = 0.0;
  int deepestPlacement = -1;  // the grasp with the deepest (-1: none inside anything)
  std::string deepestObject;  // the object it is in
  int otherPenetrating = 0;   // grasps with any part inside an object not held
  int facingGraspable = 0;    // grasps whose palm faces a graspable object
  int wrongObject = 0;        // of those, the hand took another graspable object
  int heldNothing = 0;        // of those, the hand took nothing
  int firstWrongPlacement = -1;
  // Over the wrong grasps: fingers in contact on the object taken and on the one faced (each
  // contact point's nearest object), summed.
  int wrongFingersOnTaken = 0;
  int wrongFingersOnFaced = 0;
  // The wrong grasps where some finger in contact was on the object faced: a rule that took the
  // faced object whenever a finger touches it would have taken it there.
  int wrongWithFingerOnFaced = 0;
  // Single-object figures on the object held (else the one reached for): fingers touching it,
  // contact residuals, fingers into it (per grasp's deepest), early stops, pass-throughs.
  QualityFigures held;
  // With SceneRun::approaching: the grasps whose open hand started inside the object reached for.
  // Of those the clearance moved (within its bound), the whole hand's deepest penetration into
  // any object after the grasp (the one held too: out of it without going into a neighbour). The
  // others (the hand needed more than the bound, and says so) are left where they were: their
  // fingers must not close any deeper than the open hand already was.
  int openInside = 0;
  double insideWholeP99Mm = 0.0;
  double insideWholeMaxMm = 0.0;
  int insideDeepestPlacement = -1;
  int clearanceExceeded = 0;         // grasps whose hand needed more than the clearance's bound
  double exceededDeeperMaxMm = 0.0;  // of those: after minus before, the most (<= 0: never deeper)
  int exceededDeeperPlacement = -1;
  // "ours": the version 1 contacts an app reads (XrGraspFingerStateSDFG, the fingers on the object
  // taken): the engine's distance against the grader's exact signed distance at the same point.
  int v1Contacts = 0;
  double v1ResidualMaxMm = 0.0;
};

// Errors: an unknown strategy, invalid options, fewer placements found than asked, or a failed
// build or solve (named).
Result<SceneFigures> measureScene(const BenchScene& scene, const SceneRun& run);

}  // namespace sdfg
