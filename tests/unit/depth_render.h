// Depth images for the depth scene's tests: the benchmark's rasterizer (eval/depth_render.h) under
// the tests' names, and the scene they share (the embedded mug on a table, seen from a head 40 cm
// away).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>

#include "depth/depth_view.h"
#include "eval/depth_render.h"
#include "io/shapes.h"
#include "mesh/mesh.h"

namespace sdfg::depth_test {

// The rasterizer is the benchmark's (eval/depth_render.h); the tests' names for it.
using Stored = DepthStored;
using Placed = DepthPlaced;
inline DepthView lookAt(const glm::vec3& eye, const glm::vec3& target, float nearZ, float farZ,
                        uint32_t size = 512) {
  return depthLookAt(eye, target, nearZ, farZ, size);
}
inline std::vector<float> renderDistances(const DepthView& view, std::span<const Placed> objects) {
  return renderDepthDistances(view, objects);
}
inline std::vector<float> storedDepth(const DepthView& view, const std::vector<float>& z,
                                      Stored format) {
  return storedDepthValues(view, z, format);
}

// The mug of shapes.h standing on a table top at the world's origin, as the benchmark's scenes
// have it (its base on y = 0).
struct MugOnTable {
  TriangleMesh mug = makeMug();
  TriangleMesh table = makeBox(glm::vec3(0.5f, 0.04f, 0.5f));
  Pose worldFromMug{glm::quat(1, 0, 0, 0), glm::vec3(0.0f, 0.0475f, 0.0f)};
  Pose worldFromTable{glm::quat(1, 0, 0, 0), glm::vec3(0.0f, -0.02f, 0.0f)};
  std::vector<Placed> objects() const { return {{&mug, worldFromMug}, {&table, worldFromTable}}; }
};

// A head 40 cm from the mug, above and in front of it.
inline DepthView headView(float nearZ = 0.05f, float farZ = 100.0f) {
  return lookAt(glm::vec3(0.0f, 0.30f, 0.27f), glm::vec3(0.0f, 0.05f, 0.0f), nearZ, farZ);
}

}  // namespace sdfg::depth_test
