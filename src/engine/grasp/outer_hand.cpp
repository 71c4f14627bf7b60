#include "grasp/outer_hand.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <span>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

namespace sdfg {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
// Parts within this of the margin constrain a sliding step.
constexpr float kActiveBand = 0.004f;  // metres
// A finger stops once its closest sphere is within this above the margin.
constexpr float kContactTolerance = 0.0003f;  // metres
// A turn costs as much as the motion it gives this far from the pivot (about half a hand).
constexpr float kLever = 0.1f;  // metres
constexpr int kDualSweeps = 100;
constexpr int kMaxFingerSteps = 64;
constexpr float kMinCurlStep = 1e-4f;
// A finger freed from inside stops trying a way once it is this much deeper than its best.
constexpr float kWrongWay = 0.002f;  // metres
// Finger spheres whose clearance bound is this far above a contact are not searched again.
constexpr float kFingerSlack = 0.003f;  // metres
// Spheres along a finger's bones are at most this many of the smaller joint radius apart.
constexpr float kFingerSpacing = 0.7f;
// How far a free hand's clearance is searched (OuterHandResult::clearance): a hand moves 2.2 cm
// in a frame at 2 m/s and 90 Hz.
constexpr float kFreeReach = 0.025f;  // metres
// How far the check for a released hand's coming out searches (a hand let go can be deep inside).
constexpr float kReleasedReach = 1.0f;  // metres

// The finger a part's bone belongs to, or -1 for the palm's sphere.
int fingerOf(Joint joint) {
  const int j = int(joint);
  if (j < int(Joint::thumb_metacarpal)) return -1;
  if (j <= int(Joint::thumb_tip)) return 0;
  return 1 + (j - int(Joint::index_metacarpal)) / 5;
}

bool isMetacarpal(Joint joint) {
  return joint == Joint::thumb_metacarpal || joint == Joint::index_metacarpal ||
         joint == Joint::middle_metacarpal || joint == Joint::ring_metacarpal ||
         joint == Joint::little_metacarpal;
}

bool finitePose(const Pose& p) {
  const glm::quat& q = p.orientation;
  return std::isfinite(p.position.x) && std::isfinite(p.position.y) &&
         std::isfinite(p.position.z) && std::isfinite(q.w) && std::isfinite(q.x) &&
         std::isfinite(q.y) && std::isfinite(q.z);
}

// The rotation vector of a unit quaternion (shortest way).
glm::vec3 rotationVector(glm::quat q) {
  if (q.w < 0.0f) q = -q;
  const glm::vec3 v(q.x, q.y, q.z);
  const float s = glm::length(v);
  if (s < 1e-9f) return glm::vec3(0.0f);
  return v * (2.0f * std::atan2(s, q.w) / s);
}

// A rigid motion of translation t and turn w (rotation vector) about the world point `pivot`,
// applied after `pose`.
Pose moved(const Pose& pose, const glm::vec3& pivot, const glm::vec3& t, const glm::vec3& w) {
  const float angle = glm::length(w);
  const glm::quat r = angle > 1e-9f ? glm::angleAxis(angle, w / angle) : glm::quat(1, 0, 0, 0);
  return Pose{glm::normalize(r * pose.orientation), r * (pose.position - pivot) + pivot + t};
}

// Exact clearances of spheres (world centres, radii to keep clear). Keeps, per sphere, a lower
// bound of its clearance: the exact distance changes by at most the centre's motion, so a sphere
// whose bound stays above what a caller asks about is not searched again (most of a hand is far
// from any surface while a few parts touch).
class Probe {
 public:
  explicit Probe(const ExactDistanceSource& source) : source_(source) {}

  // Sizes the tables for `n` spheres and forgets every bound.
  void reset(size_t n) {
    bound.assign(n, -kInf);
    clearance.assign(n, kInf);
    gradient.assign(n, glm::vec3(0.0f));
    fresh.assign(n, 0);
    hints_.assign(n, std::numeric_limits<uint32_t>::max());
  }
  // Every bound drops by the motion of its sphere (moves[i], metres).
  void moved(std::span<const float> motions) {
    for (size_t i = 0; i < bound.size(); ++i) bound[i] -= motions[i], fresh[i] = 0;
  }
  // Searches, within `reach` beyond its radius, every sphere whose bound is below `below`; sets
  // its clearance (distance - radius, or `reach` when nothing is that close and it is not known
  // to be inside), gradient (unit, zero when nothing was found) and bound. Returns the smallest
  // bound over all spheres.
  float operator()(std::span<const glm::vec3> centres, std::span<const float> radii, float reach,
                   float below) {
    asked_.clear(), points_.clear(), bounds_.clear(), found_.clear();
    for (size_t i = 0; i < centres.size(); ++i) {
      if (bound[i] >= below) continue;
      asked_.push_back(i);
      points_.push_back(centres[i]);
      bounds_.push_back(radii[i] + reach);
      ExactSample s;
      s.feature = hints_[i];
      found_.push_back(s);
    }
    if (!asked_.empty()) source_.sample(points_, bounds_, found_);
    samples += int(asked_.size());
    for (size_t k = 0; k < asked_.size(); ++k) {
      const size_t i = asked_[k];
      const ExactSample& s = found_[k];
      hints_[i] = s.feature;
      gradient[i] = glm::vec3(0.0f);
      fresh[i] = 1;
      if (!std::isfinite(s.distance)) {
        clearance[i] = reach;
      } else {
        clearance[i] = s.distance - radii[i];
        if (std::abs(s.distance) > 1e-7f) {
          const glm::vec3 g = (centres[i] - s.closest) / s.distance;
          const float gl = glm::length(g);
          if (gl > 1e-3f) gradient[i] = g / gl;
        }
      }
      bound[i] = clearance[i];
    }
    float lowest = kInf;
    for (float b : bound) lowest = std::min(lowest, b);
    return lowest;
  }

