// clearHand() (grasp/hand_clearance.h): the smallest rigid correction that clears the open hand.
//
// Two searches, each checked on the same distances, and the one that moves the hand least wins:
// - a sequential least-norm projection: linearise every part's clearance about the current
//   correction (distance plus gradient times motion), find the smallest correction that meets
//   every linearised constraint (a small quadratic programme solved in its dual by projected
//   Gauss-Seidel), move there, repeat. Exact on planes in one step, and it combines directions
//   where several faces push (a hand in a concave corner).
// - a march along a few directions (the hand's axes, and the directions the deepest parts point
//   out): along each, step by the largest clearance deficit, which no distance can recover
//   faster (a distance changes by at most the motion), so the first clear point is never
//   stepped over. It handles what the linearisation cannot: thin parts whose two faces push a
//   bone both ways, and convex corners, where the single-face exit is the smallest.
// A turn about the palm is then tried with the projection in six variables, its cost the
// motion it gives at kLever from the pivot. Every search runs on the field first and then, where
// the scene has an exact source, on the exact distance from where the field's search ended, so
// the exact searches (microseconds each on dense meshes) are spent only near the answer.
#include "grasp/hand_clearance.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "grasp/solver.h"

namespace sdfg {
namespace {

// Parts within this of the margin constrain the projection's step.
constexpr float kActiveBand = 0.005f;  // metres
// The grab-box field is taken to be within this of the exact distance: a part whose field
// clearance exceeds the margin by the band plus this is not sampled exactly.
constexpr float kFieldTrust = 0.003f;  // metres
// Exact searches reach this far past what a part needs.
constexpr float kSearchReach = 0.01f;  // metres
// A turn costs as much as the motion it gives this far from the pivot (about half a hand).
constexpr float kLever = 0.1f;  // metres
constexpr int kDualSweeps = 200;
// Directions marched: the hand's six axis directions plus this many from the deepest parts.
constexpr int kPartDirections = 8;
constexpr int kMaxMarchSteps = 80;
// Smallest march step: a deficit this small is met by the margin's slack anyway.
constexpr float kMinMarchStep = 0.0001f;  // metres
// Spheres along a capsule are at most this many of its smaller radius apart.
constexpr float kPartSpacing = 0.7f;

struct Probe {
  float c = 0.0f;         // clearance: distance - coverRadius (a lower bound when far)
  glm::vec3 g{0.0f};      // unit gradient of the distance (zero: unknown, unconstrained)
  glm::vec3 point{0.0f};  // the part's centre, scene hand frame
};
using Probes = std::array<Probe, kMaxHandParts>;

// Clearance of every part of a hand placed by a correction, from the exact source where there
// is one (the field decides which parts are near enough to ask it), else the field.
class Measure {
 public:
  Measure(std::span<const HandPart> parts, const SdfGrid* field, const ExactDistanceSource* exact,
          float margin, const Pose& fieldFromHand)
      : parts_(parts),
        field_(field),
        exact_(exact),
        margin_(margin),
        fieldFromHand_(fieldFromHand),
        handFromField_(fieldFromHand.inverse()) {
    hints_.fill(std::numeric_limits<uint32_t>::max());
  }

