// The grab-box SDF with a backend chosen at run time: the Vulkan builder when a device is given
// and works, the CPU builder otherwise, behind one submit / poll interface. When the GPU fails
// (device lost or any other Vulkan error) the request in flight is redone on the CPU and every
// later one goes there too, after the single log line VkSdfBuilder writes; nothing crashes.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "base/pose.h"
#include "base/status.h"
#include "mesh/mesh.h"
#include "mesh/mesh_distance.h"
#include "sdf/sdf_cpu.h"
#include "sdf/sdf_grid.h"
#include "vulkan/vk_sdf_builder.h"

namespace sdfg {

enum class SdfBackendKind { cpu, vulkan };

class GrabBoxSdf {
 public:
  // `device` null: CPU only. A device whose builder cannot be created also gives the CPU path
  // (VkSdfBuilder::create's error is logged through options.log). cpuThreads as CpuSdfBuilder.
  static std::unique_ptr<GrabBoxSdf> create(const VulkanDevice* device,
                                            const VkSdfOptions& options = {},
                                            unsigned cpuThreads = 0);
  ~GrabBoxSdf();

  // Errors: invalid_argument (see validateMesh), unsupported (busy).
  Status setMesh(const TriangleMesh& mesh);

  // Builds the SDF in `box` and samples `points` (normalized box coordinates). On the CPU the
  // work is done here and poll() is ready at once; on Vulkan it is submitted and poll() reports
  // it a frame later. Errors: invalid_argument (no mesh, bad box or pose), unsupported (busy).
  Status submit(const GridBox& box, const Pose& objectFromHand, std::span<const glm::vec3> points,
                bool readBackGrid = false);
  SdfPoll poll();
  SdfPoll wait(uint64_t timeoutNs);  // tests and tools only

  std::span<const float> samples() const;
  const SdfGrid* grid() const;  // when read back (always available on the CPU path)
  SdfBackendKind backend() const { return gpu_ ? SdfBackendKind::vulkan : SdfBackendKind::cpu; }
  // The Vulkan builder in use, or null (profiling, tests).
  VkSdfBuilder* vulkanBuilder() { return gpu_.get(); }
  // Test hook: the GPU path fails at its next call (see VkSdfBuilder).
  void simulateDeviceLostForTesting() {
    if (gpu_) gpu_->simulateDeviceLostForTesting();
  }

 private:
  GrabBoxSdf() = default;
  Status runOnCpu();
  void fallBack();

  std::unique_ptr<VkSdfBuilder> gpu_;
  std::unique_ptr<CpuSdfBuilder> cpu_;
  std::unique_ptr<MeshDistance> distance_;
  TriangleMesh mesh_;  // kept for a late switch to the CPU
  bool haveMesh_ = false;

  // The request in flight (redone on the CPU when the GPU fails).
  GridBox box_{};
  Pose objectFromHand_{};
  std::vector<glm::vec3> points_;
  bool cpuReady_ = false;
  SdfGrid cpuGrid_;
  std::vector<float> cpuSamples_;
};

}  // namespace sdfg