  std::vector<float> bound;         // lower bound of each sphere's clearance, metres
  std::vector<float> clearance;     // its last searched clearance
  std::vector<glm::vec3> gradient;  // and distance gradient
  std::vector<char> fresh;          // searched since the last motion
  int samples = 0;

 private:
  const ExactDistanceSource& source_;
  std::vector<size_t> asked_;
  std::vector<glm::vec3> points_;
  std::vector<float> bounds_;
  std::vector<ExactSample> found_;
  std::vector<uint32_t> hints_;
};

struct RigidParts {
  std::vector<glm::vec3> local;  // wrist frame
  std::vector<float> radius;     // cover radius
};

// Moves the rigid hand from `from` toward `goal` without any part crossing a surface; returns
// where it ends. `pivotLocal`: the palm, wrist frame.
Pose slide(const RigidParts& parts, const glm::vec3& pivotLocal, const Pose& from, const Pose& goal,
           const ExactDistanceSource& source, const OuterHandOptions& o, int& samples) {
  const size_t n = parts.local.size();
  if (n == 0) return goal;
  Probe probe(source);
  probe.reset(n);
  std::vector<glm::vec3> world(n), check(n);
  std::vector<float> motion(n);
  std::vector<std::array<float, 6>> rows;
  std::vector<float> b, lambda, norm2;
  // Parts this far beyond the active band are left to their bounds.
  constexpr float kSlack = 0.002f;
  Pose pose = from;
  for (int it = 0; it < o.maxIterations; ++it) {
    const glm::vec3 pivot = pose.transformPoint(pivotLocal);
    const glm::vec3 tGoal = goal.transformPoint(pivotLocal) - pivot;
    const glm::vec3 wGoal = rotationVector(goal.orientation * glm::conjugate(pose.orientation));
    // The most any part moves on the way to the goal from here.
    float farthest = 0.0f;
    for (size_t i = 0; i < n; ++i) {
      world[i] = pose.transformPoint(parts.local[i]);
      farthest = std::max(farthest,
                          glm::length(tGoal) + glm::length(wGoal) * glm::length(world[i] - pivot));
    }
    if (farthest < 1e-6f) {
      pose = goal;
      break;
    }
    // The first search reaches as far as the motion; later ones only parts near a surface.
    const float reach = farthest + o.margin + kActiveBand;
    const float lowest =
        probe(world, parts.radius, reach, it == 0 ? kInf : o.margin + kActiveBand + kSlack);
    // Free all the way (nothing within the motion): the goal itself.
    if (lowest > farthest + o.margin) {
      pose = goal;
      break;
    }
    // The constrained step: z = (t, kLever * w) nearest the goal's, every part within the band
    // kept at the margin on its linearised distance. Dual projected Gauss-Seidel.
    const std::array<float, 6> zGoal{tGoal.x,          tGoal.y,          tGoal.z,
                                     kLever * wGoal.x, kLever * wGoal.y, kLever * wGoal.z};
    rows.clear(), b.clear(), norm2.clear();
    for (size_t i = 0; i < n; ++i) {
      const glm::vec3 g = probe.gradient[i];
      if (!probe.fresh[i] || !(probe.clearance[i] < o.margin + kActiveBand) ||
          glm::dot(g, g) < 0.25f)
        continue;
      const glm::vec3 arm = glm::cross(world[i] - pivot, g) / kLever;
      rows.push_back({g.x, g.y, g.z, arm.x, arm.y, arm.z});
      float aa = 0.0f;
      for (float v : rows.back()) aa += v * v;
      norm2.push_back(aa);
      b.push_back(o.margin - probe.clearance[i]);
    }
    std::array<float, 6> z = zGoal;
    lambda.assign(rows.size(), 0.0f);
    for (int sweep = 0; sweep < kDualSweeps && !rows.empty(); ++sweep) {
      float change = 0.0f;
      for (size_t k = 0; k < rows.size(); ++k) {
        float az = 0.0f;
        for (int v = 0; v < 6; ++v) az += rows[k][v] * z[v];
        const float l = std::max(0.0f, lambda[k] + (b[k] - az) / norm2[k]);
        const float d = l - lambda[k];
        if (d == 0.0f) continue;
        lambda[k] = l;
        for (int v = 0; v < 6; ++v) z[v] += d * rows[k][v];
        change = std::max(change, std::abs(d));
      }
      if (change < 1e-8f) break;
    }
    const glm::vec3 t(z[0], z[1], z[2]), w = glm::vec3(z[3], z[4], z[5]) / kLever;
    // No step may carry a part farther than its distance to any surface not in the active set
    // (it could be a thin plate the linearisation cannot see), nor a constrained one by more
    // than its band.
    float s = 1.0f;
    for (size_t i = 0; i < n; ++i) {
      motion[i] = glm::length(t) + glm::length(w) * glm::length(world[i] - pivot);
      if (motion[i] < 1e-9f) continue;
      const bool active = probe.fresh[i] && probe.clearance[i] < o.margin + kActiveBand;
      const float room = active ? kActiveBand : std::max(probe.bound[i] - o.margin, 0.0f);
      s = std::min(s, room / motion[i]);
    }
    // The linearisation errs by the surfaces' curvature: halve until nothing ends inside. Only
    // parts whose bound could fall below the margin are searched.
    Probe verify(source);
    bool accepted = false;
    Pose next = pose;
    for (int halving = 0; halving < 6 && s > 1e-4f; ++halving, s *= 0.5f) {
      next = moved(pose, pivot, t * s, w * s);
      verify.reset(n);
      for (size_t i = 0; i < n; ++i) {
        check[i] = next.transformPoint(parts.local[i]);
        verify.bound[i] = probe.bound[i] - motion[i] * s;
      }
      const float lowest = verify(check, parts.radius, o.margin + kActiveBand, o.margin + kSlack);
      samples += verify.samples;
      verify.samples = 0;
      if (lowest >= 0.0f) {
        accepted = true;
        break;
      }
    }
    if (!accepted) break;
    for (size_t i = 0; i < n; ++i) motion[i] *= s;
    probe.moved(motion);
    const float step =
        glm::length(next.position - pose.position) +
        kLever * glm::length(rotationVector(next.orientation * glm::conjugate(pose.orientation)));
    pose = next;
    if (step < 1e-6f) break;
  }
  samples += probe.samples;
  return pose;
}

// The smallest rigid motion (world) that clears the hand's parts (world centres and radii) when
// some of them are inside: nothing when none is, or when none within releaseDistance clears
// them (caught deep, or between two objects: left where it is, the release takes it).
std::optional<Pose> pushOut(std::span<const glm::vec3> world, std::span<const float> radii,
                            const glm::vec3& pivot, const ExactDistanceSource& source,
                            const OuterHandOptions& o, int& samples, bool* inside = nullptr) {
  Probe probe(source);
  probe.reset(world.size());
  const float lowest = probe(world, radii, o.margin + kActiveBand, kInf);
  samples += probe.samples;
  if (inside != nullptr) *inside = lowest < 0.0f;
  if (lowest >= 0.0f) return std::nullopt;
  HandParts parts;
  const size_t n = std::min(world.size(), parts.size());
  for (size_t i = 0; i < n; ++i) parts[i] = HandPart{world[i], radii[i], radii[i], Joint::palm};
  ClearanceOptions co;
  co.margin = o.margin;
  co.maxCorrection = o.releaseDistance;
  auto cleared = clearHand(std::span<const HandPart>(parts.data(), n), pivot, nullptr, &source, co);
  if (!cleared) return std::nullopt;
  samples += cleared->exactSamples;
  if (cleared->exceeded || !cleared->wasInside) return std::nullopt;
  return cleared->handCorrection;
}

}  // namespace

