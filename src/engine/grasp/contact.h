// Where each finger of a solved grasp touches the target, in the target's own frame: the touching
// part (a joint's sphere or a point of a bone's capsule), the centre of that sphere, the closest
// point of the target's surface, the outward surface normal there and the signed distance at the
// centre. Computed once per solve (GraspSession), not when the app asks.
//
// The sphere centre is rebuilt from the finger's final joint curls through the hand model, so it
// is where the located joints put it, not where an intermediate step of the solver saw it. With
// a CPU mesh the point, normal and distance come from one exact query of MeshDistance at that
// centre: the distance is the mesh's exact signed distance at the reported centre (float
// rounding apart) and the point is the exact closest point. The sign is the nearest sheet's
// (MeshDistance::localSignedDistanceWithin, as the solver's exact check): on open meshes it
// differs from the winding-number sign of signedDistance() only near holes. Without one
// (device-only targets) they come from the grab-box field the solve read: trilinear distance and
// gradient, off by up to the field's error (millimetres at 16^3 near curved or sharp parts).
#pragma once

#include <array>

#include <glm/vec3.hpp>

#include "base/pose.h"
#include "grasp/solver.h"
#include "hand/hand_model.h"
#include "mesh/mesh_distance.h"
#include "sdf/sdf_grid.h"

namespace sdfg {

struct FingerContact {
  bool valid = false;  // the finger touches (FingerState::contact)
  bool exact = false;  // from the exact mesh distance (false: from the grab-box field)
  // The touching part: `jointSphere` true: the sphere of `joint`; false: the capsule of the bone
  // that starts at `joint` (toward the tip), at `boneFraction` of its length (0 at `joint`).
  bool jointSphere = false;
  Joint joint = Joint::palm;
  float boneFraction = 0.0f;
  glm::vec3 center{0.0f};        // target frame, metres: centre of the touching sphere
  float radius = 0.0f;           // metres: that sphere's radius (the finger surface's)
  glm::vec3 surfacePoint{0.0f};  // target frame: the closest point of the surface to `center`
  glm::vec3 normal{0.0f};        // target frame, unit: the surface's outward normal there
  float distance = 0.0f;         // signed distance of the target at `center`, negative inside
};

using FingerContacts = std::array<FingerContact, kFingerCount>;

// Contacts of `result` (solved with `hand`; contact points in the corrected hand frame, mapped to
// the scene's hand frame by result.handCorrection) on a target at objectFromHand. `mesh`: the
// target's exact distance (object frame), or null; `field`: the grab-box SDF of the solve (scene
// hand frame), used when `mesh` is null; with neither, contacts stay invalid.
FingerContacts computeContacts(const HandModel& hand, const GraspResult& result,
                               const Pose& objectFromHand, const MeshDistance* mesh,
                               const SdfGrid* field);

}  // namespace sdfg
