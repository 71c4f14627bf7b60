// A scene's grasps solved as the layer solves an app's buffer targets: through a GraspSession
// whose deferred backend is a VkGraspBackend on a Vulkan device (one of our own, vk_standalone.h;
// VK_ICD_FILENAMES picks the driver), every mesh object a buffer target whose vertices and
// indices exist only in host-visible buffers on that device (as XrGraspTargetVulkanBuffersSDFG
// describes them), scene geometry as analytic shape targets. The session reads each buffer
// target back (grasp_session_readback.cpp), sets it up on its worker, builds the grab-box field
// on the device and checks the stops on the copy; nothing here hands it a CPU mesh.
//
// measureScene() (eval/scene_quality.h) grades what this returns exactly as it grades its own
// solves, so a scene's figures with buffer targets stand beside the same scene's with CPU meshes.
// Each placement is one grab, as a user makes it: the squeeze at the placement until the session
// shows the grasp, then a release.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "base/status.h"
#include "eval/scene_quality.h"

namespace sdfg {

class StandaloneVulkan;

// Which of a scene's meshes go into the device's buffers; the others are CPU meshes (arrays).
enum class BufferTargets {
  everyMesh,
  reachedFor,  // only the object the placements are drawn on: a buffer target beside CPU meshes
};

class BufferSceneSolver {
 public:
  // Creates the device. `validation`: with the Khronos validation layer, whose messages are
  // counted (validationMessages()). Errors: unsupported (no Vulkan device, or no validation layer
  // when asked for).
  static Result<std::unique_ptr<BufferSceneSolver>> create(bool validation = false);
  ~BufferSceneSolver();
  BufferSceneSolver(const BufferSceneSolver&) = delete;
  BufferSceneSolver& operator=(const BufferSceneSolver&) = delete;

  // Solves every placement of `scene` with the settings of `run` (method "ours": its solver
  // options, exact check and grab box), a session of its own per call. Errors: a device or
  // session failure, a target the session did not set up, or a grasp not shown within 20 s
  // (named, with the placement).
  Result<std::vector<SceneSolve>> solve(const BenchScene& scene,
                                        std::span<const Placement> placements, const SceneRun& run,
                                        BufferTargets which = BufferTargets::everyMesh);
  // SceneRun::solves for `run`: this solver's solve() (it must outlive the run).
  SceneSolves solves(const SceneRun& run, BufferTargets which = BufferTargets::everyMesh);

  const std::string& deviceName() const;
  uint32_t validationMessages() const;
  // Of the grasps solved so far: how many were shown from a field the device built.
  uint64_t gpuGrasps() const { return gpuGrasps_; }
  uint64_t grasps() const { return grasps_; }

 private:
  BufferSceneSolver() = default;
  std::unique_ptr<StandaloneVulkan> vulkan_;
  uint64_t grasps_ = 0;
  uint64_t gpuGrasps_ = 0;
};

}  // namespace sdfg