void OuterHand::shownSpheres(std::span<const glm::vec3> rigid, std::span<const float> rigidRadius,
                             bool fingers, std::vector<glm::vec3>& world,
                             std::vector<float>& radii) const {
  world.clear();
  radii.assign(rigidRadius.begin(), rigidRadius.end());
  for (const glm::vec3& p : rigid) world.push_back(shown_.transformPoint(p));
  std::vector<glm::vec3> spheres;
  for (int f = 0; f < kFingerCount && fingers; ++f) {
    fingerSpheres(f, curl_[size_t(f)], spheres);
    for (const glm::vec3& p : spheres) world.push_back(shown_.transformPoint(p));
    radii.insert(radii.end(), rigs_[size_t(f)].radius.begin(), rigs_[size_t(f)].radius.end());
  }
}

std::optional<Pose> OuterHand::pushOutOf(const ExactDistanceSource& scene) const {
  if (!engaged_ || shownRigid_.empty()) return std::nullopt;
  std::vector<glm::vec3> world;
  std::vector<float> radii;
  shownSpheres(shownRigid_, shownRigidRadius_, !shownRigidFingers_, world, radii);
  int samples = 0;
  return pushOut(world, radii, shown_.transformPoint(shownPivot_), scene, options_, samples);
}

std::vector<HandPart> surfaceParts(const TriangleMesh& mesh) {
  std::vector<HandPart> out;
  const size_t triangles = mesh.triangleCount();
  if (mesh.positions.empty() || triangles == 0) return out;
  auto add = [&](const glm::vec3& p) {
    HandPart part;
    part.centre = p;
    out.push_back(part);
  };
  // Half the budget on vertices (the corners and rims a flat surface meets first).
  const size_t vertexBudget = kMaxAttachedParts / 2;
  const size_t stride = (mesh.positions.size() + vertexBudget - 1) / vertexBudget;
  for (size_t i = 0; i < mesh.positions.size(); i += stride) add(mesh.positions[i]);
  // The rest spread by area: a golden-ratio sequence over the cumulative areas (deterministic).
  std::vector<double> cumulative(triangles);
  double total = 0.0;
  for (size_t t = 0; t < triangles; ++t) {
    const glm::vec3 a = mesh.positions[mesh.indices[3 * t]];
    const glm::vec3 b = mesh.positions[mesh.indices[3 * t + 1]];
    const glm::vec3 c = mesh.positions[mesh.indices[3 * t + 2]];
    total += 0.5 * double(glm::length(glm::cross(b - a, c - a)));
    cumulative[t] = total;
  }
  if (!(total > 0.0)) return out;
  constexpr double kGolden = 0.6180339887498949;
  const size_t areaBudget = size_t(kMaxAttachedParts) - out.size();
  for (size_t k = 0; k < areaBudget; ++k) {
    const double u = (double(k) + 0.5) / double(areaBudget) * total;
    const size_t t = std::min<size_t>(
        size_t(std::lower_bound(cumulative.begin(), cumulative.end(), u) - cumulative.begin()),
        triangles - 1);
    // A point inside the triangle from two more low-discrepancy coordinates.
    float r1 = float(std::fmod(double(k) * kGolden, 1.0));
    float r2 = float(std::fmod(double(k) * kGolden * kGolden + 0.5, 1.0));
    if (r1 + r2 > 1.0f) r1 = 1.0f - r1, r2 = 1.0f - r2;
    const glm::vec3 a = mesh.positions[mesh.indices[3 * t]];
    const glm::vec3 b = mesh.positions[mesh.indices[3 * t + 1]];
    const glm::vec3 c = mesh.positions[mesh.indices[3 * t + 2]];
    add(a + r1 * (b - a) + r2 * (c - a));
  }
  return out;
}

