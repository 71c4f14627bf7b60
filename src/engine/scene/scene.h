// The solids a grasp sees in its grab box: every registered target whose bounds overlap the box
// (the broad phase, scene_index.h), each as its distance source (a mesh's exact MeshDistance, an
// analytic shape, or a sampled DistanceVolume such as the depth scene's) placed relative to the
// hand. The field a grasp solves on is their union
// (scene_field.h), its exact check samples the nearest of them (grasp/scene_exact_source.h), and
// which one a finger touches decides what the hand holds (grasp/target_choice.h).
#pragma once

#include <cstdint>
#include <span>

#include "base/pose.h"
#include "mesh/mesh_distance.h"
#include "scene/analytic_shape.h"
#include "scene/distance_volume.h"

namespace sdfg {

// What a target is to the hands (XR_SDFG_auto_grasp version 3).
enum class TargetRole : uint8_t {
  graspable,  // hands grasp it and stop on it
  scene,      // hands stop on it and never take it (tables, walls, a body)
  ignored,    // hands pass through it
};

struct SceneMember {
  uint64_t id = 0;                     // the target's id
  const MeshDistance* mesh = nullptr;  // exactly one of mesh, shape and volume is set
  const AnalyticShape* shape = nullptr;
  Pose objectFromHand;     // hand-space point -> the member's own frame
  bool graspable = false;  // the hand of this grasp may take it (role and per-hand settings)
  const DistanceVolume* volume = nullptr;  // a sampled solid (the depth scene's)
};

// The signed distance at `p` (the member's own frame) of a member without triangles (a shape or a
// volume), and its closest surface point.
inline float closestOfSolid(const SceneMember& m, const glm::vec3& p, glm::vec3& closest) {
  return m.shape != nullptr ? m.shape->closest(p, closest) : m.volume->closest(p, closest);
}

// At most this many members take part in one grasp: more targets than this in one grab box are
// cut to the nearest (the exact source's feature ids carry the member index in 8 bits).
inline constexpr size_t kMaxSceneMembers = 255;

}  // namespace sdfg
