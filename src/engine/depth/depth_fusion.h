// The depth scene near one hand: the app's submitted depth (depth_view.h) fused over frames into a
// signed distance volume around the hand, which grasps stop on and the outer hand keeps the shown
// hand out of as one more scene member (scene/distance_volume.h).
//
// Per frame and voxel (a cube of `size` around the hand, world-aligned, `voxel` apart), the voxel
// is projected into each view and compared with the surface its pixel saw, along the ray:
//  - in front of the surface by more than the band (`truncation`): seen through, free;
//  - within the band in front, or behind it by up to `behindThickness`: solid that far behind what
//    is seen (a finger that wraps behind a seen surface stops there; no depth camera sees the
//    back of an object, and a stated prior beats an open back: an object thinner than it, seen
//    from one place, is grasped early on its unseen side, never entered);
//  - farther behind: not observed (the voxel keeps what it had).
// Pixels whose surface point lies within the hand's exclusion spheres (the shown hand's joints,
// grown by `handMargin`) are the hand the app drew, not the scene: their rays observe nothing, so
// what was fused before the hand came stays, and is never forgotten while the hand hides it.
// Observations are averaged with a capped weight
// (`maxWeight` frames), so a surface that moves is followed within a few frames, and a voxel not
// observed for `forgetAfter` seconds is forgotten (read as free), so a moved object leaves no
// ghost where nothing looks any more.
//
// Not thread-safe; one per hand, on the thread that fuses.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "base/status.h"
#include "depth/depth_view.h"
#include "scene/distance_volume.h"

namespace sdfg {

struct DepthFusionOptions {
  float size = 0.24f;    // metres: the cube's edge (the grab box and a margin)
  float voxel = 0.003f;  // metres between nodes
  // Metres: the band of distances kept, wider than the hand's largest sphere (a finger must read
  // free space as farther than its own radius).
  float truncation = 0.03f;
  // Metres of solid assumed behind a seen surface. 3 cm: on the embedded mug seen from a head
  // 40 cm away, fingers that wrap behind it stay out of it (less, and they enter its unseen
  // walls; more, and they stop farther from its back: depth_scene_tests prints the figures).
  float behindThickness = 0.03f;
  float handMargin = 0.008f;  // metres added to each exclusion sphere
  float maxWeight = 4.0f;     // frames an average remembers
  double forgetAfter = 1.0;   // seconds without an observation before a voxel is forgotten

  std::optional<Error> validate() const;
};

// A sphere of the shown hand (world): depth within it (plus the margin) is the hand's own.
struct DepthExclusion {
  glm::vec3 centre{0.0f};
  float radius = 0.0f;
};

class DepthFusion {
 public:
  // Errors: invalid_argument for options that validate() refuses.
  static Result<DepthFusion> create(const DepthFusionOptions& options);

  // Centres the cube on `centre` (world), rounded to whole voxels; what the old cube and the new
  // one share is kept, the rest starts unobserved. volume() moves with the next finishFrame().
  void recentre(const glm::vec3& centre);
  // Fuses one view at time `time` (seconds, not decreasing): `depth` holds the view's stored
  // values, width x height, row-major from the top row. Errors: invalid_argument (the view's
  // validate(), or a span of the wrong size), and nothing changes.
  Status integrate(const DepthView& view, std::span<const float> depth,
                   std::span<const DepthExclusion> hand, double time);
  // Ends the frame: forgets voxels unobserved for forgetAfter and refreshes volume().
  void finishFrame(double time);

  // The fused signed distance; its frame is the world (a scene member's objectFromHand is then
  // the hand's pose in the world).
  const DistanceVolume& volume() const { return volume_; }
  // Voxels observed at least once and not forgotten.
  size_t observedVoxels() const;

 private:
  explicit DepthFusion(const DepthFusionOptions& options);
  size_t index(uint32_t i, uint32_t j, uint32_t k) const { return volume_.index(i, j, k); }
  // volume() from the fused values: their signs, and the Euclidean distance to their surface.
  void refreshVolume();

  DepthFusionOptions options_;
  uint32_t n_ = 0;            // nodes per axis
  glm::ivec3 corner_{0};      // node (0,0,0) in whole voxels of the world
  std::vector<float> value_;  // fused distance, metres
  std::vector<float> weight_;
  std::vector<double> seen_;  // time of the last observation
  DistanceVolume volume_;
  std::vector<uint8_t> handMask_;  // scratch: per pixel of the view being fused
  // Scratch of refreshVolume(): the fused surface's points (node units), and per node the nearest
  // of them and its distance (node units).
  std::vector<glm::vec3> surface_;
  std::vector<int32_t> nearest_;
  std::vector<float> distance_;
};

}  // namespace sdfg