std::vector<HandPart> surfaceParts(const AnalyticShape& shape) {
  std::vector<HandPart> out;
  if (!shape.bounded()) return out;
  const glm::vec3 h = shape.halfExtents;
  constexpr int kGrid = 4;  // points per face edge, corners included
  // Every point of a kGrid^3 lattice over the box that lies on its surface: corners, edges and
  // each face's grid.
  for (int i = 0; i < kGrid; ++i)
    for (int j = 0; j < kGrid; ++j)
      for (int k = 0; k < kGrid; ++k) {
        const bool surface =
            i == 0 || i == kGrid - 1 || j == 0 || j == kGrid - 1 || k == 0 || k == kGrid - 1;
        if (!surface) continue;
        HandPart part;
        part.centre = glm::vec3(float(i), float(j), float(k)) / float(kGrid - 1) * 2.0f - 1.0f;
        part.centre *= h;
        out.push_back(part);
      }
  return out;
}

std::optional<Error> OuterHandOptions::validate() const {
  if (!(margin >= 0.0f && margin <= 0.01f) || !(releaseDistance > 0.0f) ||
      !std::isfinite(releaseDistance) || !(blendTime >= 0.0f) || !std::isfinite(blendTime) ||
      maxIterations < 1 || !(stillness >= 0.0f) || !std::isfinite(stillness))
    return makeError(Status::invalid_argument,
                     "outer hand: margin in [0, 0.01], releaseDistance > 0, blendTime >= 0, "
                     "maxIterations >= 1, stillness >= 0, all finite");
  return std::nullopt;
}

OuterHand::OuterHand(const HandModel& model, const OuterHandOptions& options)
    : model_(model), options_(options) {
  prepareFingers();
}

void OuterHand::setModel(const HandModel& model) {
  // The rigs are a function of the model: recomputed only when it changed (a tracked hand's
  // model is fitted once per grab, a controller's never changes).
  if (std::memcmp(&model, &model_, sizeof(HandModel)) == 0) return;
  model_ = model;
  prepareFingers();
}

void OuterHand::reset() {
  shownRigid_.clear();
  shownRigidRadius_.clear();
  engaged_ = false;
  released_ = false;
  blending_ = false;
  capped_.fill(false);
}