  // Fills out[i] for every part; returns the smallest clearance.
  float operator()(const Pose& correction, Probes& out) {
    const size_t n = parts_.size();
    size_t asked = 0;
    std::array<uint16_t, kMaxHandParts> which{};
    for (size_t i = 0; i < n; ++i) {
      Probe& p = out[i];
      const HandPart& part = parts_[i];
      p.point = correction.transformPoint(part.centre);
      p.g = glm::vec3(0.0f);
      p.c = std::numeric_limits<float>::infinity();
      float fieldD = std::numeric_limits<float>::infinity();
      bool inBox = false;
      if (field_ != nullptr) {
        const glm::vec3 q = fieldFromHand_.transformPoint(p.point);
        const glm::vec3 uvw = field_->box().handToNormalized(q);
        inBox = glm::all(glm::greaterThanEqual(uvw, glm::vec3(0.0f))) &&
                glm::all(glm::lessThanEqual(uvw, glm::vec3(1.0f)));
        if (inBox) {
          fieldD = field_->sample(q);
          p.c = fieldD - part.coverRadius;
          if (gradients) {
            const glm::vec3 g = handFromField_.transformVector(field_->gradient(q));
            const float gl = glm::length(g);
            if (gl > 1e-3f) p.g = g / gl;
          }
        }
      }
      if (exact_ == nullptr || !exactOn) continue;
      // Clear by more than the field can be wrong: no exact sample needed.
      if (inBox && p.c > margin_ + kActiveBand + kFieldTrust) continue;
      points_[asked] = p.point;
      reach_[asked] = std::max(part.coverRadius + margin_ + kActiveBand + kSearchReach,
                               inBox ? -fieldD + kSearchReach : 0.0f);
      samples_[asked].feature = hints_[i];
      which[asked++] = uint16_t(i);
    }
    if (asked > 0) {
      exact_->sample(std::span(points_.data(), asked), std::span(reach_.data(), asked),
                     std::span(samples_.data(), asked));
      sampled_ += int(asked);
    }
    for (size_t k = 0; k < asked; ++k) {
      const size_t i = which[k];
      Probe& p = out[i];
      const ExactSample& s = samples_[k];
      hints_[i] = s.feature;
      if (std::isfinite(s.distance)) {
        p.c = s.distance - parts_[i].coverRadius;
        // The distance's gradient is the unit vector from the closest point, away from the
        // surface on the outside and toward it on the inside: (p - closest) / signed distance.
        if (std::abs(s.distance) > 1e-6f) p.g = (p.point - s.closest) / s.distance;
        const float gl = glm::length(p.g);
        if (gl > 1e-3f) p.g /= gl;
      } else if (!(p.c < 0.0f)) {
        // Nothing within the reach, and the field does not put it inside: clear by the reach.
        p.c = reach_[k] - parts_[i].coverRadius;
        p.g = glm::vec3(0.0f);
      }
      // Else deep inside, past the search: the field's value and direction stand.
    }
    float lowest = std::numeric_limits<float>::infinity();
    for (size_t i = 0; i < n; ++i) lowest = std::min(lowest, out[i].c);
    return lowest;
  }

  int sampled() const { return sampled_; }
  // False: the field alone, even where there is an exact source (the searches' first phase).
  bool exactOn = true;
  // False: values only (a march needs no direction; the field's gradient costs six samples).
  bool gradients = true;
  bool hasBoth() const { return field_ != nullptr && exact_ != nullptr; }

