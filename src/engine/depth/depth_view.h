// One view of an app's submitted depth (XR_KHR_composition_layer_depth): where the view is, its
// field of view, the sub-image it covers, and how its stored values map to distances. The depth
// scene (depth/depth_fusion.h) reads every pixel through this.
//
// Conventions, as the extension defines them: a stored value d in [minDepth, maxDepth] is at view
// distance nearZ when d == minDepth and farZ when d == maxDepth, and a perspective projection makes
// 1 / distance affine in d. So one formula serves standard depth (nearZ < farZ), reversed depth
// (nearZ > farZ) and an infinite plane on either side (1 / inf == 0). Distances are along the
// view's -Z axis (OpenXR view space: +X right, +Y up); pixel (0, 0) is the rect's top-left corner,
// pixel centres are at +0.5.
#pragma once

#include <cstdint>
#include <optional>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "base/pose.h"
#include "base/status.h"

namespace sdfg {

// Pixels [x, x + width) x [y, y + height) of a view's rect.
struct DepthPixelRect {
  uint32_t x = 0, y = 0, width = 0, height = 0;
};

// Radians, as XrFovf: left and down negative for a view that straddles its axis.
struct DepthFov {
  float left = 0.0f, right = 0.0f, up = 0.0f, down = 0.0f;
};

struct DepthView {
  Pose worldFromView;
  DepthFov fov;
  uint32_t width = 0, height = 0;  // of the sub-image rect, pixels
  float minDepth = 0.0f, maxDepth = 1.0f;
  float nearZ = 0.0f, farZ = 0.0f;  // metres; either may be +infinity, never both

  // Why the view cannot be read (nothing: it can): a non-finite or non-unit pose, a field of
  // view that is not a valid frustum, an empty rect, minDepth >= maxDepth or outside [0, 1],
  // nearZ == farZ, a plane not positive or NaN.
  std::optional<Error> validate() const;

  // The view distance of stored value `depth`; +infinity at an infinite plane; NaN for a value
  // outside [minDepth, maxDepth] or not finite.
  float distance(float depth) const;
  // The stored value at view distance `z` (> 0), clamped to [minDepth, maxDepth].
  float storedAt(float z) const;
  // Whether stored value `depth` is the far plane (nothing drawn there).
  bool atFar(float depth) const { return depth == (nearZ < farZ ? maxDepth : minDepth); }

  // The view-space direction through pixel position `pixel` scaled to distance 1 along -Z.
  glm::vec3 ray(const glm::vec2& pixel) const;
  // Where world point `p` falls: its pixel position and view distance; false behind the view.
  bool project(const glm::vec3& p, glm::vec2& pixel, float& z) const;

  // The pixels whose rays can meet the world box [lo, hi]: the bounds of its corners' projections,
  // grown to whole pixels, within the view. The whole view when the box reaches to within 1 mm of
  // the view's eye plane (its projection is unbounded there); nullopt when no ray meets it.
  std::optional<DepthPixelRect> cover(const glm::vec3& lo, const glm::vec3& hi) const;
  // The view of `rect` alone, a rect within this view: the same pose, depth range and planes, the
  // field of view narrowed to the rect's edges, rect's size.
  DepthView crop(const DepthPixelRect& rect) const;
};

}  // namespace sdfg
