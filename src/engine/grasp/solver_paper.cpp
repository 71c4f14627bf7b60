#include "grasp/solver_paper.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/vector_relational.hpp>

namespace sdfg {

float paperFineTune(float aPrev, float a, float d, float threshold, float backSegment) {
  if (!(backSegment > 0.0f) || !std::isfinite(backSegment)) return a;
  const float alpha = a + (d - threshold) / backSegment * (a - aPrev);
  // d < threshold makes the correction negative; the clamp keeps the finger between the last
  // free sample and the touching one (a NaN correction leaves it on the touching sample).
  if (!(alpha >= aPrev)) return std::isnan(alpha) ? a : aPrev;
  return std::min(alpha, a);
}

PaperFingerStop paperSolveFinger(const SdfGrid& field, std::span<const glm::vec3> uvw,
                                 std::span<const float> params, std::span<const float> backSegments,
                                 float threshold) {
  PaperFingerStop stop;
  const size_t count = std::min({uvw.size(), params.size(), backSegments.size()});
  for (size_t k = 0; k < count; ++k) {
    const float d = field.sampleNormalized(uvw[k]);
    stop.distance = d;
    stop.sample = uint32_t(k);
    if (d < threshold) {
      stop.contact = true;
      // Already touching in the open pose: there is no segment to pull back along.
      stop.curl = k == 0 ? params[0]
                         : paperFineTune(params[k - 1], params[k], d, threshold, backSegments[k]);
      return stop;
    }
  }
  stop.curl = 1.0f;  // the last sample, a = 1, was tested and is free
  return stop;
}

Status PaperSolver::prepare(const HandModel& hand, const GridBox& box,
                            const SolverOptions& options) {
  prepared_ = false;
  error_.clear();
  params_.clear();
  uvw_.clear();
  handTips_.clear();
  backSegments_.clear();
  auto fail = [this](Error error) {
    error_ = "paper: " + error.message;
    return error.code;
  };
  if (auto error = validateSolverOptions(options)) return fail(*error);
  if (auto error = box.validate()) return fail(*error);

  params_ = HandModel::curveParameters(options.da);
  if (params_.empty() || params_.front() != 0.0f || params_.back() != 1.0f) {
    return fail(makeError(Status::internal, "hand model: curveParameters() does not span [0, 1]"));
  }
  const size_t perFinger = params_.size();
  uvw_.reserve(perFinger * kFingerCount);
  handTips_.reserve(perFinger * kFingerCount);
  backSegments_.reserve(perFinger * kFingerCount);
  for (int f = 0; f < kFingerCount; ++f) {
    const Finger finger = Finger(f);
    const std::vector<glm::vec3> curve = hand.tipCurve(finger, options.da);
    if (curve.size() != perFinger) {
      return fail(makeError(Status::internal, std::string("hand model: tip curve of the ") +
                                                  fingerName(finger) +
                                                  " has the wrong sample count"));
    }
    for (size_t k = 0; k < perFinger; ++k) {
      const glm::vec3& p = curve[k];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        return fail(makeError(Status::invalid_argument,
                              std::string("hand model: tip curve of the ") + fingerName(finger) +
                                  " is not finite at sample " + std::to_string(k)));
      }
      handTips_.push_back(p);
      uvw_.push_back(box.handToNormalized(p));
      backSegments_.push_back(k == 0 ? 0.0f : glm::distance(p, curve[k - 1]));
    }
    threshold_[f] = options.threshold >= 0.0f ? options.threshold : hand.tipRadius(finger);
  }
  hand_ = hand;
  box_ = box;
  prepared_ = true;
  return Status::ok;
}

std::span<const glm::vec3> PaperSolver::normalizedSamples(Finger finger) const {
  if (!prepared_) return {};
  const size_t perFinger = params_.size();
  return std::span<const glm::vec3>(uvw_).subspan(size_t(finger) * perFinger, perFinger);
}

namespace {

bool sameBox(const GridBox& a, const GridBox& b) {
  return a.size == b.size && a.handFromBox.position == b.handFromBox.position &&
         a.handFromBox.orientation == b.handFromBox.orientation;
}

}  // namespace

Status PaperSolver::solve(const GraspScene& scene, GraspResult& out) const {
  if (!prepared_ || scene.field == nullptr) return Status::invalid_argument;
  const SdfGrid& field = *scene.field;
  // The cache is in this box's coordinates; a field on another box would be read elsewhere.
  const glm::uvec3 n = field.box().resolution;
  if (!sameBox(field.box(), box_) || glm::any(glm::lessThan(n, glm::uvec3(kMinGridResolution))) ||
      glm::any(glm::greaterThan(n, glm::uvec3(kMaxGridResolution))) ||
      field.values().size() != field.box().nodeCount()) {
    return Status::invalid_argument;
  }
  const size_t perFinger = params_.size();
  const std::span<const float> params(params_);
  for (int f = 0; f < kFingerCount; ++f) {
    const size_t first = size_t(f) * perFinger;
    const PaperFingerStop stop = paperSolveFinger(
        field, std::span<const glm::vec3>(uvw_).subspan(first, perFinger), params,
        std::span<const float>(backSegments_).subspan(first, perFinger), threshold_[f]);
    FingerState& state = out.fingers[f];
    state.curl = stop.curl;
    state.jointCurls.fill(stop.curl);
    state.contact = stop.contact;
    state.distance = stop.distance;
    if (stop.contact) {
      state.contactBone = int(fingerJoints(Finger(f)).size()) - 2;  // the tip
      state.contactT = 1.0f;
    }
    // On a sample the cached point is exact; between samples the tip is where FK puts it.
    state.contactPoint = stop.curl == params_[stop.sample]
                             ? handTips_[first + stop.sample]
                             : hand_.tipPosition(Finger(f), stop.curl);
  }
  return Status::ok;
}

}  // namespace sdfg
