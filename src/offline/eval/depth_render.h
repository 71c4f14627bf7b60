// Depth images rendered as an app's depth pass would (a small z-buffer rasterizer), for measuring
// the depth scene (depth/depth_fusion.h) against the meshes the truth is measured on: distances
// at every pixel centre of a view (depth/depth_view.h), and the stored values of each format apps
// submit (D16 and D24 quantized, D32 float) in the view's convention.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "base/pose.h"
#include "depth/depth_view.h"
#include "mesh/mesh.h"

namespace sdfg {

enum class DepthStored { d16, d24, d32 };

// A square view of `size` pixels and a 90-degree field of view at `eye`, looking at `target`
// (world +Y up).
DepthView depthLookAt(const glm::vec3& eye, const glm::vec3& target, float nearZ, float farZ,
                      uint32_t size = 512);

struct DepthPlaced {
  const TriangleMesh* mesh;
  Pose worldFromObject;
};

// The view distance of the nearest surface at every pixel centre (+infinity: none), row by row
// from the top.
std::vector<float> renderDepthDistances(const DepthView& view,
                                        std::span<const DepthPlaced> objects);

// The stored values an app would submit for those distances (DepthView::storedAt, quantized as
// `format` stores them).
std::vector<float> storedDepthValues(const DepthView& view, const std::vector<float>& z,
                                     DepthStored format);

}  // namespace sdfg
