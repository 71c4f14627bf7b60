#include "scene/scene_field.h"

#include <algorithm>
#include <limits>

namespace sdfg {

namespace {

// Merges `distance` (a signed distance of points in the member's frame) into `field` by the
// minimum, the member placed by objectFromHand.
template <class Distance>
void mergeIntoField(const Pose& objectFromHand, SdfGrid& field, const Distance& distance) {
  const GridBox& box = field.box();
  const Pose objectFromBox = objectFromHand * box.handFromBox;
  std::span<float> values = field.values();
  for (uint32_t k = 0; k < box.resolution.z; ++k) {
    for (uint32_t j = 0; j < box.resolution.y; ++j) {
      for (uint32_t i = 0; i < box.resolution.x; ++i) {
        const glm::vec3 p = objectFromBox.transformPoint(box.nodeLocal(i, j, k));
        float& v = values[field.index(i, j, k)];
        v = std::min(v, distance(p));
      }
    }
  }
}

}  // namespace

void mergeShapeIntoField(const AnalyticShape& shape, const Pose& objectFromHand, SdfGrid& field) {
  mergeIntoField(objectFromHand, field,
                 [&](const glm::vec3& p) { return shape.signedDistance(p); });
}

void mergeVolumeIntoField(const DistanceVolume& volume, const Pose& objectFromHand,
                          SdfGrid& field) {
  mergeIntoField(objectFromHand, field,
                 [&](const glm::vec3& p) { return volume.signedDistance(p); });
}

Status buildSceneField(std::span<const SceneMember> members, const GridBox& box,
                       SdfBackend& backend, SdfGrid& out, SdfGrid& scratch,
                       const WorkLimit& limit) {
  if (members.empty()) return Status::invalid_argument;
  if (box.validate()) return Status::invalid_argument;
  bool first = true;
  float band = 0.0f;
  // Meshes first: the first one builds straight into `out`, the rest into `scratch`.
  for (const SceneMember& m : members) {
    if (m.mesh == nullptr) continue;
    SdfGrid& target = first ? out : scratch;
    if (Status s = backend.build(*m.mesh, m.objectFromHand, box, target, limit); s != Status::ok)
      return s;
    band = std::max(band, target.exactBand());
    if (!first) {
      std::span<float> dst = out.values();
      std::span<const float> src = scratch.values();
      for (size_t n = 0; n < dst.size(); ++n) dst[n] = std::min(dst[n], src[n]);
    }
    first = false;
  }
  if (first) {
    out = SdfGrid(box);
    std::fill(out.values().begin(), out.values().end(), std::numeric_limits<float>::infinity());
  }
  for (const SceneMember& m : members) {
    if (m.shape == nullptr && m.volume == nullptr) continue;
    if (limit.reached()) return Status::timed_out;
    if (m.shape != nullptr)
      mergeShapeIntoField(*m.shape, m.objectFromHand, out);
    else
      mergeVolumeIntoField(*m.volume, m.objectFromHand, out);
  }
  out.setExactBand(band);
  return Status::ok;
}

}  // namespace sdfg
