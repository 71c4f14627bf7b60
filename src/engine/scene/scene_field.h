// The grab-box field of a scene: at every node, the signed distance to the nearest surface of any
// member, i.e. the field of the union of their solids. It is still a distance field (the minimum
// of 1-Lipschitz functions is one), so the solvers' conservative advancement and error bounds hold
// on it unchanged, and every hand part stops on the first surface it meets, whoever owns it.
#pragma once

#include <span>

#include "base/status.h"
#include "base/work_limit.h"
#include "scene/scene.h"
#include "sdf/sdf_backend.h"
#include "sdf/sdf_grid.h"

namespace sdfg {

// Builds the union field of `members` in `box` into `out` (resized to the box): each mesh member
// by `backend` into `scratch` (reused between calls), merged by the minimum; shapes evaluated at
// the nodes directly, volumes sampled there. An empty span fails with invalid_argument (a scene
// with nothing in the box has no field). `limit` bounds the whole build: once reached it returns
// timed_out, and `out` is then not a field to solve on; a backend failure is returned as is.
// out.exactBand() is the largest band of the mesh members' builds (each node within it of the
// union's surface is exact: the nearest member's value is, and the others' lower bounds are
// larger).
Status buildSceneField(std::span<const SceneMember> members, const GridBox& box,
                       SdfBackend& backend, SdfGrid& out, SdfGrid& scratch,
                       const WorkLimit& limit = WorkLimit::none());

// Merges shape member `shape` (placed by objectFromHand) into `field` by the minimum.
void mergeShapeIntoField(const AnalyticShape& shape, const Pose& objectFromHand, SdfGrid& field);
// The same for a sampled volume (placed by objectFromHand: hand point -> volume frame).
void mergeVolumeIntoField(const DistanceVolume& volume, const Pose& objectFromHand, SdfGrid& field);

}  // namespace sdfg
