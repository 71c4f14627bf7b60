#include "grasp/solver_ours.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>

namespace sdfg {

namespace {

// Neighbouring spheres along a bone are at most this many (smaller) joint radii apart. Each is
// grown by sqrt(r^2 + s^2/4) - r so the spheres cover the capsule between them: with 0.8 that
// is 0.077 r (about 0.6 mm), small against the field's own error.
constexpr float kSphereSpacing = 0.8f;
// Smallest step of the advancement, as sphere motion: keeps grazing approaches from crawling.
// A feature can only be stepped over if it is thinner than this plus twice the sphere radius.
constexpr float kMinMotion = 0.0005f;  // metres
// Near the surface (clearance below this) the step may jump to the secant estimate of the
// contact, limited to maxJump (one sphere radius of motion, so nothing is stepped over).
constexpr float kSecantBand = 0.004f;  // metres
constexpr int kMaxAdvanceIterations = 200;
// Spheres whose trilinear clearance is below this are also read on the curvature-corrected
// reconstruction, which can sit this much below the trilinear value near thin parts.
constexpr float kCorrectBand = 0.008f;  // metres
// The final polish on the curvature-corrected field (see polish()).
constexpr float kMaxPolishClose = 0.004f;          // metres of (bounded) sphere motion, closing
constexpr float kMaxPolishOpen = 0.012f;           // and opening, which is always safe
constexpr float kMaxTrilinearOvershoot = 0.0015f;  // metres
constexpr int kMaxPolishIterations = 8;
constexpr int kMaxRefineIterations = 40;
// Exact check (exactStop()): at most this many Newton or secant steps on the exact clearance,
// and this many doubling opening steps when every pose tried was inside.
constexpr int kMaxExactIterations = 8;
constexpr int kMaxExactBackoff = 6;
// A candidate not sampled yet is taken to be no nearer than its field clearance minus this (the
// 16^3 field's error is within it on all but the sharpest parts), so when the closest one's
// exact clearance is below that bound the others are not sampled: most stops then take one
// sample per pose instead of one per candidate. A sphere whose field clearance is wrong by more
// can only be missed while another, nearer one is touching.
constexpr float kFieldTrust = 0.001f;  // metres
// The exact check's last step is not sampled again when it moves the closest sphere's clearance
// by at most this: kUnverifiedNewton for a Newton step on the exact gradient (see exactStop();
// its error is about a hundredth of the step), kUnverifiedStep for a secant (a fraction).
// Newton at 3 mm saved a few more samples than at 1 mm, but the contact residual's p95 grew
// from 0.09 to 0.11-0.16 mm on the 300-placement bench.
constexpr float kUnverifiedNewton = 0.001f;  // metres
constexpr float kUnverifiedStep = 0.0003f;   // metres
// Curl step of the finite difference that gives a sphere's velocity along the curl.
constexpr float kVelocityStep = 1e-3f;
// Where the exact check follows, the field's stop is refined only to this: the 16^3 field is
// off by about this much near curved parts anyway, and the check corrects the rest.
constexpr float kFieldStopTolerance = 0.0005f;  // metres
// A Newton step of the exact check moves no sphere more than its clearance plus this.
constexpr float kNewtonReach = 0.002f;  // metres
// Kinematics rebuilt from fingerPose() must match it this closely, else solve() asks the model.
constexpr float kKinematicsTolerance = 2e-5f;  // metres

float quatAngle(const glm::quat& q) {
  const float w = std::min(1.0f, std::abs(q.w));
  return 2.0f * std::acos(w);
}

// Hand space -> normalized box coordinates as an affine map, so one matrix product per joint
// replaces a pose inverse per sample.
void normalizedMap(const GridBox& box, const Pose& boxHandFromHand, glm::mat3& m, glm::vec3& t) {
  const glm::mat3 boxFromHand = glm::mat3_cast(glm::conjugate(box.handFromBox.orientation));
  glm::mat3 scale(1.0f);
  for (int a = 0; a < 3; ++a) scale[a][a] = 1.0f / box.size[a];
  const glm::mat3 toNormalized = scale * boxFromHand;
  // p_norm = S R^T (C p - t_box) + 0.5 with C the hand correction.
  const glm::mat3 c = glm::mat3_cast(boxHandFromHand.orientation);
  m = toNormalized * c;
  t = toNormalized * (boxHandFromHand.position - box.handFromBox.position) + glm::vec3(0.5f);
}

}  // namespace

// The closest sphere of one finger pose: the smallest clearance (sampled value minus stop
// distance), which sphere it is, and the curl step the distance bound allows.
struct OursSolver::Eval {
  float g = std::numeric_limits<float>::max();
  int arg = -1;
  float step = std::numeric_limits<float>::max();
  float value = 0.0f;
  glm::vec3 point{0.0f};                           // hand space (corrected frame)
  float gTri = std::numeric_limits<float>::max();  // smallest clearance on the plain trilinear
};

namespace {

// Four single-precision lanes (GCC/Clang vector extension, as in triangle_bvh.cpp): SSE on
// x86-64, NEON on ARM64, scalar code elsewhere.
typedef float F4 __attribute__((vector_size(16)));

// Trilinear sampling as SdfGrid::sampleNormalized, with the floor done by an integer cast (the
// coordinate is clamped to be non-negative) so the hot loop makes no library call.
struct FastSampler {
  const float* v = nullptr;
  glm::ivec3 n{2};
  glm::vec3 scale{1.0f};
  size_t sy = 0, sz = 0;

