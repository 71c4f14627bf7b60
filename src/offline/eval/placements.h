// Seeded hand placements over a mesh: the same grasps for every solver in the benchmark.
//
// A placement puts the open hand's palm at 1 to 4 cm from a random surface point, palm facing the
// surface, rolled at random about the normal (DESIGN.md section 4). Random numbers come from
// std::mt19937_64 turned into uniforms by our own code (the standard distributions differ between
// library implementations), so a seed gives the same placements on every machine.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include <glm/vec3.hpp>

#include "base/pose.h"
#include "eval/evaluator.h"
#include "hand/hand_model.h"
#include "mesh/mesh.h"
#include "sdf/sdf_grid.h"

namespace sdfg {

struct Placement {
  Pose objectFromHand;           // hand-space point -> mesh space
  glm::vec3 surfacePoint{0.0f};  // mesh space, on the surface
  glm::vec3 normal{0.0f};        // unit face normal at surfacePoint (outward for CCW faces)
  float palmDistance = 0.0f;     // metres from surfacePoint to the palm joint, along `normal`
};

inline constexpr float kMinPalmDistance = 0.01f;  // metres
inline constexpr float kMaxPalmDistance = 0.04f;
// Attempts per requested placement before generatePlacements() gives up.
inline constexpr int kPlacementAttemptsPerPlacement = 200;

// Up to `count` placements over `normalizedMesh` (the mesh the solvers see, already scaled to hand
// size, e.g. normalizedToDiagonal(mesh, 0.18f)); `query` must be built from the same mesh.
// Each attempt draws, in this order: a triangle (area-weighted), two barycentric uniforms, the
// palm distance (uniform in [1, 4] cm) and the roll angle about the normal. An attempt is rejected
// and the next random numbers are drawn when:
//  - the surface point, seen from the hand, lies outside `box` (the grab box could not see it);
//  - the open hand (all curls 0) touches or enters the mesh: any sphere of the palm and wrist
//    joints, of the metacarpal bones (sampled every 2 mm, radius interpolated between the joints)
//    or of the phalanx capsules from the proximal joint to the tip has a signed distance below its
//    radius.
// Returns fewer than `count` placements only when kPlacementAttemptsPerPlacement * count attempts
// did not find enough (a mesh with no room for an open hand); callers check size(). count <= 0
// gives an empty vector. `stats`, when given, receives how many attempts were drawn and why
// rejected ones were.
struct PlacementStats {
  long long attempts = 0;
  long long outsideBox = 0;        // rejected: surface point outside the grab box
  long long handIntersecting = 0;  // rejected: the open hand touches or enters the mesh
};
std::vector<Placement> generatePlacements(const TriangleMesh& normalizedMesh,
                                          const ExactMeshQuery& query, const HandModel& hand,
                                          const GridBox& box, int count, uint64_t seed,
                                          PlacementStats* stats = nullptr);

// The same, where the open hand must also keep clear of other solids around the mesh (a scene: a
// table, a wall, another object): an attempt is also rejected, counted as handIntersecting, when
// `alsoRejects(objectFromHand)` is true. It is asked only after the tests above passed, so the
// random numbers drawn, and the placements kept for a null one, are those of generatePlacements().
std::vector<Placement> generatePlacements(const TriangleMesh& normalizedMesh,
                                          const ExactMeshQuery& query, const HandModel& hand,
                                          const GridBox& box, int count, uint64_t seed,
                                          const std::function<bool(const Pose&)>& alsoRejects,
                                          PlacementStats* stats = nullptr);

// Whether the open hand at `objectFromHand` touches or enters the mesh (the rejection test above,
// without the box).
bool openHandIntersects(const ExactMeshQuery& query, const HandModel& hand,
                        const Pose& objectFromHand);

// A uniform double in [0, 1) from the top 53 bits of one 64-bit draw: identical on every platform.
inline double uniform01(uint64_t bits) {
  return double(bits >> 11) * 0x1.0p-53;
}

}  // namespace sdfg
