// GraspSession's depth scene: the frames of the app's depth handed to the worker with where the
// hands are, and the volumes it fused taken in as the depth targets' versions and bounds.
#include <cmath>

#include "grasp/grasp_session.h"
#include "hand/hand_synthesis.h"

namespace sdfg {
namespace {

// The hand as the app draws it, as far as the session knows at its last update: the model at the
// wrist, closed as its grasp shows it or as the squeeze closes it.
void appendHandSpheres(const HandModel& model, const Pose& worldFromWrist, const HandGrasp& grasp,
                       float squeeze, std::vector<DepthExclusion>& out) {
  FingerCurls curls = curlsFromSqueeze(squeeze, MotionRange::unobstructed);
  Pose drawn = worldFromWrist;
  if (grasp.shown()) {
    for (int f = 0; f < kFingerCount; ++f) curls[size_t(f)] = grasp.result.fingers[size_t(f)].curl;
    drawn = worldFromWrist * grasp.result.handCorrection;
  }
  JointPoses joints;
  model.pose(curls, joints);
  for (int j = 0; j < kJointCount; ++j)
    out.push_back({drawn.transformPoint(joints[size_t(j)].position), model.jointRadius(Joint(j))});
}

}  // namespace

Status GraspSession::enableDepthScene(const DepthFusionOptions& options) {
  if (depthOn_ || options.validate()) return Status::invalid_argument;
  const std::array<uint64_t, 2> ids{depthTarget(Hand::left), depthTarget(Hand::right)};
  for (uint64_t id : ids)
    if (targets_.count(id) != 0) return Status::invalid_argument;
  if (Status s = worker_->enableDepth(ids, options); s != Status::ok) return s;
  for (uint64_t id : ids) {
    Target t;
    t.volumeTarget = true;
    t.space = kDepthWorldSpace;
    targets_.emplace(id, std::move(t));  // placed once a frame is fused (collectDepth)
  }
  depthOn_ = true;
  depthBoxSize_ = options.size;
  return Status::ok;
}

std::array<std::optional<GraspSession::DepthBox>, 2> GraspSession::depthBoxes() const {
  std::array<std::optional<DepthBox>, 2> out;
  for (size_t slot = 0; slot < 2; ++slot) {
    const HandState& hand = hands_[slot];
    if (!hand.lastWrist) continue;
    // The same centre submitDepth() fuses around; recentre() rounds it by half a voxel at most.
    const glm::vec3 c = (*hand.lastWrist * settings_.box.handFromBox).position;
    const glm::vec3 half(0.5f * depthBoxSize_);
    out[slot] = DepthBox{c - half, c + half};
  }
  return out;
}

Status GraspSession::submitDepth(std::vector<DepthView> views,
                                 std::vector<std::vector<float>> depth, double time) {
  if (!depthOn_) return Status::unsupported;
  if (views.size() != depth.size() || !std::isfinite(time)) return Status::invalid_argument;
  for (size_t v = 0; v < views.size(); ++v) {
    if (views[v].validate() || depth[v].size() != size_t(views[v].width) * size_t(views[v].height))
      return Status::invalid_argument;
  }
  GraspWorker::DepthJob job;
  job.views = std::move(views);
  job.depth = std::move(depth);
  job.time = time;
  for (size_t slot = 0; slot < 2; ++slot) {
    const HandState& hand = hands_[slot];
    if (!hand.lastWrist) continue;
    job.centres[slot] = (*hand.lastWrist * settings_.box.handFromBox).position;
    appendHandSpheres(hand.model, *hand.lastWrist, hand.grasp, hand.squeeze, job.hands);
    // Where the outer hand last showed it too, when that was elsewhere.
    const OuterView& outer = hand.outer.view;
    if (outer.active && outer.fallback.changes)
      appendHandSpheres(hand.model, *hand.lastWrist * outer.fallback.offset, hand.grasp,
                        hand.squeeze, job.hands);
  }
  worker_->requestDepth(std::move(job));
  return Status::ok;
}

void GraspSession::collectDepth() {
  if (!depthOn_) return;
  const auto fused = worker_->takeDepth();
  if (!fused) return;
  for (size_t slot = 0; slot < 2; ++slot) {
    const GraspWorker::DepthDone& d = (*fused)[slot];
    if (!d.valid) continue;
    depthDone_[slot] = d;
    const uint64_t id = depthTarget(Hand(slot));
    auto it = targets_.find(id);
    if (it == targets_.end()) continue;
    Target& t = it->second;
    t.version = d.version;
    t.bounds = d.bounds;
    t.placed = true;
    reindex(id, t);
  }
}

}  // namespace sdfg
