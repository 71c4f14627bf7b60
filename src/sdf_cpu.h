// The CPU builder of the grab-box SDF: exact signed distance at every node of the box.
//
// The fallback path when no Vulkan device can be used, and the reference the GPU path is tested
// against. Work is split over a pool of worker threads owned by the builder, so repeated builds
// (one per grab, or per frame while holding) pay no thread start-up.
#pragma once

#include <memory>

#include "mesh_distance.h"
#include "pose.h"
#include "sdf_grid.h"
#include "status.h"

namespace sdfg {

class CpuSdfBuilder {
 public:
  // threads == 0: one per hardware thread.
  explicit CpuSdfBuilder(unsigned threads = 0);
  ~CpuSdfBuilder();
  CpuSdfBuilder(const CpuSdfBuilder&) = delete;
  CpuSdfBuilder& operator=(const CpuSdfBuilder&) = delete;

  // Fills `out` (resized to `box`) with the signed distance of `target` at every node.
  // `objectFromHand` places hand-space points in the mesh's space. Fails on an invalid box.
  Status build(const MeshDistance& target, const Pose& objectFromHand, const GridBox& box,
               SdfGrid& out);

 private:
  struct Pool;
  std::unique_ptr<Pool> pool_;
};

}  // namespace sdfg
