// Which target a grasp takes: the graspable object the closing hand actually touches, not the
// one whose bounding box happens to be nearest (XR_SDFG_auto_grasp version 3).
//
// After the fingers have closed on the whole scene, each finger in contact touches the member
// that owns the nearest surface at its touching sphere, and the palm touches every member its
// surface is within kPalmTouch of. The rule, deterministic:
//   1. the member the palm faces (the first surface on the ray from the palm joint along the
//      palm's normal, within kFacingRange), if the hand may take it and touches it (a finger, or
//      the palm within kFacedTouch: the palm's turn says what the user reaches for, so it counts
//      from a little farther than kPalmTouch): fingers that wrap past it onto a neighbour (a mug
//      beside a mug, a spoon standing in a mug) must not outvote it;
//   2. else among the members the hand may take (SceneMember::graspable) that the hand touches,
//      the one the most fingers touch;
//   3. between those, the one whose surface is nearest the palm (exact distance of the palm
//      joint's centre);
//   4. between those, the lowest id.
// A member the hand does not touch is never taken (one behind another, say); when it touches
// only scene geometry, or nothing, the hand holds nothing (its fingers still rest on what they
// touch). The palm counts because a flat object under it (a comb on a table) is often touched by
// no finger: they close past it onto the table, and the thumb, lower than the palm, keeps the
// palm's own surface a centimetre or more above it.
#pragma once

#include <array>
#include <span>

#include <glm/vec3.hpp>

#include "grasp/solver.h"
#include "hand/hand_model.h"
#include "scene/scene.h"

namespace sdfg {

struct GraspChoice {
  int member = -1;  // index into the scene's members; -1: the hand holds nothing
  // Per finger (thumb first), the member its contact touches; -1: no contact, or no surface
  // within reach of the touching sphere.
  std::array<int, kFingerCount> touched{-1, -1, -1, -1, -1};
  int fingersOnChoice = 0;
  int faced = -1;  // the member the palm faces (-1: none within kFacingRange)
};

// The palm touches a member whose surface is within this of the palm joint's sphere.
inline constexpr float kPalmTouch = 0.02f;  // metres
// The palm touches the member it faces when its surface is within this of the palm's sphere.
inline constexpr float kFacedTouch = 0.03f;  // metres
// How far along the palm's normal the member the palm faces is looked for.
inline constexpr float kFacingRange = 0.3f;  // metres

// `scene`: the members' exact source (the one the solve used); `result`: the solve (contact
// points in its corrected hand frame); `palm`, `palmRadius`: the palm joint's centre in the same
// frame as the contact points, and its radius; `palmNormal`: the unit normal out of the palm's
// side, same frame; `reach`: how far from a touching sphere's centre its surface may be (the
// sphere's radius plus the solver's tolerance; metres).
GraspChoice chooseTarget(std::span<const SceneMember> members, const ExactDistanceSource& scene,
                         const GraspResult& result, const glm::vec3& palm, float palmRadius,
                         const glm::vec3& palmNormal, float reach);

}  // namespace sdfg
