// Where the grab-box SDF is built: one interface, so the CPU builder (headless and OpenGL
// sessions, and the fallback) and the Vulkan compute backend (the app's device) plug in alike.
#pragma once

#include <memory>
#include <string_view>

#include "mesh_distance.h"
#include "pose.h"
#include "sdf_grid.h"
#include "status.h"

namespace sdfg {

class SdfBackend {
 public:
  virtual ~SdfBackend() = default;
  virtual std::string_view name() const = 0;
  // Fills `out` (resized to `box`) with the signed distance of `target` at every node;
  // `objectFromHand` places hand-space points in the mesh's space. A backend that fails with
  // device_lost or unsupported lets the caller fall back to the CPU.
  virtual Status build(const MeshDistance& target, const Pose& objectFromHand, const GridBox& box,
                       SdfGrid& out) = 0;
};

// The CPU builder (CpuSdfBuilder) behind the interface; threads == 0: one per hardware thread.
std::unique_ptr<SdfBackend> makeCpuSdfBackend(unsigned threads);

}  // namespace sdfg