  explicit FastSampler(const SdfGrid& grid)
      : v(grid.values().data()),
        n(grid.box().resolution),
        scale(glm::vec3(grid.box().resolution) - 1.0f),
        sy(size_t(n.x)),
        sz(size_t(n.x) * size_t(n.y)) {}

  static void locate(float u, float s, int n, int& i, float& t) {
    const float x = std::clamp(u, 0.0f, 1.0f) * s;
    i = std::min(int(x), n - 2);
    t = x - float(i);
  }
  float operator()(const glm::vec3& uvw) const {
    int i, j, k;
    float tx, ty, tz;
    locate(uvw.x, scale.x, n.x, i, tx);
    locate(uvw.y, scale.y, n.y, j, ty);
    locate(uvw.z, scale.z, n.z, k, tz);
    const float* p = v + size_t(i) + sy * size_t(j) + sz * size_t(k);
    const float c00 = p[0] + (p[1] - p[0]) * tx;
    const float c10 = p[sy] + (p[sy + 1] - p[sy]) * tx;
    const float c01 = p[sz] + (p[sz + 1] - p[sz]) * tx;
    const float c11 = p[sz + sy] + (p[sz + sy + 1] - p[sz + sy]) * tx;
    const float c0 = c00 + (c10 - c00) * ty;
    const float c1 = c01 + (c11 - c01) * ty;
    return c0 + (c1 - c0) * tz;
  }

