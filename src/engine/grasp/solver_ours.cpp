// The "ours" strategy's set-up and its per-finger loop: prepare() turns the hand model into joint
// rigs, spheres and speed bounds once; solve() closes each finger, stage by stage, on the field
// (solver_ours_field.cpp) and, where the scene has one, the exact source (solver_ours_exact.cpp).
#include "grasp/solver_ours_detail.h"

namespace sdfg {

Status OursSolver::prepare(const HandModel& hand, const GridBox& box,
                           const SolverOptions& options) {
  prepared_ = false;
  error_.clear();
  if (std::optional<Error> e = validateSolverOptions(options)) {
    error_ = "ours: " + e->message;
    return e->code;
  }
  if (std::optional<Error> e = box.validate()) {
    error_ = "ours: " + e->message;
    return e->code;
  }
  hand_ = hand;
  box_ = box;
  options_ = options;

  for (int f = 0; f < kFingerCount; ++f) {
    const Finger finger = Finger(f);
    const std::span<const Joint> joints = fingerJoints(finger);
    FingerRig& fr = fingers_[f];
    fr = FingerRig{};
    const int n = int(joints.size()) - 1;
    if (n < 2 || n > kMaxJoints) {
      error_ =
          std::string("ours: finger ") + fingerName(finger) + " has an unsupported joint count";
      return Status::internal;
    }
    fr.joints = n;

    std::array<Pose, kMaxJoints + 1> open{}, closed{};
    hand.fingerPose(finger, JointCurls{0.0f, 0.0f, 0.0f, 0.0f}, std::span(open.data(), n + 1));
    hand.fingerPose(finger, JointCurls{1.0f, 1.0f, 1.0f, 1.0f}, std::span(closed.data(), n + 1));
    for (int j = 0; j < n; ++j) {
      JointRig& jr = fr.rig[j];
      glm::quat qo = open[j].orientation, qc = closed[j].orientation;
      if (j == 0) {
        jr.offset = open[0].position;
      } else {
        qo = glm::conjugate(open[j - 1].orientation) * qo;
        qc = glm::conjugate(closed[j - 1].orientation) * qc;
        jr.offset = open[j - 1].inverse().transformPoint(open[j].position);
      }
      glm::quat rel = glm::conjugate(qo) * qc;
      if (rel.w < 0.0f) rel = -rel;  // the short way, as slerp takes it
      jr.open = qo;
      jr.angle = quatAngle(rel);
      const glm::vec3 v(rel.x, rel.y, rel.z);
      jr.axis = glm::length(v) > 1e-7f ? glm::normalize(v) : glm::vec3(1.0f, 0.0f, 0.0f);
    }
    fr.tipOffset = open[n - 1].inverse().transformPoint(open[n].position);

    // Bone lengths from joint m to m + 1 (the last one ends at the tip).
    std::array<float, kMaxJoints> boneLength{};
    for (int m = 0; m < n; ++m) {
      boneLength[m] = glm::length(m + 1 < n ? fr.rig[m + 1].offset : fr.tipOffset);
    }

    // Angular speed of each joint's local rotation, per unit curl. A slerp turns at a constant
    // `angle`; finite differences catch a model that blends some other way (nlerp speeds up in
    // the middle), and the larger of the two bounds the motion.
    std::array<float, kMaxJoints> omega{};
    constexpr int kProbe = 64;
    std::array<Pose, kMaxJoints + 1> pa{}, pb{};
    for (int k = 0; k < kProbe; ++k) {
      const float a0 = float(k) / kProbe, a1 = float(k + 1) / kProbe;
      hand.fingerPose(finger, JointCurls{a0, a0, a0, a0}, std::span(pa.data(), n + 1));
      hand.fingerPose(finger, JointCurls{a1, a1, a1, a1}, std::span(pb.data(), n + 1));
      for (int j = 0; j < n; ++j) {
        glm::quat la = pa[j].orientation, lb = pb[j].orientation;
        if (j > 0) {
          la = glm::conjugate(pa[j - 1].orientation) * la;
          lb = glm::conjugate(pb[j - 1].orientation) * lb;
        }
        omega[j] = std::max(omega[j], quatAngle(glm::conjugate(la) * lb) * kProbe);
      }
    }
    for (int j = 0; j < n; ++j) omega[j] = std::max(omega[j], fr.rig[j].angle) * 1.02f + 1e-4f;

    // Spheres: the proximal joint (end of the metacarpal bone, moved by joint 0 only), then
    // along each phalanx up to and including the tip. A sphere at a bone's end joint belongs to
    // that bone, so stopping the joints that move it never stops a joint it does not depend on.
    auto radiusAt = [&](int bone, float t) {
      return (1.0f - t) * hand.jointRadius(joints[bone]) + t * hand.jointRadius(joints[bone + 1]);
    };
    // The thumb's metacarpal turns at its carpometacarpal joint as the hand closes (the other
    // metacarpals are fixed): its whole capsule sweeps toward the palm, so it is sampled along
    // its length like a phalanx, not only at its end joint.
    const bool movingMetacarpal = fr.rig[0].angle > 1e-4f;
    const int firstBone = movingMetacarpal ? 0 : 1;
    float spacing = kSphereSpacing;
    for (int attempt = 0; attempt < 8; ++attempt) {
      int count = movingMetacarpal ? 0 : 1;
      for (int b = firstBone; b < n; ++b) {
        const float r = std::min(hand.jointRadius(joints[b]), hand.jointRadius(joints[b + 1]));
        count += std::max(1, int(std::ceil(boneLength[b] / (spacing * std::max(r, 1e-4f)))));
      }
      if (count <= kMaxSpheres) break;
      spacing *= 1.25f;
    }
    const float thresholdOffset =
        options.threshold < 0.0f ? 0.0f : options.threshold - hand.tipRadius(finger);
    auto addSphere = [&](int bone, float t, float cover) {
      if (fr.sphereCount >= kMaxSpheres) return;
      Sphere& s = fr.spheres[fr.sphereCount++];
      s.bone = uint8_t(bone);
      s.t = t;
      s.radius = radiusAt(bone, t);
      s.testRadius = s.radius + cover + thresholdOffset;
    };
    if (!movingMetacarpal) {
      const float r = hand.jointRadius(joints[1]);
      const float s = spacing * r;
      addSphere(0, 1.0f, std::sqrt(r * r + 0.25f * s * s) - r);
    }
    for (int b = firstBone; b < n; ++b) {
      const float r =
          std::max(1e-4f, std::min(hand.jointRadius(joints[b]), hand.jointRadius(joints[b + 1])));
      const int count = std::max(1, int(std::ceil(boneLength[b] / (spacing * r))));
      const float s = boneLength[b] / float(count);
      const float cover = std::sqrt(r * r + 0.25f * s * s) - r;
      for (int k = 1; k <= count; ++k) {
        const bool tip = (b == n - 1 && k == count);
        addSphere(b, float(k) / float(count), tip ? 0.0f : cover);
      }
    }
    fr.tipSphere = fr.sphereCount - 1;
    for (int j = 0; j <= n; ++j) fr.jointRadius[j] = hand.jointRadius(joints[j]);
    fr.thresholdOffset = thresholdOffset;

    // Speed bounds: the centre of a sphere on bone b turns about every moving joint j <= b at
    // omega_j, at a distance no more than the chain length from joint j to it.
    for (int first = 0; first < n; ++first) {
      float vmax = 0.0f, rmin = std::numeric_limits<float>::max();
      for (int i = 0; i < fr.sphereCount; ++i) {
        const Sphere& s = fr.spheres[i];
        float v = 0.0f;
        for (int j = first; j <= s.bone; ++j) {
          float chain = s.t * boneLength[s.bone];
          for (int m = j; m < s.bone; ++m) chain += boneLength[m];
          v += omega[j] * chain;
        }
        fr.speed[first][i] = v;
        if (s.bone >= first) {
          vmax = std::max(vmax, v);
          rmin = std::min(rmin, s.radius);
        }
      }
      fr.minStep[first] = vmax > 0.0f ? kMinMotion / vmax : 1.0f;
      fr.maxJump[first] = vmax > 0.0f ? rmin / vmax : 1.0f;
    }

    // Check the rebuilt kinematics against the model at a few mixed curls.
    const JointCurls probes[] = {{0.3f, 0.7f, 0.1f, 0.9f},
                                 {1.0f, 0.2f, 0.5f, 0.5f},
                                 {0.05f, 0.95f, 0.6f, 0.33f},
                                 {0.5f, 0.5f, 0.5f, 0.5f}};
    for (const JointCurls& c : probes) {
      hand.fingerPose(finger, c, std::span(pa.data(), n + 1));
      glm::quat q(1.0f, 0.0f, 0.0f, 0.0f);
      glm::vec3 p(0.0f);
      for (int j = 0; j < n; ++j) {
        const JointRig& jr = fr.rig[j];
        p = q * jr.offset + p;
        if (glm::length(p - pa[j].position) > kKinematicsTolerance) fr.ownKinematics = false;
        const float h = 0.5f * c[j] * jr.angle;
        q = q * jr.open * glm::quat(std::cos(h), std::sin(h) * jr.axis);
      }
      p = q * fr.tipOffset + p;
      if (glm::length(p - pa[n].position) > kKinematicsTolerance) fr.ownKinematics = false;
    }
  }
  partCount_ = handParts(hand, FingerCurls{}, parts_);
  {
    JointPoses open{};
    hand.pose(FingerCurls{}, open);
    palm_ = open[size_t(Joint::palm)].position;
  }
  prepared_ = true;
  return Status::ok;
}

void OursSolver::jointPositions(int finger, const JointCurls& curls,
                                std::array<glm::vec3, kMaxJoints + 1>& hand) const {
  const FingerRig& fr = fingers_[finger];
  const int n = fr.joints;
  if (fr.ownKinematics) {
    glm::quat q(1.0f, 0.0f, 0.0f, 0.0f);
    glm::vec3 p(0.0f);
    for (int j = 0; j < n; ++j) {
      const JointRig& jr = fr.rig[j];
      p = q * jr.offset + p;
      hand[j] = p;
      const float h = 0.5f * curls[j] * jr.angle;
      q = q * jr.open * glm::quat(std::cos(h), std::sin(h) * jr.axis);
    }
    hand[n] = q * fr.tipOffset + p;
  } else {
    std::array<Pose, kMaxJoints + 1> poses{};
    hand_.fingerPose(Finger(finger), curls, std::span(poses.data(), n + 1));
    for (int j = 0; j <= n; ++j) hand[j] = poses[j].position;
  }
}

Status OursSolver::solve(const GraspScene& scene, GraspResult& out) const {
  if (!prepared_) return Status::invalid_argument;
  if (scene.field == nullptr) return Status::invalid_argument;
  const SdfGrid& field = *scene.field;
  if (field.values().size() != field.box().nodeCount() || field.values().empty()) {
    return Status::invalid_argument;
  }

  out = GraspResult{};
  bool approached = false;
  if (options_.approach) {
    // Only a palm near the surface, not touching it and roughly facing it is brought onto it:
    // a hand far away or turned away is not reaching for this surface.
    const float d = field.sample(palm_);
    const glm::vec3 g = field.gradient(palm_);
    JointPoses open{};
    hand_.pose(FingerCurls{}, open);
    const glm::vec3 palmNormal = palmFacing(open[size_t(Joint::palm)]);
    const float gl = glm::length(g);
    const float facing =
        gl > 1e-3f ? std::acos(std::clamp(glm::dot(palmNormal, -g / gl), -1.0f, 1.0f)) : 0.0f;
    if (gl > 1e-3f && d > hand_.jointRadius(Joint::palm) && d <= options_.approachRange &&
        facing <= options_.approachMaxAngle) {
      Result<ApproachResult> approach = approachPose(field, hand_);
      if (approach.ok()) out.handCorrection = approach->handCorrection, approached = true;
    }
  }
  if (options_.clearance) {
    ClearanceOptions co;
    co.margin = options_.clearanceMargin;
    co.maxCorrection = options_.clearanceBound;
    co.rotation = options_.clearanceRotation;
    co.fieldFromHand = scene.fieldFromHand;
    // The model's open hand (where the fingers close from), and the scene's own parts of the
    // hand (a tracked hand as the user holds it), cleared together.
    HandParts all;
    int count = 0;
    for (int i = 0; i < partCount_ && count < kMaxHandParts; ++i) all[size_t(count++)] = parts_[i];
    for (const HandPart& p : scene.extraParts) {
      if (count < kMaxHandParts) all[size_t(count++)] = p;
    }
    const std::span<const HandPart> parts(all.data(), size_t(count));
    Result<ClearanceResult> c =
        clearHand(parts, palm_, &field, scene.exact, co, out.handCorrection);
    if (c.ok() && c->exceeded && approached) {
      // The approach put the hand where it cannot be cleared: clear it from where it was.
      out.handCorrection = Pose{};
      c = clearHand(parts, palm_, &field, scene.exact, co, Pose{});
    }
    if (c.ok()) {
      out.openClearance = c->clearanceBefore;
      out.handCorrection = c->handCorrection;
      out.clearanceExceeded = c->exceeded;
      out.exactSamples += c->exactSamples;
    }
  }
  for (int i = 0; i < partCount_; ++i) {
    out.handMoved = std::max(
        out.handMoved,
        glm::length(out.handCorrection.transformPoint(parts_[i].centre) - parts_[i].centre));
  }
  glm::mat3 toBox;
  glm::vec3 toBoxOffset;
  normalizedMap(field.box(), scene.fieldFromHand * out.handCorrection, toBox, toBoxOffset);
  const FastSampler sampler(field);
  ExactContext cx;
  cx.source = scene.exact;
  cx.sceneFromHand = out.handCorrection;
  cx.sample = &sampler;
  cx.toBox = &toBox;
  cx.toBoxOffset = toBoxOffset;
  using Clock = std::chrono::steady_clock;
  Clock::duration checkTime{0};

  std::array<uint32_t, kMaxSpheres> hints{};
  cx.hints = &hints;
  for (int f = 0; f < kFingerCount; ++f) {
    const FingerRig& fr = fingers_[f];
    const int n = fr.joints;
    FingerState& state = out.fingers[f];
    hints.fill(std::numeric_limits<uint32_t>::max());
    JointCurls curls{0.0f, 0.0f, 0.0f, 0.0f};
    int firstFree = 0;
    float a = 0.0f;
    int restarts = 0;  // field stops the exact check found false, closed on from
    while (firstFree < n) {
      int touching = -1;
      glm::vec3 point(0.0f);
      float value = 0.0f;
      Stage st;
      st.finger = f;
      st.firstFree = firstFree;
      st.toBox = &toBox;
      st.toBoxOffset = toBoxOffset;
      st.sample = &sampler;
      st.polish = scene.exact == nullptr;
      a = stage(st, curls, a, touching, point, value);
      if (scene.exact != nullptr) {
        const Clock::time_point t0 = Clock::now();
        const bool fieldStopped = touching >= 0;
        a = exactStop(cx, f, firstFree, a, curls, touching, point, value, out.exactSamples);
        checkTime += Clock::now() - t0;
        // The field stopped the group where the exact surface is not near: closed on from the
        // pose the check reached, on the field again (its bounds far from the surface are low).
        if (fieldStopped && touching < 0 && a < 1.0f && ++restarts <= kMaxFalseStops) continue;
      }
      if (touching < 0) break;
      // The most distal contact is the one reported: it is where the finger ends up resting.
      state.contact = true;
      state.contactPoint = point;
      state.distance = value;
      state.contactBone = fr.spheres[touching].bone;
      state.contactT = fr.spheres[touching].t;
      firstFree = fr.spheres[touching].bone + 1;
    }
    for (int j = n; j < kMaxJoints; ++j) curls[j] = curls[n - 1];
    state.jointCurls = curls;
    // Joints only close further toward the tip, so the proximal joint holds the smallest curl:
    // the single-curl pose at that value is the first contact, free of the object.
    state.curl = curls[0];
    for (int j = 1; j < n; ++j) state.curl = std::min(state.curl, curls[j]);
  }
  if (scene.exact != nullptr) {
    out.exactCheckUs = std::chrono::duration<float, std::micro>(checkTime).count();
  }
  return Status::ok;
}

}  // namespace sdfg