 private:
  std::span<const HandPart> parts_;
  const SdfGrid* field_;
  const ExactDistanceSource* exact_;
  float margin_;
  Pose fieldFromHand_;
  Pose handFromField_;
  int sampled_ = 0;
  std::array<uint32_t, kMaxHandParts> hints_{};
  std::array<glm::vec3, kMaxHandParts> points_{};
  std::array<float, kMaxHandParts> reach_{};
  std::array<ExactSample, kMaxHandParts> samples_{};
};

// A correction of translation t and turn w (rotation vector) about `pivot` (start's frame
// image of the palm), applied after `start`.
Pose compose(const Pose& start, const glm::vec3& pivot, const glm::vec3& t, const glm::vec3& w) {
  const float angle = glm::length(w);
  const glm::quat r = angle > 1e-9f ? glm::angleAxis(angle, w / angle) : glm::quat(1, 0, 0, 0);
  Pose c;
  c.orientation = glm::normalize(r * start.orientation);
  c.position = r * (start.position - pivot) + pivot + t;
  return c;
}

float displacement(std::span<const HandPart> parts, const Pose& start, const Pose& c) {
  float d = 0.0f;
  for (const HandPart& p : parts) {
    d = std::max(d, glm::length(c.transformPoint(p.centre) - start.transformPoint(p.centre)));
  }
  return d;
}

struct Candidate {
  Pose correction;
  float clearance = -std::numeric_limits<float>::infinity();
  float moved = std::numeric_limits<float>::infinity();
  bool rotated = false;
  bool valid() const { return clearance >= 0.0f; }
};

// The least-norm projection (see the file comment); `turn` adds the three rotation variables.
// `z` = (t, kLever * w) is where it starts, and where it ended on return; the objective is |z|^2.
Candidate project(std::span<const HandPart> parts, const glm::vec3& pivot, const Pose& start,
                  Measure& measure, Probes& probes, const ClearanceOptions& o, bool turn,
                  int& iterations, std::array<float, 6>& z) {
  const glm::vec3 o0 = start.transformPoint(pivot);
  std::array<std::array<float, 6>, kMaxHandParts> rows{};
  std::array<float, kMaxHandParts> b{}, lambda{}, norm2{};
  const int vars = turn ? 6 : 3;
  Candidate out;
  for (int it = 0; it < o.maxIterations; ++it) {
    ++iterations;
    const glm::vec3 t(z[0], z[1], z[2]), w = glm::vec3(z[3], z[4], z[5]) / kLever;
    const Pose c = compose(start, o0, t, w);
    const float lowest = measure(c, probes);
    if (lowest >= 0.0f) {
      const float moved = displacement(parts, start, c);
      if (moved < out.moved) out = Candidate{c, lowest, moved, turn};
    }
    int m = 0;
    for (size_t i = 0; i < parts.size(); ++i) {
      const Probe& p = probes[i];
      if (!(p.c < o.margin + kActiveBand) || glm::dot(p.g, p.g) < 0.25f) continue;
      std::array<float, 6>& a = rows[m];
      a = {p.g.x, p.g.y, p.g.z, 0.0f, 0.0f, 0.0f};
      if (turn) {
        const glm::vec3 arm = glm::cross(p.point - (o0 + t), p.g) / kLever;
        a[3] = arm.x, a[4] = arm.y, a[5] = arm.z;
      }
      float az = 0.0f, aa = 0.0f;
      for (int v = 0; v < vars; ++v) az += a[v] * z[v], aa += a[v] * a[v];
      b[m] = o.margin - p.c + az;
      norm2[m] = aa;
      lambda[m] = 0.0f;
      ++m;
    }
    if (m == 0) break;  // nothing near: the current correction stands
    std::array<float, 6> next{};
    for (int sweep = 0; sweep < kDualSweeps; ++sweep) {
      float change = 0.0f;
      for (int k = 0; k < m; ++k) {
        float az = 0.0f;
        for (int v = 0; v < vars; ++v) az += rows[k][v] * next[v];
        const float l = std::max(0.0f, lambda[k] + (b[k] - az) / norm2[k]);
        const float d = l - lambda[k];
        if (d == 0.0f) continue;
        lambda[k] = l;
        for (int v = 0; v < vars; ++v) next[v] += d * rows[k][v];
        change = std::max(change, std::abs(d));
      }
      if (change < 1e-7f) break;
    }
    // Opposed constraints (two faces of a thin part) have no common solution and make the
    // multipliers grow: keep the step within reach, the march handles such parts.
    float step2 = 0.0f;
    for (int v = 0; v < 6; ++v) step2 += (next[v] - z[v]) * (next[v] - z[v]);
    const float step = std::sqrt(step2);
    const float limit = 2.0f * o.maxCorrection;
    if (step > limit) {
      for (int v = 0; v < 6; ++v) next[v] = z[v] + (next[v] - z[v]) * (limit / step);
    }
    z = next;
    if (step < 1e-5f) break;
  }
  const glm::vec3 t(z[0], z[1], z[2]), w = glm::vec3(z[3], z[4], z[5]) / kLever;
  const Pose c = compose(start, o0, t, w);
  const float lowest = measure(c, probes);
  if (lowest >= 0.0f) {
    const float moved = displacement(parts, start, c);
    if (moved < out.moved) out = Candidate{c, lowest, moved, turn};
  }
  return out;
}

// The projection on the field alone first, then on the exact source from where that ended: the
// exact searches (microseconds each on dense meshes) are spent only near the answer.
Candidate projectInPhases(std::span<const HandPart> parts, const glm::vec3& pivot,
                          const Pose& start, Measure& measure, Probes& probes,
                          const ClearanceOptions& o, bool turn, int& iterations) {
  std::array<float, 6> z{};
  if (measure.hasBoth()) {
    measure.exactOn = false;
    (void)project(parts, pivot, start, measure, probes, o, turn, iterations, z);
    measure.exactOn = true;
  }
  return project(parts, pivot, start, measure, probes, o, turn, iterations, z);
}

// Along `dir` from `start` + `from`: the first translation that clears every part, within the
// bound (and below bestSoFar). Starting before the first clear point, it never steps past it.
Candidate march(std::span<const HandPart> parts, const Pose& start, Measure& measure,
                Probes& probes, const ClearanceOptions& o, const glm::vec3& dir, float bestSoFar,
                int& iterations, float from = 0.0f) {
  Candidate out;
  float s = from;
  const float limit = std::min(o.maxCorrection, bestSoFar);
  measure.gradients = false;
  for (int k = 0; k < kMaxMarchSteps && s <= limit; ++k) {
    ++iterations;
    Pose c = start;
    c.position += dir * s;
    const float lowest = measure(c, probes);
    if (lowest >= o.margin - 1e-5f) {
      out = Candidate{c, lowest, s, false};
      break;
    }
    s += std::max(kMinMarchStep, o.margin - lowest);
  }
  measure.gradients = true;
  (void)parts;
  return out;
}

}  // namespace

int handParts(const HandModel& hand, const FingerCurls& curls, HandParts& out) {
  JointPoses joints{};
  hand.pose(curls, joints);
  std::array<float, kJointCount> radii{};
  for (int j = 0; j < kJointCount; ++j) radii[size_t(j)] = hand.jointRadius(Joint(j));
  return jointParts(joints, radii, out, 0);
}

int jointParts(std::span<const Pose, kJointCount> joints, std::span<const float, kJointCount> radii,
               HandParts& out, int first) {
  int n = std::max(0, first);
  auto add = [&](const glm::vec3& c, float r, float cover, Joint j) {
    if (n >= kMaxHandParts) return;
    out[n++] = HandPart{c, r, cover, j};
  };
  const float palmRadius = radii[size_t(Joint::palm)];
  add(joints[size_t(Joint::palm)].position, palmRadius, palmRadius, Joint::palm);
  for (int f = 0; f < kFingerCount; ++f) {
    const std::span<const Joint> fj = fingerJoints(Finger(f));
    for (size_t b = 0; b + 1 < fj.size(); ++b) {
      const glm::vec3 p0 = joints[size_t(fj[b])].position, p1 = joints[size_t(fj[b + 1])].position;
      const float r0 = radii[size_t(fj[b])], r1 = radii[size_t(fj[b + 1])];
      const float rmin = std::max(1e-4f, std::min(r0, r1));
      const float length = glm::length(p1 - p0);
      const int count = std::max(1, int(std::ceil(length / (kPartSpacing * rmin))));
      const float spacing = length / float(count);
      const float grow = std::sqrt(rmin * rmin + 0.25f * spacing * spacing) - rmin;
      for (int k = b == 0 ? 0 : 1; k <= count; ++k) {
        const float t = float(k) / float(count);
        const float r = (1.0f - t) * r0 + t * r1;
        add(glm::mix(p0, p1, t), r, r + grow, fj[b]);
      }
    }
  }
  return n;
}

Result<ClearanceResult> clearHand(std::span<const HandPart> parts, const glm::vec3& pivot,
                                  const SdfGrid* field, const ExactDistanceSource* exact,
                                  const ClearanceOptions& o, const Pose& start) {
  if (!(o.margin >= 0.0f) || !std::isfinite(o.margin) || !(o.maxCorrection >= 0.0f) ||
      !std::isfinite(o.maxCorrection) || o.maxIterations < 1 || !(o.rotationGain > 0.0f) ||
      !(o.rotationGain <= 1.0f)) {
    return makeError(Status::invalid_argument,
                     "clearance: margin and bound must be finite and >= 0, iterations >= 1, "
                     "rotationGain in (0, 1]");
  }
  if (parts.size() > size_t(kMaxHandParts)) {
    return makeError(Status::invalid_argument, "clearance: more than kMaxHandParts parts");
  }
  if (field == nullptr && exact == nullptr) {
    return makeError(Status::invalid_argument, "clearance: no distance (field or exact)");
  }
  if (field != nullptr &&
      (field->values().empty() || field->values().size() != field->box().nodeCount())) {
    return makeError(Status::invalid_argument, "clearance: the field has no values for its box");
  }
  ClearanceResult r;
  r.handCorrection = start;
  Measure measure(parts, field, exact, o.margin, o.fieldFromHand);
  Probes probes{};
  // Most grabs start clear: values only for that answer, directions only when inside.
  measure.gradients = false;
  r.clearanceBefore = measure(start, probes);
  measure.gradients = true;
  r.clearanceAfter = r.clearanceBefore;
  r.wasInside = r.clearanceBefore < 0.0f;
  r.exactSamples = measure.sampled();
  if (!r.wasInside) return r;
  (void)measure(start, probes);

  // The directions the deepest parts point out, before any search overwrites the probes.
  std::array<glm::vec3, 6 + kPartDirections> dirs{};
  int dirCount = 0;
  for (int a = 0; a < 3; ++a) {
    glm::vec3 axis(0.0f);
    axis[a] = 1.0f;
    dirs[dirCount++] = start.transformVector(axis);
    dirs[dirCount++] = -start.transformVector(axis);
  }
  {
    std::array<int, kMaxHandParts> order{};
    int inside = 0;
    for (size_t i = 0; i < parts.size(); ++i) {
      if (probes[i].c < 0.0f && glm::dot(probes[i].g, probes[i].g) > 0.25f)
        order[inside++] = int(i);
    }
    std::sort(order.begin(), order.begin() + inside,
              [&](int x, int y) { return probes[x].c < probes[y].c; });
    for (int k = 0; k < inside && dirCount < int(dirs.size()); ++k) {
      const glm::vec3 g = probes[order[k]].g;
      bool seen = false;
      for (int d = 0; d < dirCount; ++d) seen = seen || glm::dot(dirs[d], g) > 0.995f;
      if (!seen) dirs[dirCount++] = g;
    }
  }

  Candidate best = projectInPhases(parts, pivot, start, measure, probes, o, false, r.iterations);
  // Each direction is marched on the field first; the exact march then starts kFieldTrust short
  // of the field's answer, nearest first, and only while it can still beat the best so far.
  std::array<float, 6 + kPartDirections> fieldStop{};
  std::array<int, 6 + kPartDirections> order{};
  for (int d = 0; d < dirCount; ++d) {
    order[d] = d;
    fieldStop[d] = 0.0f;
    if (!measure.hasBoth()) continue;
    measure.exactOn = false;
    ClearanceOptions reach = o;  // the field may need up to kFieldTrust more than the mesh
    reach.maxCorrection += kFieldTrust;
    const Candidate f = march(parts, start, measure, probes, reach, dirs[d],
                              std::numeric_limits<float>::infinity(), r.iterations);
    measure.exactOn = true;
    fieldStop[d] =
        f.valid() ? std::max(0.0f, f.moved - kFieldTrust) : std::numeric_limits<float>::infinity();
  }
  std::sort(order.begin(), order.begin() + dirCount,
            [&](int x, int y) { return fieldStop[x] < fieldStop[y]; });
  for (int k = 0; k < dirCount; ++k) {
    const int d = order[k];
    if (!(fieldStop[d] < std::min(best.moved, o.maxCorrection))) break;
    const Candidate c =
        march(parts, start, measure, probes, o, dirs[d], best.moved, r.iterations, fieldStop[d]);
    if (c.valid() && c.moved < best.moved) best = c;
  }
  if (o.rotation) {
    const Candidate c =
        projectInPhases(parts, pivot, start, measure, probes, o, true, r.iterations);
    if (c.valid() && (!best.valid() || c.moved < o.rotationGain * best.moved)) best = c;
  }
  r.exactSamples = measure.sampled();
  if (!best.valid() || best.moved > o.maxCorrection) {
    r.exceeded = true;
    return r;
  }
  r.handCorrection = best.correction;
  r.clearanceAfter = best.clearance;
  r.displacement = best.moved;
  r.rotated = best.rotated;
  return r;
}

}  // namespace sdfg
