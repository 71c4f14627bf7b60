#include "state.h"

#include <cmath>

namespace sdfg::layer {

uint64_t newLayerHandle() {
  static std::atomic<uint64_t> counter{0};
  return (uint64_t{0x5DF6} << 48) | ++counter;
}

HandleMap<InstanceState>& instances() {
  static HandleMap<InstanceState> map;
  return map;
}
HandleMap<SessionState>& sessions() {
  static HandleMap<SessionState> map;
  return map;
}
HandleMap<TrackerState>& trackers() {
  static HandleMap<TrackerState> map;
  return map;
}
HandleMap<TargetState>& targets() {
  static HandleMap<TargetState> map;
  return map;
}
HandleMap<SessionState>& spaceOwners() {
  static HandleMap<SessionState> map;
  return map;
}

HandleMap<SwapchainState>& swapchains() {
  static HandleMap<SwapchainState> map;
  return map;
}

XrResult toXrResult(Status status) {
  switch (status) {
    case Status::ok:
      return XR_SUCCESS;
    case Status::invalid_argument:
      return XR_ERROR_VALIDATION_FAILURE;
    case Status::unsupported:
      return XR_ERROR_FEATURE_UNSUPPORTED;
    case Status::out_of_memory:
      return XR_ERROR_OUT_OF_MEMORY;
    case Status::io_error:
    case Status::device_lost:
    case Status::timed_out:
    case Status::internal:
      break;
  }
  return XR_ERROR_RUNTIME_FAILURE;
}

Pose toPose(const XrPosef& p) {
  return Pose{glm::quat(p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z),
              glm::vec3(p.position.x, p.position.y, p.position.z)};
}

XrPosef toXr(const Pose& p) {
  XrPosef out;
  out.orientation = {p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w};
  out.position = {p.position.x, p.position.y, p.position.z};
  return out;
}

bool isFinitePose(const XrPosef& p) {
  const float v[7] = {p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w,
                      p.position.x,    p.position.y,    p.position.z};
  for (float f : v) {
    if (!std::isfinite(f)) return false;
  }
  return true;
}

bool isUnitQuaternion(const XrQuaternionf& q) {
  const float n = q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w;
  return std::isfinite(n) && std::abs(n - 1.0f) < 1e-3f;
}

std::string resolveSolverName(const std::string& name) {
  if (name != "default") return name;
  for (const std::string& n : solverNames()) {
    if (n == "ours") return n;
  }
  return "paper";
}

GraspSettings settingsFromConfig(const Config& config) {
  GraspSettings s;
  s.solver = resolveSolverName(config.solver);
  s.solverOptions.da = config.curlStep;
  s.exactCheck = config.exactCheck;
  s.buildTimeLimit = std::chrono::milliseconds(config.buildTimeLimitMs);
  s.box.resolution = glm::uvec3(config.resolution);
  s.grabThreshold = config.grabThreshold;
  s.releaseRatio = config.releaseRatio;
  s.solverOptions.clearance = config.clearHand;
  s.solverOptions.clearanceBound = config.clearBound;
  s.solverOptions.approach = config.approach;
  s.solverOptions.approachRange = config.approachRange;
  s.solverOptions.approachMaxAngle = config.approachMaxAngle * 3.14159265f / 180.0f;
  s.outerHand = config.outerHand;
  s.outerOptions.releaseDistance = config.outerReleaseDistance;
  s.outerOptions.blendTime = config.outerBlendTime;
  return s;
}

}  // namespace sdfg::layer
