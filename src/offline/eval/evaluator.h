// Grasp quality, judged against the exact surface of the original mesh (DESIGN.md section 4).
//
// ExactMeshQuery answers point-to-mesh distance with CGAL's AABB tree and inside/outside by ray
// parity, a method deliberately independent of MeshDistance (pseudo-normals, winding numbers) and
// of the SDF grids the solvers read, so the evaluator never grades a solver with its own ruler.
// evaluateGrasp() turns one solved grasp into per-finger metrics in millimetres: tip residual,
// phalanx penetration, early stop and touching. Lives in sdfg_eval (links CGAL), never in the
// layer.
#pragma once

#include <array>
#include <memory>
#include <span>

#include <glm/vec3.hpp>

#include "base/pose.h"
#include "base/status.h"
#include "grasp/solver.h"
#include "hand/hand_model.h"
#include "mesh/mesh.h"

namespace sdfg {

class ExactMeshQuery {
 public:
  // Takes its own copy of the triangles. Fails only on an invalid mesh (see validateMesh).
  // Everything is built here, so the const queries below are safe from several threads at once.
  static Result<std::unique_ptr<ExactMeshQuery>> create(const TriangleMesh& mesh);
  ~ExactMeshQuery();
  ExactMeshQuery(const ExactMeshQuery&) = delete;
  ExactMeshQuery& operator=(const ExactMeshQuery&) = delete;

  // Distance in metres to the closest point of any triangle (exact, in double precision).
  double unsignedDistance(const glm::vec3& p) const;

  // Ray parity, majority of up to kInsideRays rays in fixed pseudo-random directions (stops once
  // a majority agrees). Robust to small holes (the bunny's base) and overlapping open components
  // (the teapot) as long as most rays do not escape through a hole.
  bool inside(const glm::vec3& p) const;

  // Negative inside, metres.
  double signedDistance(const glm::vec3& p) const;

  // Signed distances of the points of a chain (consecutive points close together, e.g. samples
  // along a finger) written to `out` (same size as `points`). Faster than one signedDistance()
  // per point: the sign cannot change between neighbours farther from the surface than they are
  // from each other, so rays are cast only where the chain comes near the surface.
  void signedDistances(std::span<const glm::vec3> points, std::span<double> out) const;

  // Whether some point of a chain (as signedDistances()) has a signed distance below its radius:
  // a sphere that touches or enters the mesh. Stops at the first one, so a chain that does is
  // cheaper to refuse than to measure whole.
  bool anyWithin(std::span<const glm::vec3> points, std::span<const float> radii) const;

  static constexpr int kInsideRays = 7;

 private:
  template <class Stop>
  size_t walkChain(std::span<const glm::vec3> points, std::span<double> out, Stop stop) const;
  struct Impl;
  explicit ExactMeshQuery(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// Thresholds of the metrics (DESIGN.md section 4).
inline constexpr float kEarlyStopGapMm = 5.0f;       // a stop with a larger tip gap may be early
inline constexpr float kTouchingMm = 2.0f;           // closest phalanx sphere this near = touching
inline constexpr float kEarlyStopSweepStep = 0.01f;  // curl step of the early-stop sweep
// Penetration smaller than this does not end the early-stop sweep: solvers stop within their own
// tolerance of the surface, and the sweep asks whether a clearly better pose existed.
inline constexpr float kSweepPenetrationToleranceMm = 0.1f;
// Spacing of the spheres that sample each phalanx capsule (radius interpolated between joints).
inline constexpr float kCapsuleSampleSpacing = 0.002f;  // metres
// Curl step of the pass-through sweep (every joint from 0 to its final curl).
inline constexpr float kPassThroughSweepStep = 0.005f;
// A finger's tip counts as its contact when the tip sphere's gap is within this of the closest
// phalanx sphere's (the tip is, up to sampling, the closest part of the finger).
inline constexpr float kTipContactToleranceMm = 0.1f;

struct FingerMetrics {
  bool contact = false;        // the solver said it stopped on the surface (FingerState)
  bool stopped = false;        // contact, or curl < 1 (it did not close fully)
  float tipDistanceMm = 0.0f;  // exact signed distance of the tip joint centre
  float tipGapMm = 0.0f;       // tipDistanceMm - r_tip (negative: tip sphere penetrates)
  float tipResidualMm = 0.0f;  // |tipGapMm|; meaningful only when `contact`
  float penetrationMm = 0.0f;  // deepest point of the finger's moving capsules inside, >= 0
  float clearanceMm = 0.0f;    // min over phalanx spheres of (d - r); <= kTouchingMm: touching
  bool touching = false;
  bool earlyStop = false;  // stopped with a tip gap > 5 mm though a closer pose existed
  // Contact residual of a whole-finger method: |clearanceMm|, the gap of the closest phalanx
  // sphere (pad, proximal phalanx or tip). Equals tipResidualMm when the tip is the contact.
  float contactResidualMm = 0.0f;
  bool tipIsContact = false;  // tipGapMm <= clearanceMm + kTipContactToleranceMm
  // Some phalanx capsule sphere was inside the mesh by more than its radius (its centre inside)
  // at some curl of the sweep from the open hand to the final pose: the finger went through a
  // part, e.g. skipped a thin plate, even when its final pose is clear.
  bool passThrough = false;
};

struct GraspMetrics {
  std::array<FingerMetrics, kFingerCount> fingers{};
  float penetrationMm = 0.0f;  // max over fingers
  int contacts = 0;            // touching fingers
  int earlyStops = 0;
  int passThroughs = 0;  // fingers with passThrough
};

// Metrics of one grasp. `objectFromHand` is the placement the solver saw (non-finite: every
// float metric is NaN); the fingers are graded in the hand frame the solver closed them in,
// objectFromHand * grasp.handCorrection (where the app shows them). Curls are clamped to [0, 1],
// NaN read as 0; the finger poses come from hand.fingerPose() at each finger's final jointCurls.
// Penetration, clearance and contact residual are measured on the capsules of every bone that
// moves as the finger curls, up to the tip: from the proximal joint, or from the metacarpal where
// it turns (the thumb's), with joint radii linearly interpolated along each bone, sampled every
// kCapsuleSampleSpacing. Early stop: for a stopped finger with a tip gap > 5 mm, every joint
// curl is advanced by 0.01 per step (clamped to 1); the finger stopped early if some step brings
// the tip gap to <= 5 mm before any capsule sphere penetrates by more than 0.1 mm.
// Pass-through: s runs from 0 to the largest final joint curl in steps of kPassThroughSweepStep
// (the final curls included); joint j is at min(s, final_j), i.e. all joints close together and
// each stops at its final curl. At each step every capsule sphere centre is tested for being
// inside (exact distance, ray parity). A centre found outside at distance u is not tested again
// until the chord length it has travelled since exceeds u (it cannot have crossed before). Parts
// thinner than the centres' travel per step (about 1 mm at the tip) can be stepped over unseen.
GraspMetrics evaluateGrasp(const ExactMeshQuery& mesh, const HandModel& hand,
                           const Pose& objectFromHand, const GraspResult& grasp);

}  // namespace sdfg