void OuterHand::prepareFingers() {
  for (int f = 0; f < kFingerCount; ++f) {
    const Finger finger = Finger(f);
    const std::span<const Joint> joints = fingerJoints(finger);
    const int bones = int(joints.size()) - 1;
    std::array<Pose, 5> open{}, closed{};
    model_.fingerPose(finger, 0.0f, std::span(open.data(), joints.size()));
    model_.fingerPose(finger, 1.0f, std::span(closed.data(), joints.size()));
    // The first bone that moves with the curl (the thumb's metacarpal turns, the others' not).
    const int first = glm::length(open[1].position - closed[1].position) > 1e-6f ? 0 : 1;
    FingerRig& rig = rigs_[size_t(f)];
    rig = FingerRig{};
    for (int bone = first; bone < bones; ++bone) {
      const float r0 = model_.jointRadius(joints[size_t(bone)]);
      const float r1 = model_.jointRadius(joints[size_t(bone) + 1]);
      const float rmin = std::max(1e-4f, std::min(r0, r1));
      const float length =
          glm::length(open[size_t(bone) + 1].position - open[size_t(bone)].position);
      const int count = std::max(1, int(std::ceil(length / (kFingerSpacing * rmin))));
      const float spacing = length / float(count);
      const float grow = std::sqrt(rmin * rmin + 0.25f * spacing * spacing) - rmin;
      for (int k = 1; k <= count; ++k) {
        const float u = float(k) / float(count);
        rig.t.push_back(float(bone) + u);
        rig.radius.push_back((1.0f - u) * r0 + u * r1 + grow);
      }
    }
    // A bound on every sphere's motion per unit curl, from the model itself (finite differences,
    // with a margin for the curvature between samples).
    std::vector<glm::vec3> a, c;
    constexpr int kProbe = 64;
    for (int k = 0; k < kProbe; ++k) {
      fingerSpheres(f, float(k) / kProbe, a);
      fingerSpheres(f, float(k + 1) / kProbe, c);
      for (size_t i = 0; i < a.size(); ++i)
        rig.speed = std::max(rig.speed, glm::length(c[i] - a[i]) * float(kProbe));
    }
    rig.speed = rig.speed * 1.1f + 1e-4f;
  }
}

void OuterHand::fingerSpheres(int f, float a, std::vector<glm::vec3>& out) const {
  const Finger finger = Finger(f);
  const std::span<const Joint> joints = fingerJoints(finger);
  std::array<Pose, 5> poses{};
  model_.fingerPose(finger, a, std::span(poses.data(), joints.size()));
  const FingerRig& rig = rigs_[size_t(f)];
  out.resize(rig.t.size());
  for (size_t i = 0; i < rig.t.size(); ++i) {
    const int bone = std::min(int(rig.t[i]), int(joints.size()) - 2);
    const float u = rig.t[i] - float(bone);
    out[i] = drawnOffset_.transformPoint(
        glm::mix(poses[size_t(bone)].position, poses[size_t(bone) + 1].position, u));
  }
}

