// approachPose() (grasp/solver_ours.h): turns and moves the open hand onto the surface along the
// field's gradient at the palm, before the fingers close (the paper's future work).
#include "grasp/solver_ours_detail.h"

namespace sdfg {

Result<ApproachResult> approachPose(const SdfGrid& field, const HandModel& hand,
                                    const ApproachOptions& options) {
  if (!(options.tolerance > 0.0f) || !(options.angleTolerance > 0.0f) ||
      !(options.maxStep > 0.0f) || !(options.maxTurn > 0.0f) || options.maxIterations < 1 ||
      !std::isfinite(options.targetDistance) || !std::isfinite(options.maxStep) ||
      !std::isfinite(options.maxTurn) || !std::isfinite(options.tolerance)) {
    return makeError(Status::invalid_argument,
                     "approach: tolerances, steps and iterations must be finite and positive");
  }
  if (field.values().empty() || field.values().size() != field.box().nodeCount()) {
    return makeError(Status::invalid_argument, "approach: the field has no values for its box");
  }
  JointPoses joints{};
  hand.pose(FingerCurls{0.0f, 0.0f, 0.0f, 0.0f, 0.0f}, joints);
  const Pose& palm = joints[size_t(Joint::palm)];
  const glm::vec3 palmPoint = palm.position;
  const glm::vec3 palmNormal = palmFacing(palm);
  const float target = options.targetDistance >= 0.0f ? options.targetDistance
                                                      : hand.jointRadius(Joint::palm) + 0.005f;

  ApproachResult r;
  Pose& c = r.handCorrection;
  auto measure = [&](glm::vec3& p, glm::vec3& normal, float& d, glm::vec3& g) {
    p = c.transformPoint(palmPoint);
    normal = c.transformVector(palmNormal);
    d = field.sample(p);
    g = field.gradient(p);
  };
  for (; r.iterations < options.maxIterations; ++r.iterations) {
    glm::vec3 p, normal, g;
    float d;
    measure(p, normal, d, g);
    const float gl = glm::length(g);
    if (!(gl > 1e-3f) || !std::isfinite(d)) break;  // no surface direction here
    const glm::vec3 toSurface = -g / gl;
    const float angle = std::acos(std::clamp(glm::dot(normal, toSurface), -1.0f, 1.0f));
    if (std::abs(d - target) < options.tolerance && angle < options.angleTolerance) break;
    // Turn about the palm point (it stays put), then slide along the gradient.
    if (angle > 1e-6f) {
      glm::vec3 axis = glm::cross(normal, toSurface);
      if (glm::length(axis) < 1e-6f) {  // facing away: any axis across the normal
        axis = glm::cross(normal, glm::vec3(1.0f, 0.0f, 0.0f));
        if (glm::length(axis) < 1e-6f) axis = glm::cross(normal, glm::vec3(0.0f, 1.0f, 0.0f));
      }
      const glm::quat turn = glm::angleAxis(std::min(angle, options.maxTurn), glm::normalize(axis));
      c.orientation = glm::normalize(turn * c.orientation);
      c.position = turn * (c.position - p) + p;
    }
    const float move = std::clamp(d - target, -options.maxStep, options.maxStep);
    c.position += toSurface * move;
  }
  glm::vec3 p, normal, g;
  measure(p, normal, r.distance, g);
  const float gl = glm::length(g);
  r.angle = gl > 1e-3f ? std::acos(std::clamp(glm::dot(normal, -g / gl), -1.0f, 1.0f)) : 0.0f;
  r.converged = gl > 1e-3f && std::abs(r.distance - target) < options.tolerance &&
                r.angle < options.angleTolerance;
  return r;
}

}  // namespace sdfg
