// autograsp-outer's scripted scenes: the objects a tracked hand meets (a table, a thin plate, the
// mug, a thin ring) and, per trajectory, where the tracked hand is in every 90 Hz frame.
//
// Depths are set from the hand itself: each trajectory finds the offset along its approach at
// which the tracked hand's joint spheres first touch the object (bisection on the exact
// distance), then goes the stated depth past it, so "2 cm in" means the deepest joint sphere is
// 2 cm inside, whatever the hand model's proportions.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "base/pose.h"
#include "hand/hand_model.h"
#include "mesh/mesh.h"
#include "mesh/mesh_distance.h"
#include "scene/analytic_shape.h"
#include "scene/scene.h"

namespace sdfg::outer_bench {

inline constexpr double kFrameSeconds = 1.0 / 90.0;

// One target of a scene: an analytic box or a mesh, with the exact distance the measurements use.
struct SceneObject {
  std::string name;
  uint64_t id = 0;
  TargetRole role = TargetRole::graspable;
  Pose worldFromObject;
  std::optional<AnalyticShape> shape;
  std::shared_ptr<const TriangleMesh> mesh;
  std::shared_ptr<const MeshDistance> distance;  // of `mesh`
  // Signed distance of a world point, negative inside.
  float signedDistance(const glm::vec3& world) const;
};

// A thin part the hand must not pass: in the check's frame the part is thin along Y and the hand
// comes from +Y; a shown joint centre with y < -farSide and |x| < half.x, |z| < half.z has gone
// through it.
struct PassCheck {
  Pose worldFromCheck;  // with `object`: objectFromCheck, the check moves with that object
  float farSide = 0.0f;
  glm::vec2 half{0.0f};  // x and z half extents of the footprint
  int object = -1;       // the index in Trajectory::objects of the part when it moves
};

// The tracked hand: 26 joints (hand space, the model's open pose or a squeeze) and their radii.
struct TrackedHand {
  HandModel model = HandModel::defaultAdult(Hand::right);
  JointPoses local{};
  std::array<float, kJointCount> radii{};
  // `curl`: every finger's curl in the model's curl space (0: open, 1: a fist).
  explicit TrackedHand(float curl = 0.0f);
  void world(const Pose& worldFromHand, JointPoses& out) const;
};

struct Trajectory {
  std::string name;
  std::string description;
  std::vector<SceneObject> objects;
  std::vector<Pose> hand;  // worldFromHand per frame
  std::optional<PassCheck> pass;
  // Objects the app moves: per frame, every object's worldFromObject (empty: each stays where
  // `objects` places it). The world moving past a still hand: locomotion, an object brought to it.
  std::vector<std::vector<Pose>> objectPoses;
  // Per frame, whether the hand is tracked (empty: in every frame). A frame that is not has no
  // hand to show (tracking lost; the app draws none) and is left out of every figure.
  std::vector<bool> valid;
  // Frames in which the tracked hand has just jumped (farther than a hand moves in a frame) onto
  // a pose clear of everything: the shown hand must be there at once.
  std::vector<size_t> clearJumps;
  // `objects` as they are at frame k.
  std::vector<SceneObject> objectsAt(size_t k) const;
  bool validAt(size_t k) const { return k >= valid.size() || valid[k]; }
  // The thin part's check as it is at frame k (it moves with its object).
  PassCheck passAt(size_t k) const;
};

// The deepest penetration of joint spheres (world joints, radii) into any object, metres (0 when
// clear), and the smallest clearance (negative: the depth).
float smallestClearance(const JointPoses& joints, const std::array<float, kJointCount>& radii,
                        const std::vector<SceneObject>& objects);

// The same over the hand's bone capsules as the engine covers them (grasp/hand_clearance.h's
// jointParts: spheres along every bone): over their radii, and over the radii grown to cover the
// capsules between the spheres (HandPart::coverRadius), as the outer hand keeps them out.
struct PartClearance {
  float radius = 0.0f;
  float cover = 0.0f;
};
PartClearance smallestPartClearance(const JointPoses& joints,
                                    const std::array<float, kJointCount>& radii,
                                    const std::vector<SceneObject>& objects);

// Every trajectory of the benchmark, for `hand`. `scale` (0, 1] shortens holds and slides (the
// smoke test); speeds and depths stay.
std::vector<Trajectory> makeTrajectories(const TrackedHand& hand, float scale);

}  // namespace sdfg::outer_bench
