// The CPU builder of the grab-box SDF: exact signed distance at every node of the box.
//
// The fallback path when no Vulkan device can be used, and the reference the GPU path is tested
// against. Work is split over a pool of worker threads owned by the builder, so repeated builds
// (one per grab, or per frame while holding) pay no thread start-up.
//
// Optional far-field mode (CpuSdfOptions::exactBand > 0): nodes proven at least `exactBand` from
// the surface get a certified lower bound of their distance, with the exact builder's sign,
// instead of an exact query (the expensive ones: far from the surface a query visits many
// leaves). Every node closer than the band is exact. See sdf_cpu.cpp for the proofs.
#pragma once

#include <cstddef>
#include <memory>

#include "base/pose.h"
#include "base/status.h"
#include "base/work_limit.h"
#include "mesh/mesh_distance.h"
#include "sdf/sdf_grid.h"

namespace sdfg {

struct CpuSdfOptions {
  // Metres. 0: every node exact (the reference, the default). > 0: a node whose distance to the
  // surface is below exactBand holds the exact signed distance; any other node may instead hold
  // sign * b with the exact sign and exactBand <= b <= |exact distance|. The node values stay
  // 1-Lipschitz along grid edges (each axis difference at most the spacing), as exact distances
  // are. Must be finite and >= 0, else build() fails with invalid_argument. With exactBand at
  // least sqrt(3) spacings, every grid cell the surface crosses has only exact corners.
  float exactBand = 0.0f;
};

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
  // As above, with `options` (see CpuSdfOptions); the grid's exactBand() records the band.
  // `limit` is polled before every row of nodes: once reached, the build stops with timed_out
  // and `out` is left as it was.
  Status build(const MeshDistance& target, const Pose& objectFromHand, const GridBox& box,
               SdfGrid& out, const CpuSdfOptions& options, const WorkLimit& limit = {});

  // Nodes the last successful build queried exactly (all of them without a band).
  size_t lastExactNodes() const { return lastExactNodes_; }

 private:
  struct Pool;
  Status buildExact(const MeshDistance& target, const Pose& objectFromHand, const GridBox& box,
                    SdfGrid& out, const WorkLimit& limit);
  Status buildFar(const MeshDistance& target, const Pose& objectFromHand, const GridBox& box,
                  float band, SdfGrid& out, const WorkLimit& limit);
  std::unique_ptr<Pool> pool_;
  size_t lastExactNodes_ = 0;
};

}  // namespace sdfg