Result<OuterHandResult> OuterHand::update(const OuterHandInput& in,
                                          const ExactDistanceSource* scene) {
  if (in.joints == nullptr || in.radii == nullptr || !finitePose(in.worldFromWrist) ||
      !finitePose(in.drawnOffset))
    return makeError(Status::invalid_argument, "outer hand: joints, radii and a finite wrist");
  if (auto e = options_.validate()) return *e;
  const Pose& tracked = in.worldFromWrist;
  OuterHandResult out;
  out.worldFromShownWrist = tracked;
  out.clearance = kInf;
  if (scene == nullptr) {
    reset();
    return out;
  }

  // The hand as given, in parts (wrist frame): the rigid ones, and each finger's; moved by the
  // grasp's offset where it is drawn.
  drawnOffset_ = in.drawnOffset;
  JointPoses drawn;
  for (int j = 0; j < kJointCount; ++j) drawn[size_t(j)] = in.drawnOffset * (*in.joints)[size_t(j)];
  HandParts parts;
  const int count = jointParts(drawn, *in.radii, parts);
  RigidParts rigid;
  std::array<std::vector<glm::vec3>, kFingerCount> fingerLocal;
  std::array<std::vector<float>, kFingerCount> fingerRadius;
  for (int i = 0; i < count; ++i) {
    const HandPart& p = parts[size_t(i)];
    const int f = fingerOf(p.joint);
    if (f < 0 || isMetacarpal(p.joint) || in.rigidFingers) {
      rigid.local.push_back(p.centre);
      rigid.radius.push_back(p.coverRadius);
    } else {
      fingerLocal[size_t(f)].push_back(p.centre);
      fingerRadius[size_t(f)].push_back(p.coverRadius);
    }
  }
  // A held object's surface keeps no margin: it may rest on a surface, not enter it.
  const float attachedRadius = -options_.margin;
  for (const HandPart& p : in.attached) {
    rigid.local.push_back(p.centre);
    rigid.radius.push_back(p.coverRadius + attachedRadius);
  }
  const glm::vec3 pivot = drawn[size_t(Joint::palm)].position;
  const FingerCurls user = model_.estimateCurls(*in.joints);
  // The hand's own rigid parts shown last frame (for a target that moved into it), and this
  // frame's for the next.
  const ptrdiff_t handRigid = ptrdiff_t(rigid.local.size() - in.attached.size());
  std::vector<glm::vec3> lastRigid(rigid.local.begin(), rigid.local.begin() + handRigid);
  std::vector<float> lastRigidRadius(rigid.radius.begin(), rigid.radius.begin() + handRigid);
  std::swap(lastRigid, shownRigid_);
  std::swap(lastRigidRadius, shownRigidRadius_);
  shownPivot_ = pivot;
  shownRigidFingers_ = in.rigidFingers;

  // The largest motion of any part between two wrist poses.
  auto motion = [&](const Pose& a, const Pose& b) {
    float m = 0.0f;
    for (int i = 0; i < count; ++i) {
      const glm::vec3 p = parts[size_t(i)].centre;
      m = std::max(m, glm::length(a.transformPoint(p) - b.transformPoint(p)));
    }
    return m;
  };

  // A hand that jumps (farther than a hand moves between two updates: tracking lost and found
  // elsewhere, or the app teleported it) is shown at its new pose at once, never blended there
  // through whatever lies between; where that pose is inside something, at the nearest pose that
  // is clear (within releaseDistance; deeper, it follows tracking until it is clear, as after a
  // release).
  int arrivalSamples = 0;
  const bool jumped = engaged_ && motion(lastTracked_, tracked) > kJumpDistance;
  if (!engaged_ || jumped) {
    engaged_ = true;
    shown_ = tracked;
    lastTracked_ = tracked;
    blending_ = false;
    released_ = false;
    for (int f = 0; f < kFingerCount; ++f) curl_[size_t(f)] = user[size_t(f)];
    capped_.fill(false);
    // A hand that appears inside (its first update: tracking found again, the first frame near
    // a target) is shown at the nearest clear pose as a jump is.
    {
      std::vector<glm::vec3> handWorld;
      std::vector<float> handRadii;
      for (int i = 0; i < count; ++i) {
        handWorld.push_back(tracked.transformPoint(parts[size_t(i)].centre));
        handRadii.push_back(parts[size_t(i)].coverRadius);
      }
      bool inside = false;
      if (auto c = pushOut(handWorld, handRadii, tracked.transformPoint(pivot), *scene, options_,
                           arrivalSamples, &inside)) {
        shown_ = *c * tracked;
        out.pushedOut = true;
      } else if (inside) {
        released_ = true;  // no clear pose within the bound: tracking, until it is clear
      }
    }
    lastRigid.clear();  // nothing shown before to test against the scene
  }
  Probe probe(*scene);
  std::vector<glm::vec3> world;
  std::vector<float> radii;
  // The whole hand as given, placed at `wrist`: its smallest clearance (searched within reach).
  auto handClearance = [&](const Pose& wrist, float reach) {
    world.clear(), radii.clear();
    for (int i = 0; i < count; ++i) {
      world.push_back(wrist.transformPoint(parts[size_t(i)].centre));
      radii.push_back(parts[size_t(i)].coverRadius);
    }
    for (const HandPart& p : in.attached) {
      world.push_back(wrist.transformPoint(p.centre));
      radii.push_back(p.coverRadius + attachedRadius);
    }
    probe.reset(world.size());
    return probe(world, radii, reach, kInf);
  };

  // After a release the shown hand follows tracking, but never into an object: a part that is
  // clear where the hand was shown last and that the motion to the tracked pose brings onto a
  // surface (toward the nearest one, within its motion, or inside at the tracked pose) ends the
  // release. The outer hand then holds again from the last shown pose, that part among its
  // constraints, while the parts still inside are free to come out (the slide below drops them).
  // A hand pushed partly into a table, let go, and moved on into a comb stops on the comb.
  if (released_ && !blending_) {
    // Every part where it was shown (`world`, with the probe's clearance and gradient of each).
    handClearance(shown_, motion(shown_, tracked) + options_.margin + kActiveBand);
    const Pose toTracked = tracked * shown_.inverse();
    std::vector<glm::vec3> arriving;
    std::vector<float> arrivingRadii;
    bool reengage = false;
    for (size_t i = 0; i < world.size() && !reengage; ++i) {
      const glm::vec3 move = toTracked.transformPoint(world[i]) - world[i];
      const float c = probe.clearance[i];
      if (c < options_.margin || c >= glm::length(move) + options_.margin)
        continue;  // inside, or nothing near
      if (glm::dot(move, probe.gradient[i]) < 0.0f) {
        reengage = true;  // toward the surface it is near
      } else {
        arriving.push_back(world[i] + move);
        arrivingRadii.push_back(radii[i]);
      }
    }
    if (!reengage && !arriving.empty()) {
      // Away from the nearest surface, but another may be where it arrives.
      probe.reset(arriving.size());
      reengage =
          probe(arriving, arrivingRadii, options_.margin + kActiveBand, kInf) < options_.margin;
    }
    if (reengage) {
      released_ = false;
      capped_.fill(false);
      for (int f = 0; f < kFingerCount; ++f) curl_[size_t(f)] = user[size_t(f)];
    }
  }

  // Returning to tracking: blend, then follow tracking until the tracked hand is clear.
  if (blending_ || released_) {
    if (blending_) {
      const float alpha =
          options_.blendTime > 0.0f
              ? float(std::clamp((in.time - blendStart_) / options_.blendTime, 0.0, 1.0))
              : 1.0f;
      shown_ = Pose{glm::slerp(blendFrom_.orientation, tracked.orientation, alpha),
                    glm::mix(blendFrom_.position, tracked.position, alpha)};
      if (alpha >= 1.0f) blending_ = false, released_ = true, shown_ = tracked;
    } else {
      shown_ = tracked;
    }
    // A bounded search that finds nothing says "clear" about a part deep inside too. The palm is
    // searched as far as a hand let go can be inside; the other parts only near the surface:
    // with the palm out and no part near a surface, none is inside (the parts of a bone are
    // closer than their radii, so a chain that crosses the surface puts one near it).
    if (released_ && handClearance(tracked, options_.margin + kActiveBand) >= options_.margin) {
      const std::array<glm::vec3, 1> palm{tracked.transformPoint(pivot)};
      const std::array<float, 1> palmRadius{(*in.radii)[size_t(Joint::palm)]};
      Probe far(*scene);
      far.reset(1);
      if (far(palm, palmRadius, kReleasedReach, kInf) >= options_.margin) {
        released_ = false;  // the tracked hand came out: the outer hand holds again
      }
      probe.samples += far.samples;
    }
    out.worldFromShownWrist = shown_;
    out.offset = tracked.inverse() * shown_;
    out.curl = user;
    out.blending = blending_;
    out.released = released_;
    out.constrained = blending_;
    out.samples = probe.samples;
    lastTracked_ = tracked;
    capped_.fill(false);
    return out;
  }

  // Too far from tracking: let go, blended.
  if (motion(shown_, tracked) > options_.releaseDistance) {
    blending_ = true;
    blendStart_ = in.time;
    blendFrom_ = shown_;
    out.worldFromShownWrist = shown_;
    out.offset = tracked.inverse() * shown_;
    out.curl = user;
    out.blending = true;
    out.constrained = true;
    lastTracked_ = tracked;
    return out;
  }

  // Nothing within the motion from the last shown pose to the tracked one, fingers as given:
  // the tracked hand, exactly.
  const float reach = motion(shown_, tracked);
  const bool wasConstrained = motion(shown_, lastTracked_) > 1e-7f ||
                              std::any_of(capped_.begin(), capped_.end(), [](bool c) { return c; });
  if (handClearance(shown_, reach + options_.margin + kActiveBand) > reach + options_.margin &&
      (!wasConstrained ||
       handClearance(tracked, options_.margin + kActiveBand) >= options_.margin)) {
    shown_ = tracked;
    lastTracked_ = tracked;
    capped_.fill(false);
    for (int f = 0; f < kFingerCount; ++f) curl_[size_t(f)] = user[size_t(f)];
    out.curl = curl_;
    // The clearance there, searched as far as a hand moves in a frame at speed: the next
    // frame's hand that moved less is clear without a search (GraspSession's fast path).
    const float searched = handClearance(tracked, kFreeReach);
    out.samples = probe.samples;
    out.clearance = std::min(searched, kFreeReach);
    return out;
  }

  // The rigid part inside where it was shown: a target moved into the hand (an object brought to
  // it, the world moved past the user, the other hand's held object), so no motion of the hand
  // put it there. Out first, by the smallest rigid motion (hand_clearance.h), then on toward
  // tracking. (A finger a target moved into is the finger stage's: it curls out of it.)
  int slideSamples = 0;
  // The hand tested is the one shown last (its rigid parts then), in the world as it is now: a
  // part the user's own input moves in (a thumb curled into the table) is not the world's doing.
  // The fingers count as shown last too (at their last shown curls): a table rising into a
  // relaxed, half-curled hand meets the fingertips first, and the hand rises with it rather than
  // leave them in it.
  if (in.sceneMoved && !lastRigid.empty()) {
    std::vector<glm::vec3> handWorld;
    std::vector<float> handRadii;
    shownSpheres(lastRigid, lastRigidRadius, !in.rigidFingers, handWorld, handRadii);
    if (auto c = pushOut(handWorld, handRadii, shown_.transformPoint(pivot), *scene, options_,
                         slideSamples)) {
      shown_ = *c * shown_;
      out.pushedOut = true;
    }
  }

  // A hand held still against a surface stays where it is shown (no jitter).
  Pose next = shown_;
  if (!(wasConstrained && motion(tracked, lastTracked_) <= options_.stillness)) {
    // The rigid part, with every finger as it was shown (clear there) joining the constraints.
    RigidParts all = rigid;
    std::vector<glm::vec3> spheres;
    for (int f = 0; f < kFingerCount; ++f) {
      if (capped_[size_t(f)]) {
        fingerSpheres(f, curl_[size_t(f)], spheres);
        all.local.insert(all.local.end(), spheres.begin(), spheres.end());
        all.radius.insert(all.radius.end(), rigs_[size_t(f)].radius.begin(),
                          rigs_[size_t(f)].radius.end());
      } else {
        all.local.insert(all.local.end(), fingerLocal[size_t(f)].begin(),
                         fingerLocal[size_t(f)].end());
        all.radius.insert(all.radius.end(), fingerRadius[size_t(f)].begin(),
                          fingerRadius[size_t(f)].end());
      }
    }
    // Parts already inside where the hand starts cannot constrain a motion: a finger pushed in
    // by the last frame's fingers is the finger stage's to take out.
    world.clear();
    for (const glm::vec3& p : all.local) world.push_back(shown_.transformPoint(p));
    probe.reset(world.size());
    probe(world, all.radius, options_.margin + kActiveBand, kInf);
    RigidParts clear;
    for (size_t i = 0; i < all.local.size(); ++i) {
      if (probe.clearance[i] >= 0.0f) {
        clear.local.push_back(all.local[i]);
        clear.radius.push_back(all.radius[i]);
      }
    }
    next = slide(clear, pivot, shown_, tracked, *scene, options_, slideSamples);
  }

  // Each finger from its last shown curl toward the user's, stopping at contact.
  std::vector<glm::vec3> spheres, sphereWorld;
  Probe fingerProbe(*scene);
  std::vector<float> drop;
  for (int f = 0; f < kFingerCount; ++f) {
    if (in.rigidFingers) {
      curl_[size_t(f)] = user[size_t(f)];
      capped_[size_t(f)] = false;
      continue;
    }
    const FingerRig& rig = rigs_[size_t(f)];
    const float target = user[size_t(f)];
    float a = curl_[size_t(f)];
    fingerProbe.reset(rig.t.size());
    // The finger's smallest clearance at curl `curl`, searching only spheres whose bound is
    // below `below` (every one at the first call).
    auto clearanceAt = [&](float curl, float within, float below) {
      fingerSpheres(f, curl, spheres);
      sphereWorld.resize(spheres.size());
      for (size_t i = 0; i < spheres.size(); ++i) sphereWorld[i] = next.transformPoint(spheres[i]);
      return fingerProbe(sphereWorld, rig.radius, within, below);
    };
    auto advance = [&](float from, float to) {
      drop.assign(rig.t.size(), rig.speed * std::abs(to - from));
      fingerProbe.moved(drop);
    };
    const float near = options_.margin + kContactTolerance + kFingerSlack;
    bool contact = false;
    float g =
        clearanceAt(a, rig.speed * std::abs(target - a) + options_.margin + kActiveBand, kInf);
    // Inside where it starts (the scene moved, or the rigid part could not take it along): the
    // curl nearest it that is clear, or failing that the least deep, opening or closing (opening
    // is not always the way out: a finger curled over a plate's face swings into it as it opens).
    if (g < 0.0f) {
      float bestA = a, bestG = g;
      for (const float way : {-1.0f, 1.0f}) {
        float c = a;
        fingerProbe.reset(rig.t.size());
        float gc = clearanceAt(c, options_.margin + kActiveBand, kInf);
        for (int k = 0; k < kMaxFingerSteps && gc < options_.margin; ++k) {
          const float step = std::max(options_.margin - gc, 0.0005f) / rig.speed;
          const float d = std::clamp(c + way * step, 0.0f, 1.0f);
          if (d == c) break;
          advance(c, d);
          c = d;
          gc = clearanceAt(c, options_.margin + kActiveBand, near);
          if (gc > bestG) bestA = c, bestG = gc;
          if (gc < bestG - kWrongWay) break;  // deeper this way
        }
        if (bestG >= options_.margin) break;
      }
      a = bestA;
      fingerProbe.reset(rig.t.size());
      g = clearanceAt(a, options_.margin + kActiveBand, kInf);
      contact = true;
    } else if (g < options_.margin) {
      contact = true;  // on the surface where it starts: stays there
    }
    const float dir = target >= a ? 1.0f : -1.0f;
    for (int k = 0; k < kMaxFingerSteps && !contact; ++k) {
      if (g <= options_.margin + kContactTolerance && !(g < options_.margin && a == 0.0f)) {
        contact = std::abs(target - a) > 1e-6f;
        break;
      }
      if (std::abs(target - a) < 1e-6f) break;
      const float step = std::max((g - options_.margin) / rig.speed, kMinCurlStep);
      const float b = dir > 0.0f ? std::min(target, a + step) : std::max(target, a - step);
      advance(a, b);
      a = b;
      g = clearanceAt(a, rig.speed * std::abs(target - a) + options_.margin + kActiveBand, near);
    }
    curl_[size_t(f)] = a;
    // Reached the user's curl and the finger as given is clear too: shown as given.
    bool asGiven = !contact && std::abs(target - a) < 1e-6f;
    if (asGiven && !fingerLocal[size_t(f)].empty()) {
      sphereWorld.resize(fingerLocal[size_t(f)].size());
      for (size_t i = 0; i < sphereWorld.size(); ++i)
        sphereWorld[i] = next.transformPoint(fingerLocal[size_t(f)][i]);
      fingerProbe.reset(sphereWorld.size());
      asGiven = fingerProbe(sphereWorld, fingerRadius[size_t(f)], options_.margin + kActiveBand,
                            kInf) >= options_.margin;
    }
    capped_[size_t(f)] = !asGiven;
  }
  shown_ = next;
  lastTracked_ = tracked;
  out.worldFromShownWrist = shown_;
  out.offset = tracked.inverse() * shown_;
  out.capped = capped_;
  out.curl = curl_;
  out.constrained = motion(shown_, tracked) > 1e-7f ||
                    std::any_of(capped_.begin(), capped_.end(), [](bool c) { return c; });
  out.clearance = handClearance(shown_, options_.margin + kActiveBand);
  out.touching = out.clearance <= options_.margin + 0.0005f;
  out.samples = probe.samples + fingerProbe.samples + slideSamples + arrivalSamples;
  return out;
}

}  // namespace sdfg
