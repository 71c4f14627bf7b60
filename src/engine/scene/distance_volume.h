// A solid known only through samples of its signed distance on a regular grid: the depth scene's
// fused view of what the app draws (depth/depth_fusion.h), or any other source without
// triangles. A scene member like a mesh or an analytic shape (scene.h): the union field merges
// it, the exact source and the target choice read it, with the caveat that its distance is only
// as good as its samples (trilinear between nodes; the closest point is found along the
// gradient).
//
// Nodes hold metres, negative inside, clamped by whoever fills them to a truncation band
// (`truncation()`): farther than that from a surface reads as that far. Outside the grid the
// volume says nothing, which reads as `truncation()` outside (no surface within the band).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "mesh/mesh.h"

namespace sdfg {

class DistanceVolume {
 public:
  DistanceVolume() = default;
  // `dims` nodes per axis (each >= 2), `voxel` metres apart, node (0,0,0) at `origin` (the
  // volume's own frame), every node at `truncation` (> 0).
  DistanceVolume(const glm::vec3& origin, float voxel, const glm::uvec3& dims, float truncation);

  // Trilinear signed distance at `p` (volume frame); truncation() outside the grid.
  float signedDistance(const glm::vec3& p) const;
  // The same, and the closest surface point estimated one Newton step along the gradient (p when
  // no surface is within the band).
  float closest(const glm::vec3& p, glm::vec3& closest) const;

  const glm::vec3& origin() const { return origin_; }
  float voxel() const { return voxel_; }
  const glm::uvec3& dims() const { return dims_; }
  float truncation() const { return truncation_; }
  Aabb bounds() const;
  bool empty() const { return values_.empty(); }

  size_t index(uint32_t i, uint32_t j, uint32_t k) const {
    return (size_t(k) * dims_.y + j) * dims_.x + i;
  }
  glm::vec3 node(uint32_t i, uint32_t j, uint32_t k) const {
    return origin_ + voxel_ * glm::vec3(float(i), float(j), float(k));
  }
  std::span<float> values() { return values_; }
  std::span<const float> values() const { return values_; }

 private:
  glm::vec3 origin_{0.0f};
  float voxel_ = 0.0f;
  glm::uvec3 dims_{0u};
  float truncation_ = 0.0f;
  std::vector<float> values_;
};

}  // namespace sdfg
