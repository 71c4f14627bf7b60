// The "ours" strategy on the grab-box field: evaluate() reads every moving sphere of a finger
// pose, stage() advances a joint group by the distance bound until a sphere touches (no
// tunnelling), and polish() moves the stop onto the curvature-corrected field.
#include "grasp/solver_ours_detail.h"

namespace sdfg {

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

}  // namespace sdfg
