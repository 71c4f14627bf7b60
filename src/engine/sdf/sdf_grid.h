// The grab box and the signed distance field sampled on it.
//
// The box is fixed to the hand (its pose is in hand space). The field holds one signed distance
// in metres per grid node; nodes sit on the box corners and are spaced evenly, so resolution N
// gives N nodes per axis and a spacing of size / (N - 1). Negative values are inside the object.
// Sampling is trilinear between nodes and clamps to the box, like a clamp-to-edge texture.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "base/pose.h"
#include "base/status.h"

namespace sdfg {

inline constexpr uint32_t kMinGridResolution = 2;
inline constexpr uint32_t kMaxGridResolution = 128;

struct GridBox {
  Pose handFromBox;                      // box centre and axes in hand space
  glm::vec3 size{0.2133f};               // edge lengths, metres
  glm::uvec3 resolution{16u, 16u, 16u};  // nodes per axis, each in [2, 128]

  // The paper's reference box: a 0.2133 m cube centred 8.1 cm in front of and 7.5 cm below
  // (toward the palm) the wrist joint, 16 nodes per axis.
  static GridBox referenceDefault();

  std::optional<Error> validate() const;

  size_t nodeCount() const { return size_t(resolution.x) * resolution.y * resolution.z; }
  glm::vec3 spacing() const { return size / (glm::vec3(resolution) - 1.0f); }
  float maxSpacing() const;

  // Box-local point (centre at 0, spanning +-size/2) of node (i, j, k).
  glm::vec3 nodeLocal(uint32_t i, uint32_t j, uint32_t k) const {
    return glm::vec3(i, j, k) * spacing() - size * 0.5f;
  }
  // Hand space -> normalized box coordinates in [0,1]^3 over the box (the paper's eq. 2, with
  // the mapping its code uses: 0 and 1 are the box faces).
  glm::vec3 handToNormalized(const glm::vec3& pHand) const {
    return handFromBox.inverse().transformPoint(pHand) / size + 0.5f;
  }
};

class SdfGrid {
 public:
  SdfGrid() = default;
  explicit SdfGrid(const GridBox& box) : box_(box), values_(box.nodeCount(), 0.0f) {}

  const GridBox& box() const { return box_; }
  std::span<float> values() { return values_; }
  std::span<const float> values() const { return values_; }

  // Node (i, j, k) is values()[i + N.x * (j + N.y * k)].
  size_t index(uint32_t i, uint32_t j, uint32_t k) const {
    return i + size_t(box_.resolution.x) * (j + size_t(box_.resolution.y) * k);
  }
  float at(uint32_t i, uint32_t j, uint32_t k) const { return values_[index(i, j, k)]; }

  // Trilinear value at normalized box coordinates (clamped to [0,1]^3).
  float sampleNormalized(const glm::vec3& uvw) const;
  // Trilinear value at a hand-space point.
  float sample(const glm::vec3& pHand) const {
    return sampleNormalized(box_.handToNormalized(pHand));
  }
  // Gradient of the trilinear interpolant at a hand-space point, in hand space (per metre).
  glm::vec3 gradient(const glm::vec3& pHand) const;

  // 0: every value is the exact signed distance. > 0 (a far-field build, CpuSdfOptions): values
  // of nodes closer to the surface than this (metres) are exact; the others may be lower bounds
  // of the distance, with the exact sign, of magnitude at least this.
  float exactBand() const { return exactBand_; }
  void setExactBand(float band) { exactBand_ = band; }

 private:
  GridBox box_;
  std::vector<float> values_;
  float exactBand_ = 0.0f;
};

}  // namespace sdfg
