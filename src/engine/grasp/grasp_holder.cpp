#include "grasp/grasp_holder.h"

#include <algorithm>
#include <cmath>

namespace sdfg {

const GraspResult& GraspHolder::update(const GraspResult& fresh, const FingerCurls& userCurls,
                                       float dt) {
  target_ = fresh;
  if (!held_) {
    shown_ = fresh;
    held_ = true;
    // The first frame still honours the user's curl where that is safe.
    step(userCurls, 0.0f);
    return shown_;
  }
  step(userCurls, dt);
  return shown_;
}

const GraspResult& GraspHolder::hold(const FingerCurls& userCurls, float dt) {
  if (!held_) return shown_;
  step(userCurls, dt);
  return shown_;
}

void GraspHolder::step(const FingerCurls& userCurls, float dt) {
  if (!std::isfinite(dt) || dt < 0.0f) dt = 0.0f;
  const float blend =
      options_.smoothingTime > 0.0f ? 1.0f - std::exp(-dt / options_.smoothingTime) : 1.0f;
  const float maxMove = options_.maxCurlSpeed > 0.0f ? options_.maxCurlSpeed * dt : 1.0f;
  for (int f = 0; f < kFingerCount; ++f) {
    const FingerState& t = target_.fingers[f];
    FingerState& s = shown_.fingers[f];
    const float user = std::isfinite(userCurls[f]) ? std::clamp(userCurls[f], 0.0f, 1.0f) : 0.0f;
    for (size_t j = 0; j < s.jointCurls.size(); ++j) {
      const float goal = t.jointCurls[j];
      float c = s.jointCurls[j];
      if (goal <= c) {
        c = goal;  // toward the object's surface moved back: follow at once
      } else {
        c += std::min((goal - c) * blend, maxMove);
        c = std::min(c, goal);
      }
      // Never more open than the user's hand, as far as that stays outside the object.
      c = std::max(c, std::min(user, goal));
      s.jointCurls[j] = c;
    }
    float curl = s.jointCurls[0];
    for (float c : s.jointCurls) curl = std::min(curl, c);
    s.curl = curl;
    s.contact = t.contact;
    s.contactPoint = t.contactPoint;
    s.distance = t.distance;
    s.contactBone = t.contactBone;
    s.contactT = t.contactT;
  }
  shown_.handCorrection = target_.handCorrection;
}

bool SolveBudget::shouldSolve(bool targetChanged) {
  owed_ = owed_ || targetChanged;
  if (!owed_) {
    skipped_ = 0;
    return false;
  }
  if (estimate_ <= budget_ || skipped_ >= kMaxSkippedFrames) {
    skipped_ = 0;
    owed_ = false;
    return true;
  }
  ++skipped_;
  return false;
}

void SolveBudget::record(float microseconds) {
  if (!std::isfinite(microseconds) || microseconds < 0.0f) return;
  // A running estimate that follows slow changes and forgets single spikes quickly enough.
  estimate_ = estimate_ == 0.0f ? microseconds : 0.8f * estimate_ + 0.2f * microseconds;
}

}  // namespace sdfg
