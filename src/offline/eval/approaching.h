// Approaching hands (issue 21): placements where the open hand may already be inside the object,
// and the penetration of the whole hand after a grasp.
//
// A user reaches for an object and squeezes when the hand is near it, often partly in it. These
// placements put the palm joint anywhere from 1 cm inside to 5 cm outside a random surface point
// (palm facing the surface, random roll), with no rejection of hands that intersect the mesh, and
// flag the ones whose open hand is already inside, so a benchmark can split its figures by that.
#pragma once

#include <cstdint>
#include <vector>

#include "base/pose.h"
#include "eval/evaluator.h"
#include "eval/placements.h"
#include "grasp/solver.h"
#include "hand/hand_model.h"
#include "mesh/mesh.h"
#include "sdf/sdf_grid.h"

namespace sdfg {

inline constexpr float kApproachMinPalmDistance = -0.01f;  // metres: palm joint 1 cm inside
inline constexpr float kApproachMaxPalmDistance = 0.05f;   // and 5 cm outside

struct ApproachPlacement {
  Placement placement;             // palmDistance in [-1, 5] cm
  float openPenetrationMm = 0.0f;  // deepest part of the open hand inside the mesh, >= 0
  bool openInside = false;         // openPenetrationMm > 0: the open hand is already inside
};

// Up to `count` approaching placements over `normalizedMesh` (as generatePlacements(), same draws
// per attempt, but the palm distance uniform in [-1, 5] cm and no rejection of hands that touch
// or enter the mesh; attempts whose surface point is outside `box` are still rejected).
std::vector<ApproachPlacement> generateApproachingPlacements(const TriangleMesh& normalizedMesh,
                                                             const ExactMeshQuery& query,
                                                             const HandModel& hand,
                                                             const GridBox& box, int count,
                                                             uint64_t seed);

// Deepest point of the whole hand inside the mesh, millimetres, >= 0: the palm joint's sphere and
// every bone's capsule from the metacarpal joint to the tip (joint radii interpolated, sampled
// every kCapsuleSampleSpacing), with each finger at `curls` and the hand moved by `handCorrection`
// (GraspResult::handCorrection: corrected hand frame -> the placement's hand frame).
float handPenetrationMm(const ExactMeshQuery& query, const HandModel& hand,
                        const Pose& objectFromHand,
                        const std::array<JointCurls, kFingerCount>& curls,
                        const Pose& handCorrection = {});

// handPenetrationMm() of a solved grasp: each finger at its final jointCurls, the hand where the
// strategy moved it.
float graspPenetrationMm(const ExactMeshQuery& query, const HandModel& hand,
                         const Pose& objectFromHand, const GraspResult& grasp);

}  // namespace sdfg
