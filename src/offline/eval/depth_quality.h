// The depth scene's figures (issue 35, docs/depth.md): an object on the table, seen only through
// the depth an app would submit from a head 40 cm away, grasped by hands that reach for what the
// head sees, graded against the true surfaces.
//
// Per scene (eval/scenes.h: the object the placements are drawn on and the table under it): one
// D24 view of everything, 512 x 512 pixels and 90 degrees, from above and in front of the object;
// the benchmark's placements on the object whose open hand is clear of everything and whose
// surface point the head sees, split by where the palm comes from (above: the surface's normal
// within 45 degrees of up; the side: within 25 degrees of level); per placement the view fused
// once into the depth volume around the hand (depth/depth_fusion.h, its defaults), the grab-box
// field built from that volume alone, solved, and every finger graded on the nearest true
// surface.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "base/status.h"
#include "depth/depth_view.h"
#include "eval/scenes.h"
#include "grasp/solver.h"
#include "hand/hand_model.h"
#include "sdf/sdf_backend.h"
#include "sdf/sdf_grid.h"

namespace sdfg {

struct DepthQualityOptions {
  int placements = 200;  // per reach (above, side)
  uint64_t seed = 1;
  float headDistance = 0.40f;  // metres from the object's centre
};

struct DepthReachFigures {
  std::string reach;  // "above" or "side"
  int reaches = 0;
  int made = 0;  // grasps with two or more fingers on a true surface (within kTouchingMm)
  float penetrationP99Mm = 0.0f, penetrationMaxMm = 0.0f;  // deepest finger per grasp
  float residualMedianMm = 0.0f, residualP95Mm = 0.0f;     // |gap| of fingers in contact
};

struct DepthQuality {
  std::string scene;
  std::vector<DepthReachFigures> reaches;
};

// One grasp on depth alone: `stored` (the view's values) fused once into the volume around the
// hand at `worldFromHand` (its grab box's centre), the grab-box field built from that volume, and
// `solver` closing on it. Errors: those of the fusion (a view it refuses), the build and the solve.
Status solveOnDepth(const DepthView& view, std::span<const float> stored, const Pose& worldFromHand,
                    const GridBox& box, GraspSolver& solver, SdfBackend& backend, GraspResult& out);

// Errors: invalid_argument (a scene without its object and a table, a solver that is not
// prepared for `hand` and `box`), and those of the meshes' exact queries and the field's build.
// Fewer reaches than asked when the object has no more seen placements of that kind
// (DepthReachFigures::reaches says how many).
Result<DepthQuality> depthSceneQuality(const BenchScene& scene, const HandModel& hand,
                                       const GridBox& box, GraspSolver& solver, SdfBackend& backend,
                                       const DepthQualityOptions& options);

}  // namespace sdfg
