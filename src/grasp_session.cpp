#include "grasp_session.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sdf_cpu.h"

namespace sdfg {
namespace {

class CpuBackend final : public SdfBackend {
 public:
  explicit CpuBackend(unsigned threads) : builder_(threads) {}
  std::string_view name() const override { return "cpu"; }
  Status build(const MeshDistance& target, const Pose& objectFromHand, const GridBox& box,
               SdfGrid& out) override {
    return builder_.build(target, objectFromHand, box, out);
  }

 private:
  CpuSdfBuilder builder_;
};

float angleBetween(const glm::quat& a, const glm::quat& b) {
  const float d = std::min(1.0f, std::abs(glm::dot(a, b)));
  return 2.0f * std::acos(d);
}

}  // namespace

std::unique_ptr<SdfBackend> makeCpuSdfBackend(unsigned threads) {
  return std::make_unique<CpuBackend>(threads);
}

std::optional<Error> GraspSettings::validate() const {
  if (auto e = box.validate()) return e;
  if (!(grabThreshold > 0.0f && grabThreshold <= 1.0f))
    return makeError(Status::invalid_argument, "grasp settings: grabThreshold must be in (0, 1]");
  if (!(releaseRatio >= 0.0f && releaseRatio <= 1.0f))
    return makeError(Status::invalid_argument, "grasp settings: releaseRatio must be in [0, 1]");
  if (!(moveTolerance >= 0.0f) || !(turnTolerance >= 0.0f))
    return makeError(Status::invalid_argument, "grasp settings: tolerances must be >= 0");
  return std::nullopt;
}

GraspSession::GraspSession(std::unique_ptr<SdfBackend> backend) : backend_(std::move(backend)) {
  hands_[0].model = HandModel::defaultAdult(Hand::left);
  hands_[1].model = HandModel::defaultAdult(Hand::right);
  (void)configure(settings_);
}

GraspSession::~GraspSession() = default;

Status GraspSession::configure(const GraspSettings& settings) {
  if (settings.validate()) return Status::invalid_argument;
  std::array<std::unique_ptr<GraspSolver>, 2> solvers;
  for (auto& s : solvers) {
    auto made = createSolver(settings.solver);
    if (!made) return made.error().code;
    if (!(*made)->needsField() || (*made)->needsCollider()) return Status::unsupported;
    s = std::move(*made);
  }
  settings_ = settings;
  for (size_t h = 0; h < 2; ++h) {
    hands_[h].solver = std::move(solvers[h]);
    hands_[h].prepared = false;
  }
  return Status::ok;
}

Status GraspSession::addTarget(uint64_t id, const TriangleMesh& mesh) {
  if (targets_.count(id) != 0) return Status::invalid_argument;
  auto distance = MeshDistance::create(mesh);
  if (!distance) return distance.error().code;
  Target t;
  t.bounds = computeBounds(mesh.positions);
  t.distance = std::move(*distance);
  targets_.emplace(id, std::move(t));
  return Status::ok;
}

Status GraspSession::updateTargetVertices(uint64_t id, std::span<const glm::vec3> positions) {
  auto it = targets_.find(id);
  if (it == targets_.end()) return Status::invalid_argument;
  if (Status s = it->second.distance->updatePositions(positions); s != Status::ok) return s;
  it->second.bounds = computeBounds(positions);
  ++it->second.version;
  return Status::ok;
}

bool GraspSession::removeTarget(uint64_t id) {
  for (HandState& h : hands_) {
    if (h.grasp.holding && h.grasp.target == id) h.grasp = HandGrasp{};
  }
  return targets_.erase(id) != 0;
}

void GraspSession::release(Hand hand) {
  hands_[size_t(hand)].grasp = HandGrasp{};
}

std::optional<uint64_t> GraspSession::pickTarget(const Pose& worldFromWrist,
                                                 std::span<const TargetFrame> targets) const {
  const GridBox& box = settings_.box;
  const Pose boxFromWorld = (worldFromWrist * box.handFromBox).inverse();
  const glm::vec3 half = box.size * 0.5f;
  std::optional<uint64_t> best;
  float bestDistance = std::numeric_limits<float>::infinity();
  for (const TargetFrame& t : targets) {
    auto it = targets_.find(t.id);
    if (!t.valid || it == targets_.end()) continue;
    const Pose boxFromObject = boxFromWorld * t.worldFromObject;
    // The target's bounds, as a box-space AABB of its 8 corners, must overlap the grab box.
    glm::vec3 lo(std::numeric_limits<float>::infinity()), hi(-lo);
    for (int c = 0; c < 8; ++c) {
      const glm::vec3 corner((c & 1) ? it->second.bounds.max.x : it->second.bounds.min.x,
                             (c & 2) ? it->second.bounds.max.y : it->second.bounds.min.y,
                             (c & 4) ? it->second.bounds.max.z : it->second.bounds.min.z);
      const glm::vec3 p = boxFromObject.transformPoint(corner);
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
    if (glm::any(glm::greaterThan(lo, half)) || glm::any(glm::lessThan(hi, -half))) continue;
    const float d = glm::length(boxFromObject.transformPoint(it->second.bounds.center()));
    if (d < bestDistance) bestDistance = d, best = t.id;
  }
  return best;
}

Status GraspSession::solve(HandState& hand, const Target& target, const Pose& objectFromHand) {
  if (!hand.prepared) {
    if (Status s = hand.solver->prepare(hand.model, settings_.box, settings_.solverOptions);
        s != Status::ok)
      return s;
    hand.prepared = true;
  }
  if (Status s = backend_->build(*target.distance, objectFromHand, settings_.box, hand.grid);
      s != Status::ok)
    return s;
  GraspScene scene;
  scene.field = &hand.grid;
  scene.objectFromHand = objectFromHand;
  GraspResult result;
  if (Status s = hand.solver->solve(scene, result); s != Status::ok) return s;
  hand.grasp.result = result;
  hand.grasp.objectFromHand = objectFromHand;
  hand.solvedVersion = target.version;
  ++hand.grasp.solves;
  return Status::ok;
}

Status GraspSession::update(Hand side, const HandFrame& frame,
                            std::span<const TargetFrame> targets) {
  HandState& hand = hands_[size_t(side)];
  hand.squeeze = std::isfinite(frame.squeeze) ? frame.squeeze : 0.0f;
  if (hand.grasp.holding) {
    auto it = targets_.find(hand.grasp.target);
    if (it == targets_.end() || hand.squeeze < settings_.grabThreshold * settings_.releaseRatio) {
      hand.grasp = HandGrasp{};
      return Status::ok;
    }
    const TargetFrame* located = nullptr;
    for (const TargetFrame& t : targets) {
      if (t.id == hand.grasp.target && t.valid) located = &t;
    }
    if (!frame.valid || located == nullptr) return Status::ok;  // keep the last solve
    const Pose objectFromHand = located->worldFromObject.inverse() * frame.worldFromWrist;
    const bool moved =
        glm::length(objectFromHand.position - hand.grasp.objectFromHand.position) >
            settings_.moveTolerance ||
        angleBetween(objectFromHand.orientation, hand.grasp.objectFromHand.orientation) >
            settings_.turnTolerance;
    if (!moved && hand.solvedVersion == it->second.version) return Status::ok;
    const Status s = solve(hand, it->second, objectFromHand);
    if (s != Status::ok) hand.grasp = HandGrasp{};
    return s;
  }

  if (!frame.valid || hand.squeeze < settings_.grabThreshold) return Status::ok;
  const std::optional<uint64_t> id = pickTarget(frame.worldFromWrist, targets);
  if (!id) return Status::ok;
  const Target& target = targets_.at(*id);
  const TargetFrame* located = nullptr;
  for (const TargetFrame& t : targets) {
    if (t.id == *id) located = &t;
  }
  // A tracked hand brings its own bone lengths: fit the model to it at the start of the grab.
  if (frame.trackedJoints != nullptr && frame.trackedRadii != nullptr) {
    auto fitted = HandModel::fitToJoints(side, *frame.trackedJoints, *frame.trackedRadii);
    if (fitted) {
      hand.model = std::move(*fitted);
      hand.prepared = false;
    }
  }
  hand.grasp = HandGrasp{};
  hand.grasp.holding = true;
  hand.grasp.target = *id;
  const Status s = solve(hand, target, located->worldFromObject.inverse() * frame.worldFromWrist);
  if (s != Status::ok) hand.grasp = HandGrasp{};
  return s;
}

}  // namespace sdfg