  // Trilinear value minus its leading error term. Linear interpolation of f between nodes h
  // apart misses t(1-t)/2 h^2 f'' at fraction t; f'' comes from the nodes' second differences,
  // blended trilinearly, so the result stays continuous. On smooth parts of a distance field
  // this cuts the 16^3 error about tenfold (median 0.8 -> 0.07 mm on spheres and boxes).
  float corrected(const glm::vec3& uvw, float trilinear) const {
    int idx[3];
    float t[3];
    locate(uvw.x, scale.x, n.x, idx[0], t[0]);
    locate(uvw.y, scale.y, n.y, idx[1], t[1]);
    locate(uvw.z, scale.z, n.z, idx[2], t[2]);
    const std::ptrdiff_t stride[3] = {1, std::ptrdiff_t(sy), std::ptrdiff_t(sz)};
    const float* base = v + size_t(idx[0]) + sy * size_t(idx[1]) + sz * size_t(idx[2]);
    // Per axis, the cell's four node lines along it are the four lanes: (ob, oc) = (0, 0),
    // (1, 0), (0, 1), (1, 1) over the other two axes b and c.
    F4 correction = F4{0.0f, 0.0f, 0.0f, 0.0f};
    for (int axis = 0; axis < 3; ++axis) {
      const float bend = t[axis] * (1.0f - t[axis]) * 0.5f;
      if (bend <= 0.0f) continue;
      // Along `axis`, second differences at the cell's two node layers idx and idx + 1 (0 on
      // the grid's faces) from four values per line, blended over the other two axes.
      const int b = (axis + 1) % 3, c = (axis + 2) % 3;
      const std::ptrdiff_t sa = stride[axis], sb = stride[b], sc = stride[c];
      auto line = [&](std::ptrdiff_t at) {
        const float* p = base + at * sa;
        return F4{p[0], p[sb], p[sc], p[sb + sc]};
      };
      const F4 v0 = line(0), v1 = line(1);
      const F4 zero{0.0f, 0.0f, 0.0f, 0.0f};
      const F4 d0 = idx[axis] > 0 ? line(-1) - 2.0f * v0 + v1 : zero;
      const F4 d1 = idx[axis] + 1 < n[axis] - 1 ? v0 - 2.0f * v1 + line(2) : zero;
      const float ub = 1.0f - t[b], uc = 1.0f - t[c];
      const F4 w{ub * uc, t[b] * uc, ub * t[c], t[b] * t[c]};
      correction += bend * w * (d0 + (d1 - d0) * t[axis]);
    }
    return trilinear - (correction[0] + correction[1] + correction[2] + correction[3]);
  }
};

// Bound on the slope of the trilinear interpolant of distance values (each axis difference of
// a distance is at most the spacing): lets a sphere skip its sample while the last one, minus
// the most the field can have dropped since, still keeps it clear.
constexpr float kInterpolantLipschitz = 1.7321f;

}  // namespace

// One finger's advance with joints firstFree.. moving: what evaluate() needs, and each moving
// sphere's last sample (curl and clearance) for skipping samples that cannot matter.
struct OursSolver::Stage {
  int finger = 0;
  int firstFree = 0;
  const glm::mat3* toBox = nullptr;
  glm::vec3 toBoxOffset{0.0f};
  const FastSampler* sample = nullptr;
  bool lazy = false;    // false until every sphere has a sample
  float aStart = 0.0f;  // where the stage began: polish() never opens the joints past it
  bool polish = true;   // false: the exact check replaces polish()
  std::array<float, kMaxSpheres> lastA{};
  std::array<float, kMaxSpheres> lastG{};
};

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
    float spacing = kSphereSpacing;
    for (int attempt = 0; attempt < 8; ++attempt) {
      int count = 1;
      for (int b = 1; b < n; ++b) {
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
    {
      const float r = hand.jointRadius(joints[1]);
      const float s = spacing * r;
      addSphere(0, 1.0f, std::sqrt(r * r + 0.25f * s * s) - r);
    }
    for (int b = 1; b < n; ++b) {
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

void OursSolver::evaluate(Stage& st, const JointCurls& curls, float a, Eval& e,
                          bool corrected) const {
  const FingerRig& fr = fingers_[st.finger];
  const int n = fr.joints;
  std::array<glm::vec3, kMaxJoints + 1> hand{};
  jointPositions(st.finger, curls, hand);
  std::array<glm::vec3, kMaxJoints + 1> uvw{};
  for (int j = 0; j <= n; ++j) uvw[j] = *st.toBox * hand[j] + st.toBoxOffset;

  const std::array<float, kMaxSpheres>& speed = fr.speed[st.firstFree];
  // Lower bounds on each sphere's clearance from its last sample. Spheres whose bound allows a
  // step well beyond the smallest one, and that are not near the surface, keep their bound.
  std::array<float, kMaxSpheres> bound{};
  float minStepBound = std::numeric_limits<float>::max();
  if (st.lazy) {
    for (int i = 0; i < fr.sphereCount; ++i) {
      if (fr.spheres[i].bone < st.firstFree) continue;
      bound[i] = st.lastG[i] - kInterpolantLipschitz * speed[i] * std::abs(a - st.lastA[i]);
      if (speed[i] > 0.0f)
        minStepBound = std::min(minStepBound, std::max(bound[i], 0.0f) / speed[i]);
    }
  }
  e = Eval{};
  for (int i = 0; i < fr.sphereCount; ++i) {
    const Sphere& s = fr.spheres[i];
    if (s.bone < st.firstFree) continue;  // stopped: it cannot move any more
    float g;
    float value = 0.0f;
    bool sampled = true;
    if (st.lazy && bound[i] > kCorrectBand && speed[i] > 0.0f &&
        bound[i] / speed[i] > 2.0f * minStepBound) {
      g = std::min(bound[i], kCorrectBand);
      sampled = false;
      e.gTri = std::min(e.gTri, g);
    } else {
      const glm::vec3 c = uvw[s.bone] + s.t * (uvw[s.bone + 1] - uvw[s.bone]);
      value = (*st.sample)(c);
      g = value - s.testRadius;
      st.lastA[i] = a;
      st.lastG[i] = g;
      e.gTri = std::min(e.gTri, g);
      if (g < kCorrectBand) {
        // Advancing: stop on whichever of the two says nearer (a thin part or a sharp convex
        // edge reads too far on the trilinear field). Polishing: the corrected one alone.
        const float fixedValue = st.sample->corrected(c, value);
        if (corrected || fixedValue < value) {
          value = fixedValue;
          g = value - s.testRadius;
        }
      }
    }
    if (g < e.g) {
      e.g = g;
      e.arg = i;
      e.value = sampled ? value : g + s.testRadius;
    }
    if (speed[i] > 0.0f) e.step = std::min(e.step, std::max(g, 0.0f) / speed[i]);
  }
  st.lazy = true;
  if (e.arg >= 0) {
    const Sphere& s = fr.spheres[e.arg];
    e.point = hand[s.bone] + s.t * (hand[s.bone + 1] - hand[s.bone]);
  }
}

// Advances joints firstFree.. together from curl `a` until a sphere they move touches or they
// reach 1. Returns the final curl; `touching` is the touching sphere or -1.
//
// Why the distance bound never steps over a feature: a step moves every sphere centre by at most
// its clearance g (speed bounds are upper bounds). The trilinear interpolant of node values that
// are distances is sqrt(3)-Lipschitz, so over that motion it cannot fall from g to below zero
// and rise back above zero (that needs a slope of 2). Every crossing of the stop distance is thus
// seen by some sample, and then bracketed and refined.
float OursSolver::stage(Stage& st, JointCurls& curls, float a, int& touching, glm::vec3& touchPoint,
                        float& touchValue) const {
  const FingerRig& fr = fingers_[st.finger];
  const int firstFree = st.firstFree;
  const int n = fr.joints;
  // With the exact check after it, a stop within the field's own error is all the check needs.
  const float tol = st.polish ? kContactTolerance : kFieldStopTolerance;
  auto at = [&](float v, Eval& e) {
    for (int j = firstFree; j < n; ++j) curls[j] = v;
    evaluate(st, curls, v, e, false);
  };
  const float aStart = a;
  auto finish = [&](float v, Eval e) {
    st.aStart = aStart;
    if (st.polish) v = polish(st, curls, v, e);
    for (int j = firstFree; j < n; ++j) curls[j] = v;
    touching = e.arg;
    touchPoint = e.point;
    touchValue = e.value;
    return v;
  };

  Eval lo;
  at(a, lo);
  if (lo.arg < 0) {  // nothing moves
    touching = -1;
    return a;
  }
  if (lo.g <= tol) return finish(a, lo);  // touching (or already inside) where it starts

  float aLo = a, aPrev = a;
  Eval prev;
  bool havePrev = false;
  Eval hi;
  float aHi = 1.0f;
  bool bracketed = false;
  for (int it = 0; it < kMaxAdvanceIterations; ++it) {
    if (aLo >= 1.0f) {
      touching = -1;
      return 1.0f;
    }
    float step = lo.step;
    if (havePrev && lo.g < kSecantBand && prev.g > lo.g) {
      // Aim half a tolerance above the surface: a linear g lands inside [0, tol].
      const float secant = (aLo - aPrev) * (lo.g - 0.5f * tol) / (prev.g - lo.g);
      step = std::max(step, std::min(secant, fr.maxJump[firstFree]));
    }
    step = std::max(step, fr.minStep[firstFree]);
    const float aNext = std::min(1.0f, aLo + step);
    Eval next;
    at(aNext, next);
    if (next.g < 0.0f) {
      aHi = aNext;
      hi = next;
      bracketed = true;
      break;
    }
    if (next.g <= tol) return finish(aNext, next);
    aPrev = aLo;
    prev = lo;
    havePrev = true;
    aLo = aNext;
    lo = next;
  }
  if (!bracketed) {  // iteration cap (grazing for very long): stop where it is, outside
    return finish(aLo, lo);
  }

  // Regula falsi (Illinois) on g - tol/2 between an outside and an inside pose; the outside
  // end is returned, so no sphere ends inside the field.
  float fLo = lo.g - 0.5f * tol, fHi = hi.g - 0.5f * tol;
  int side = 0;
  for (int it = 0; it < kMaxRefineIterations && lo.g > tol; ++it) {
    const float width = aHi - aLo;
    if (width < 1e-7f) break;
    float m = aLo + width * fLo / (fLo - fHi);
    m = std::clamp(m, aLo + 0.01f * width, aHi - 0.01f * width);
    Eval mid;
    at(m, mid);
    if (mid.g < 0.0f) {
      aHi = m;
      hi = mid;
      fHi = mid.g - 0.5f * tol;
      if (side == -1) fLo *= 0.5f;
      side = -1;
    } else {
      aLo = m;
      lo = mid;
      fLo = mid.g - 0.5f * tol;
      if (side == 1) fHi *= 0.5f;
      side = 1;
    }
  }
  // Contact is the hi side's first touching sphere when the bracket closed on a grazing pose.
  if (lo.g > tol && hi.arg >= 0) {
    Eval e = lo;
    e.arg = hi.arg;
    return finish(aLo, e);
  }
  return finish(aLo, lo);
}

// Moves a contact found on the trilinear field to the root of the curvature-corrected field
// (FastSampler::corrected) by a few secant steps from the trilinear answer. Only spheres near
// the surface are corrected, a closing move is bounded (kMaxPolishClose of sphere motion, so it
// cannot step over anything) and a forward move may not take the trilinear clearance below
// -kMaxTrilinearOvershoot (guards against creases where the correction is unreliable). The
// result is a pose whose corrected clearance is in [0, tol] when one was found, else the safest
// pose tried.
float OursSolver::polish(Stage& st, JointCurls& curls, float a, Eval& e) const {
  const FingerRig& fr = fingers_[st.finger];
  const int n = fr.joints;
  const float tol = kContactTolerance;
  auto at = [&](float v, Eval& out) {
    for (int j = st.firstFree; j < n; ++j) curls[j] = v;
    evaluate(st, curls, v, out, true);
  };
  Eval e0;
  at(a, e0);
  if (e0.arg < 0) return a;
  if (e0.g >= 0.0f && e0.g <= tol) {
    e = e0;
    return a;
  }
  const float speed = std::max(fr.speed[st.firstFree][e0.arg], 1e-6f);
  const float lowest = std::max(st.aStart, a - kMaxPolishOpen / speed);
  const float highest = std::min(1.0f, a + kMaxPolishClose / speed);
  // Second point for the secant: a small step toward where the root should be.
  float a1 = std::clamp(a + (e0.g > 0.0f ? 1.0f : -1.0f) * 0.0005f / speed, lowest, highest);
  if (a1 == a) return a;
  float aPrev = a, gPrev = e0.g;
  float bestA = a;
  Eval best = e0;
  bool bestSafe = e0.g >= 0.0f;
  for (int it = 0; it < kMaxPolishIterations; ++it) {
    Eval e1;
    at(a1, e1);
    const bool guard = a1 <= a || e1.gTri >= -kMaxTrilinearOvershoot;
    const bool safe = e1.g >= 0.0f && guard;
    if (safe && (!bestSafe || a1 > bestA)) {
      bestA = a1;
      best = e1;
      bestSafe = true;
    } else if (!bestSafe && !safe && a1 < bestA) {
      bestA = a1;  // nothing safe yet: keep the most open pose
      best = e1;
    }
    if (safe && e1.g <= tol) break;
    if (!guard) break;
    const float slope = (e1.g - gPrev) / (a1 - aPrev);
    if (!(slope < 0.0f)) break;  // the corrected field does not fall as the finger closes here
    const float next = std::clamp(a1 + (0.5f * tol - e1.g) / slope, lowest, highest);
    aPrev = a1;
    gPrev = e1.g;
    if (std::abs(next - a1) < 1e-7f) break;
    a1 = next;
  }
  // Nothing safe found (the corrected field says the trilinear contact is inside and the
  // opening range ran out): the most open pose tried is the best there is.
  for (int j = st.firstFree; j < n; ++j) curls[j] = bestA;
  e = best;
  return bestA;
}

// What exactStop() reads besides the finger: the exact source, the map from the corrected hand
// frame (where the fingers are) to the scene's hand frame (where the source answers), and the
// field, to choose which spheres to sample.
struct OursSolver::ExactContext {
  const ExactDistanceSource* source = nullptr;
  Pose sceneFromHand;
  const FastSampler* sample = nullptr;
  const glm::mat3* toBox = nullptr;
  glm::vec3 toBoxOffset{0.0f};
  // Per sphere of the finger being solved: the source's closest feature at its last sample
  // (ExactSample::feature), handed back as the next search's hint.
  std::array<uint32_t, OursSolver::kMaxSpheres>* hints = nullptr;
};

namespace {

// The closest checked sphere of one pose on the exact source.
struct ExactEval {
  float g = std::numeric_limits<float>::infinity();  // exact clearance, metres
  int arg = -1;                                      // sphere; -1: none within the band
  float distance = 0.0f;                             // exact distance of its centre
  glm::vec3 centre{0.0f};                            // its centre, corrected hand frame
};

}  // namespace

// Corrects the curl of joints firstFree.. (which the field stopped at `a`) on the exact source.
// Checked: the spheres on bones firstFree..lastBone (the ones this stop freezes) that the field
// puts within kExactBand of touching, plus the touching one. A sphere's clearance is measured
// against its own bone's capsule: the exact closest point q of its centre, its distance to the
// bone's axis minus the capsule radius there (at most the centre's distance minus its radius;
// it sees a bone that leans into the surface next to the centre). Secant steps on the smallest
// clearance bring it into [0, kContactTolerance]. Closing past the field's stop is limited so
// that no sphere left unchecked (distal ones included) moves more than its clearance on the
// field; opening may go below where the group began (down to 0), which is how a sphere the
// previous group left inside comes out. Spheres are re-chosen at every pose tried. The most
// closed pose with no checked sphere inside is kept; if none was found, the group opens in
// doubling steps while that helps and the least inside pose is kept. Reports the closest sphere
// as the touching one when it is within the tolerance (or when the field said it touched).
float OursSolver::exactStop(const ExactContext& cx, int f, int firstFree, int lastBone, float a,
                            JointCurls& curls, int& touching, glm::vec3& touchPoint,
                            float& touchValue, int& samples) const {
  const FingerRig& fr = fingers_[f];
  const int n = fr.joints;
  const float tol = kContactTolerance;
  const std::array<float, kMaxSpheres>& speed = fr.speed[firstFree];
  std::array<glm::vec3, kMaxJoints + 1> hand{};
  auto setCurl = [&](float v) {
    for (int j = firstFree; j < n; ++j) curls[j] = v;
  };
  auto centreOf = [&](const Sphere& s) {
    return hand[s.bone] + s.t * (hand[s.bone + 1] - hand[s.bone]);
  };

  std::array<int, kMaxSpheres> cand{};
  std::array<bool, kMaxSpheres> isCand{};
  int count = 0;
  float maxSpeed = 0.0f;  // over the candidates
  std::array<glm::vec3, 1> points{};
  std::array<float, 1> bounds{};
  std::array<ExactSample, 1> found{};
  // Each candidate's last exact clearance (or the lower bound a bounded search gave) and curl:
  // the centre's distance is 1-Lipschitz and moves at most speed * |da|, so a candidate whose
  // bound stays kLazyMargin above the smallest one cannot be the closest and is not sampled.
  // `fresh`: not sampled yet (searched over the whole band; its lower bound is its field
  // clearance minus kFieldTrust).
  std::array<float, kMaxSpheres> lastG{}, lastA{};
  std::array<bool, kMaxSpheres> fresh{};
  // Each candidate's d(clearance)/d(curl) at its last exact sample: the direction from its
  // closest point (the distance's gradient) against its centre's velocity. NaN: none (the centre
  // was on the surface, or the search found nothing within its bound).
  std::array<float, kMaxSpheres> exactSlope{};
  // Candidates are chosen on the field at every pose tried: a sphere of the frozen bones that
  // comes within the band joins them. Every other moving sphere (distal ones too) limits how
  // far the group may close from here: no more than its clearance on the field allows (the
  // interpolant's slope bound), so none reaches the surface unseen. `highest`: that limit.
  float highest = 1.0f;
  // Each sphere's last trilinear clearance read here and its curl: the trilinear interpolant is
  // kInterpolantLipschitz-Lipschitz, so while that bound keeps a sphere beyond kExactBand +
  // kCorrectBand (where neither reading can make it a candidate) it is not read again and the
  // bound limits the reach instead (a little more cautious than its value).
  std::array<float, kMaxSpheres> readA{}, readG{};
  std::array<bool, kMaxSpheres> read{};
  auto select = [&](float v) {
    float reach = 1.0f - v;
    for (int i = 0; i < fr.sphereCount; ++i) {
      const Sphere& s = fr.spheres[i];
      if (s.bone < firstFree || isCand[i]) continue;
      if (read[i]) {
        const float bound = readG[i] - kInterpolantLipschitz * speed[i] * std::abs(v - readA[i]);
        if (bound >= kExactBand + kCorrectBand) {
          if (speed[i] > 0.0f) reach = std::min(reach, bound / (kInterpolantLipschitz * speed[i]));
          continue;
        }
      }
      const glm::vec3 uvw = *cx.toBox * centreOf(s) + cx.toBoxOffset;
      const float value = (*cx.sample)(uvw);
      float g = value - s.testRadius;
      read[i] = true;
      readA[i] = v;
      readG[i] = g;
      // As in evaluate(): the corrected reading only matters where it can be lower.
      if (g < kExactBand + kCorrectBand) {
        g = std::min(value, cx.sample->corrected(uvw, value)) - s.testRadius;
      }
      if (s.bone <= lastBone && (g < kExactBand || i == touching)) {
        isCand[i] = true;
        fresh[count] = true;
        lastA[count] = v;
        lastG[count] = g - kFieldTrust;
        cand[count++] = i;
        maxSpeed = std::max(maxSpeed, speed[i]);
      } else if (speed[i] > 0.0f) {
        reach = std::min(reach, std::max(g, 0.0f) / (kInterpolantLipschitz * speed[i]));
      }
    }
    highest = std::min(1.0f, v + reach);
  };
  setCurl(a);
  jointPositions(f, curls, hand);
  select(a);
  if (count == 0 || !(maxSpeed > 0.0f)) return a;

  // Joint positions a little further along the curl than `hand`, for the spheres' velocities;
  // computed once per pose, when a sample first needs it.
  std::array<glm::vec3, kMaxJoints + 1> ahead{};
  float aheadOf = -1.0f, aheadStep = 0.0f;
  auto velocityOf = [&](const Sphere& s, float v) {
    if (aheadOf != v) {
      aheadStep = v + kVelocityStep <= 1.0f ? kVelocityStep : -kVelocityStep;
      JointCurls c = curls;
      for (int j = firstFree; j < n; ++j) c[j] = v + aheadStep;
      jointPositions(f, c, ahead);
      aheadOf = v;
    }
    const glm::vec3 next = ahead[s.bone] + s.t * (ahead[s.bone + 1] - ahead[s.bone]);
    return (next - centreOf(s)) / aheadStep;
  };
  // Samples candidate k at the current joint positions; records its clearance (or the lower
  // bound the bounded search gave) and, from the closest point, its exact slope along the curl.
  auto sampleOne = [&](int k, float v, ExactEval& r) {
    const Sphere& s = fr.spheres[cand[k]];
    exactSlope[k] = std::numeric_limits<float>::quiet_NaN();
    const float radius = s.radius + fr.thresholdOffset;
    points[0] = cx.sceneFromHand.transformPoint(centreOf(s));
    const float upper = fresh[k] ? kExactBand : lastG[k] + speed[cand[k]] * std::abs(v - lastA[k]);
    fresh[k] = false;
    bounds[0] = radius + std::clamp(upper + 0.0005f, 0.0005f, kExactBand);
    uint32_t& hint = (*cx.hints)[size_t(cand[k])];
    found[0].feature = hint;
    cx.source->sample(std::span(points.data(), 1), std::span(bounds.data(), 1),
                      std::span(found.data(), 1));
    ++samples;
    lastA[k] = v;
    if (found[0].feature != std::numeric_limits<uint32_t>::max()) hint = found[0].feature;
    if (!std::isfinite(found[0].distance)) {  // clear by more than the search distance
      lastG[k] = bounds[0] - radius;
      return;
    }
    float g = found[0].distance - radius;
    {
      // The signed distance grows away from the closest point outside and toward it inside.
      const glm::vec3 away = points[0] - found[0].closest;
      const float length = glm::length(away);
      if (length > 1e-6f) {
        const glm::vec3 velocity = cx.sceneFromHand.transformVector(velocityOf(s, v));
        exactSlope[k] =
            (found[0].distance < 0.0f ? -1.0f : 1.0f) * glm::dot(away, velocity) / length;
      }
    }
    if (found[0].distance > 0.0f) {
      // The sphere at the proximal joint (bone 0, t = 1) starts the first phalanx's capsule.
      const int b = s.bone == 0 ? 1 : s.bone;
      const glm::vec3 pa = cx.sceneFromHand.transformPoint(hand[b]);
      const glm::vec3 pb = cx.sceneFromHand.transformPoint(hand[b + 1]);
      const glm::vec3 axis = pb - pa;
      const float len2 = glm::dot(axis, axis);
      const float t =
          len2 > 0.0f ? std::clamp(glm::dot(found[0].closest - pa, axis) / len2, 0.0f, 1.0f) : 0.0f;
      const float rr =
          fr.jointRadius[b] + t * (fr.jointRadius[b + 1] - fr.jointRadius[b]) + fr.thresholdOffset;
      g = std::min(g, glm::length(found[0].closest - (pa + t * axis)) - rr);
    }
    lastG[k] = g;
    if (g < r.g) {
      r.g = g;
      r.arg = cand[k];
      r.distance = found[0].distance;
      r.centre = centreOf(s);
    }
  };
  // The smallest clearance over the candidates: sampled in order of their lower bounds, until
  // the smallest found is below every bound left (those cannot be nearer, nor inside when it
  // is not). Returns how many were sampled.
  auto measureOnce = [&](float v, ExactEval& r, bool forceFresh) {
    std::array<float, kMaxSpheres> lower{};
    std::array<int, kMaxSpheres> order{};
    for (int k = 0; k < count; ++k) {
      lower[k] = fresh[k] && forceFresh ? -std::numeric_limits<float>::infinity()
                                        : lastG[k] - speed[cand[k]] * std::abs(v - lastA[k]);
      int pos = k;
      while (pos > 0 && lower[order[pos - 1]] > lower[k]) {
        order[pos] = order[pos - 1];
        --pos;
      }
      order[pos] = k;
    }
    r = ExactEval{};
    int m = 0;
    for (int q = 0; q < count; ++q) {
      const int k = order[q];
      if (lower[k] >= r.g) break;
      sampleOne(k, v, r);
      ++m;
    }
    return m;
  };
  // Nothing sampled near: the spheres skipped may be nearer than their bounds say (opening
  // moves them away, which a speed bound cannot tell), so all are searched over the band.
  auto measure = [&](float v, ExactEval& r) {
    setCurl(v);
    jointPositions(f, curls, hand);
    select(v);
    if (measureOnce(v, r, false) < count && r.arg < 0) {
      for (int k = 0; k < count; ++k) fresh[k] = true;
      measureOnce(v, r, true);
    }
    if (r.arg < 0) {
      r.g = kExactBand;
      for (int k = 0; k < count; ++k) r.g = std::min(r.g, lastG[k]);
    }
  };

  // Whether every candidate but `arg` is certainly clear at curl v (bounds from the samples).
  auto othersClear = [&](float v, int arg) {
    for (int k = 0; k < count; ++k) {
      if (cand[k] != arg && lastG[k] - speed[cand[k]] * std::abs(v - lastA[k]) < 0.0f) {
        return false;
      }
    }
    return true;
  };

  ExactEval cur;
  measure(a, cur);
  if (cur.arg < 0 && touching < 0) {  // nothing near: the field's pose stands
    setCurl(a);
    return a;
  }
  float aCur = a, aPrev = a, gPrev = 0.0f;
  bool havePrev = false;
  int argPrev = -1;
  float aSafe = -1.0f, aOpen = a;  // most closed pose with nothing inside; most open tried
  ExactEval safe, open = cur, least = cur;
  float aLeast = a;  // the pose with the largest clearance tried
  for (int it = 0;; ++it) {
    if (cur.g >= 0.0f && aCur > aSafe) {
      aSafe = aCur;
      safe = cur;
    }
    if (aCur < aOpen) {
      aOpen = aCur;
      open = cur;
    }
    if (cur.g > least.g) {
      aLeast = aCur;
      least = cur;
    }
    if ((cur.g >= 0.0f && cur.g <= tol) || it >= kMaxExactIterations) break;
    const float argSpeed = cur.arg >= 0 ? std::max(speed[cur.arg], 1e-4f) : maxSpeed;
    // Newton on the exact clearances: every candidate sampled at this pose that comes nearer
    // as the group closes limits the step to where its linear prediction reaches tol / 2. The
    // distance's gradient is exact (the unit vector from the closest point), so the prediction
    // errs only by the surface's curvature over the motion: about d^2 / (2 R) for a motion d
    // past a surface of radius R, hundredths of a millimetre here. Closing on it moves no
    // sphere more than its clearance plus kNewtonReach (a wrong linearization must not carry
    // a sphere through a thin part).
    float newton = std::numeric_limits<float>::infinity();
    int limiting = -1;
    for (int k = 0; k < count; ++k) {
      if (lastA[k] != aCur || !(exactSlope[k] < 0.0f)) continue;
      const float root = aCur + (0.5f * tol - lastG[k]) / exactSlope[k];
      if (root < newton) {
        newton = root;
        limiting = cand[k];
      }
    }
    const bool useNewton = limiting >= 0;
    // Without one (every slope known is flat or receding), a secant through two samples of
    // the same sphere, else a conservative step.
    const bool secant = !useNewton && havePrev && argPrev == cur.arg && aCur != aPrev;
    const float slope = secant ? (cur.g - gPrev) / (aCur - aPrev) : 0.0f;
    float next;
    if (useNewton) {
      next = std::min(newton, aCur + (std::max(cur.g, 0.0f) + kNewtonReach) / maxSpeed);
    } else if (slope < 0.0f) {
      next = aCur + (0.5f * tol - cur.g) / slope;
    } else if (cur.g > 0.0f) {
      // The closest sphere does not come nearer as the group closes (it slides along
      // the surface): advance conservatively, no checked sphere moving more than its
      // clearance.
      next = aCur + std::max(cur.g, 0.001f) / maxSpeed;
    } else {
      next = aCur + (0.5f * tol - cur.g) / -argSpeed;
    }
    // Opening is safe but a flat secant can ask for far too much: a few times the
    // least needed.
    next = std::max(next, aCur - 4.0f * (std::abs(cur.g) + 0.0005f) / argSpeed);
    // The group may open below where it started: a sphere the previous group left
    // inside (it was distal to that group's check) can only come out by opening this
    // group further.
    const float lowest = 0.0f;
    next = std::clamp(next, lowest, highest);
    // Never close past a pose known to be inside, nor open past one known to be
    // clear.
    if (aSafe >= 0.0f && next < aSafe) next = aSafe + 0.5f * (aCur - aSafe);
    if (std::abs(next - aCur) < 1e-7f) break;
    // A small last correction is taken without sampling it again: the step errs by a small
    // fraction of it (Newton: the curvature term above; a secant: more), so the pose lands
    // within that fraction of touching, and the other candidates' bounds keep them clear of it.
    // (Only when the closest sphere is the one that set the step.)
    const float unverified = limiting == cur.arg ? kUnverifiedNewton
                             : useNewton         ? 0.0f
                                                 : kUnverifiedStep;
    if (cur.arg >= 0 && std::abs(cur.g - 0.5f * tol) <= unverified && othersClear(next, cur.arg)) {
      setCurl(next);
      jointPositions(f, curls, hand);
      aSafe = next;
      safe = cur;
      safe.centre = centreOf(fr.spheres[cur.arg]);
      safe.distance = cur.distance - (cur.g - 0.5f * tol);
      safe.g = 0.5f * tol;
      break;
    }
    aPrev = aCur;
    gPrev = cur.g;
    argPrev = cur.arg;
    havePrev = true;
    aCur = next;
    measure(aCur, cur);
  }
  if (aSafe < 0.0f) {
    // Everything tried was inside: open from the most open pose in doubling steps
    // while that helps (a part behind the finger gets deeper as it opens), then keep
    // the least inside.
    const float s0 = std::max(-open.g, 0.0005f) / std::max(speed[std::max(open.arg, 0)], 1e-3f);
    for (int k = 0; k < kMaxExactBackoff && aOpen > 0.0f; ++k) {
      const float v = std::max(0.0f, aOpen - s0 * float(1 << k));
      ExactEval e;
      measure(v, e);
      const bool better = e.g > open.g;
      aOpen = v;
      open = e;
      if (e.g > least.g) {
        aLeast = v;
        least = e;
      }
      if (e.g >= 0.0f || !better) break;
    }
    aSafe = aLeast;
    safe = least;
  }
  setCurl(aSafe);
  if (safe.arg >= 0 && (touching >= 0 || safe.g <= tol)) {
    touching = safe.arg;
    touchPoint = safe.centre;
    touchValue = safe.distance;
  }
  return aSafe;
}

Status OursSolver::solve(const GraspScene& scene, GraspResult& out) const {
  if (!prepared_) return Status::invalid_argument;
  if (scene.field == nullptr) return Status::invalid_argument;
  const SdfGrid& field = *scene.field;
  if (field.values().size() != field.box().nodeCount() || field.values().empty()) {
    return Status::invalid_argument;
  }

  out = GraspResult{};
  if (options_.approach) {
    Result<ApproachResult> approach = approachPose(field, hand_);
    if (approach.ok()) out.handCorrection = approach->handCorrection;
  }
  glm::mat3 toBox;
  glm::vec3 toBoxOffset;
  normalizedMap(field.box(), out.handCorrection, toBox, toBoxOffset);
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
        const int lastBone = touching >= 0 ? int(fr.spheres[touching].bone) : n - 1;
        a = exactStop(cx, f, firstFree, lastBone, a, curls, touching, point, value,
                      out.exactSamples);
        checkTime += Clock::now() - t0;
      }
      if (touching < 0) break;
      // The most distal contact is the one reported: it is where the finger ends up resting.
      state.contact = true;
      state.contactPoint = point;
      state.distance = value;
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
  // The palm side of the hand is -Y of the palm joint.
  const glm::vec3 palmNormal = palm.transformVector(glm::vec3(0.0f, -1.0f, 0.0f));
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
