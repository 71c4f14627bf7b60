// The "ours" strategy's exact check: exactStop() corrects a joint group's field stop on the exact
// distance of the target's mesh, by Newton and secant steps on the clearance of the spheres the
// field puts near the surface, so contacts land within 0.1 mm where the 16^3 field errs by mm.
#include "grasp/solver_ours_detail.h"

namespace sdfg {

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
// Checked: every sphere these joints move that the field puts within kExactBand of touching, plus
// the touching one. All of them move together here, so whichever touches first on the exact
// surface is the stop, proximal or distal: the field's order of contact can be wrong by its own
// error, and checking only the field's touching bone and those before it left the distal ones to
// limit how far the group may close, which crept toward the contact by halves and stopped short.
// A sphere's clearance is measured against its own bone's capsule: the exact closest point q of its
// centre, its distance to the bone's axis minus the capsule radius there (at most the centre's
// distance minus its radius; it sees a bone that leans into the surface next to the centre). Secant
// steps on the smallest clearance bring it into [0, kContactTolerance]. Closing past the field's
// stop is limited so that no sphere left unchecked (one farther than the band) moves more than its
// clearance on the field; opening may go below where the group began (down to 0), which is how a
// sphere the previous group left inside comes out. Spheres are re-chosen at every pose tried. The
// most closed pose with no checked sphere inside is kept; if none was found, the group opens in
// doubling steps while that helps and the least inside pose is kept. Reports the closest sphere
// as the touching one when it is within the tolerance (or when the field said it touched, unless
// the pose kept is clear of the exact surface and either fully closed or with no surface within
// the band of any sphere checked: then nothing touches, and the caller closes the group on).
float OursSolver::exactStop(const ExactContext& cx, int f, int firstFree, float a,
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
  // Candidates are chosen on the field at every pose tried: a moving sphere that comes within
  // the band joins them. Every other moving sphere limits how far the group may close from here: no
  // more than its clearance on the field allows (the interpolant's slope bound), so none reaches
  // the surface unseen. `highest`: that limit.
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
      if (g < kExactBand || i == touching) {
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
      // The sphere at the proximal joint (bone 0, t = 1) starts the first phalanx's capsule; the
      // other spheres of bone 0 (a metacarpal that turns, the thumb's) lie on their own bone.
      const int b = s.bone == 0 && s.t >= 1.0f ? 1 : s.bone;
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

  // Samples, at the current joint positions (curl v), every candidate never sampled exactly yet:
  // until then its bound is its field clearance minus kFieldTrust, which a part thinner than the
  // field resolves (a spike, a thin rim) can beat by millimetres. Before a pose is taken as the
  // stop, every candidate's bound comes from an exact sample.
  auto verifyFresh = [&](float v, ExactEval& r) {
    for (int k = 0; k < count; ++k) {
      if (fresh[k]) sampleOne(k, v, r);
    }
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
  // The least closed pose tried that had a candidate inside, above aSafe: the contact lies
  // between the two, and no step goes to or past it.
  float aInside = std::numeric_limits<float>::infinity();
  ExactEval safe, open = cur, least = cur;
  float aLeast = a;  // the pose with the largest clearance tried
  for (int it = 0;; ++it) {
    // A pose near enough to end the search is first checked against every candidate.
    if (cur.g >= 0.0f && cur.g <= kVerifyBand) verifyFresh(aCur, cur);
    if (cur.g < 0.0f && aCur > aSafe) aInside = std::min(aInside, aCur);
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
    // Nor, from a pose below it, to or past one known to be inside: the step's prediction is
    // wrong there (bisect). From an inside pose itself any step is taken: a sphere can come out
    // as the group closes (a part behind the finger).
    if (aCur < aInside && next >= aInside) next = 0.5f * (aCur + aInside);
    if (std::abs(next - aCur) < 1e-7f) break;
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
  // Clear of the exact surface by more than the tolerance at the pose kept, fully closed or with
  // no surface within the search band of any sphere checked: the field's contact was its own error
  // (a far node's bound reads millimetres where the surface is centimetres off), and the finger
  // touches nothing here (it would otherwise report the field's point, of another pose). The
  // caller closes it on from here.
  if ((aSafe >= 1.0f || safe.arg < 0) && safe.g > tol) {
    touching = -1;
    return aSafe;
  }
  if (safe.arg >= 0 && (touching >= 0 || safe.g <= tol)) {
    touching = safe.arg;
    touchPoint = safe.centre;
    touchValue = safe.distance;
  }
  return aSafe;
}

}  // namespace sdfg
