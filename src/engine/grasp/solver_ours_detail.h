// Internal to the "ours" strategy (grasp/solver_ours*.cpp), not part of the engine's interface:
// the constants the solver's stages share, the fast trilinear sampler, and the per-stage state
// the field advancement (solver_ours_field.cpp) and the exact check (solver_ours_exact.cpp) read.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>

#include "grasp/solver_ours.h"

namespace sdfg::ours_detail {

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
// Exact check (exactStop()): at most this many steps on the exact clearance, and this many
// doubling opening steps when every pose tried was inside. Newton converges in two or three; the
// cap is for a finger that slides along the surface a millimetre or two clear, where each step is
// cut short by the reach of the spheres left unchecked (at 8 such a finger stopped 2 mm short on
// the dragon).
constexpr int kMaxExactIterations = 32;
constexpr int kMaxExactBackoff = 6;
// Field stops per finger group that the exact check may find false (nothing near) and close on
// from before the finger is left where the last check ended.
constexpr int kMaxFalseStops = 4;
// A candidate not sampled yet is taken to be no nearer than its field clearance minus this (the
// 16^3 field's error is within it on all but the sharpest parts), so when the closest one's
// exact clearance is below that bound the others are not sampled: most stops then take one
// sample per pose instead of one per candidate. Where the stop is decided every candidate is
// sampled anyway (kVerifyBand): a thin spike the 16^3 field smooths away is off by more.
constexpr float kFieldTrust = 0.001f;  // metres
// Every pose the exact check ends on is sampled: a last Newton step taken unsampled (it saved a
// fifth of the samples) landed up to 0.8 mm inside near the sharp parts of the research meshes,
// where the gradient at the start of a 1 mm step says little about its end. A pose whose closest
// clearance is within this of touching is first checked against every candidate (verifyFresh in
// exactStop()), so that none is trusted on its field reading alone where the stop is decided.
constexpr float kVerifyBand = 0.001f;  // metres
// Curl step of the finite difference that gives a sphere's velocity along the curl.
constexpr float kVelocityStep = 1e-3f;
// Where the exact check follows, the field's stop is refined only to this: the 16^3 field is
// off by about this much near curved parts anyway, and the check corrects the rest.
constexpr float kFieldStopTolerance = 0.0005f;  // metres
// A Newton step of the exact check moves no sphere more than its clearance plus this.
constexpr float kNewtonReach = 0.002f;  // metres
// Kinematics rebuilt from fingerPose() must match it this closely, else solve() asks the model.
constexpr float kKinematicsTolerance = 2e-5f;  // metres

inline float quatAngle(const glm::quat& q) {
  const float w = std::min(1.0f, std::abs(q.w));
  return 2.0f * std::acos(w);
}

// Hand space -> normalized box coordinates as an affine map, so one matrix product per joint
// replaces a pose inverse per sample.
inline void normalizedMap(const GridBox& box, const Pose& boxHandFromHand, glm::mat3& m,
                          glm::vec3& t) {
  const glm::mat3 boxFromHand = glm::mat3_cast(glm::conjugate(box.handFromBox.orientation));
  glm::mat3 scale(1.0f);
  for (int a = 0; a < 3; ++a) scale[a][a] = 1.0f / box.size[a];
  const glm::mat3 toNormalized = scale * boxFromHand;
  // p_norm = S R^T (C p - t_box) + 0.5 with C the hand correction.
  const glm::mat3 c = glm::mat3_cast(boxHandFromHand.orientation);
  m = toNormalized * c;
  t = toNormalized * (boxHandFromHand.position - box.handFromBox.position) + glm::vec3(0.5f);
}

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

}  // namespace sdfg::ours_detail

namespace sdfg {

using namespace ours_detail;  // NOLINT: the solver's own files only

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

}  // namespace sdfg
