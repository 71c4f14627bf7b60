// Holding a grasped target that moves or deforms: per-frame re-solve under a time budget, and
// smoothing of the finger curls so they do not jitter.
//
// Each frame the caller either hands in a fresh solve (the target moved or got new vertices) or
// reports that it skipped the solve (nothing changed, or the budget said no). GraspHolder keeps
// the curls it shows and moves them toward the fresh contact curls with rules that keep the
// fingers out of the object:
// - a fresh contact curl below the shown one (the target moved into the finger) is taken at
//   once: the shown curl never exceeds the latest contact curl, so smoothing never pushes a
//   finger into the object;
// - a fresh curl above the shown one (the target moved away) is approached smoothly: an
//   exponential filter with time constant `smoothingTime`, at most `maxCurlSpeed` per second;
// - the shown curl is never below the user's own curl where that is still outside the object
//   (min(user, contact)), so the finger is never more open than the user holds it.
// The safe direction is decided per joint (JointCurls), so a finger that wraps keeps its shape.
//
// SolveBudget decides whether a frame may re-solve: it keeps a running estimate of the solve time
// and says no when the frame's budget would be exceeded, yes when the target changed and there is
// room. Neither class allocates after construction; neither is thread-safe (one per hand).
#pragma once

#include <array>
#include <cstdint>

#include "grasp/solver.h"
#include "hand/hand_model.h"

namespace sdfg {

struct HolderOptions {
  float smoothingTime = 0.06f;  // seconds; time constant of the closing filter (0: no smoothing)
  float maxCurlSpeed = 3.0f;    // curl per second a finger may close at while held
};

class GraspHolder {
 public:
  explicit GraspHolder(const HolderOptions& options = {}) : options_(options) {}

  // Forgets the held state: the next update() shows its solve as is.
  void reset() { held_ = false; }
  bool holding() const { return held_; }

  // A frame with a fresh solve. `userCurls` is the user's own curl per finger (estimateCurls);
  // `dt` the time since the previous frame in seconds (negative or non-finite counts as 0).
  // Returns the grasp to show: the fresh one with smoothed curls.
  const GraspResult& update(const GraspResult& fresh, const FingerCurls& userCurls, float dt);

  // A frame without a fresh solve: keeps closing smoothly toward the last solve's curls.
  const GraspResult& hold(const FingerCurls& userCurls, float dt);

  const GraspResult& shown() const { return shown_; }

 private:
  void step(const FingerCurls& userCurls, float dt);

  HolderOptions options_;
  bool held_ = false;
  GraspResult target_{};  // the latest solve
  GraspResult shown_{};
};

class SolveBudget {
 public:
  // `budgetMicroseconds`: time the grasp may take per frame.
  explicit SolveBudget(float budgetMicroseconds) : budget_(budgetMicroseconds) {}

  // Whether this frame should re-solve: the target changed (moved or new vertices) and the
  // estimated solve time fits the budget, or a solve has been owed for `maxSkippedFrames`.
  bool shouldSolve(bool targetChanged);
  // Reports how long the solve this frame took.
  void record(float microseconds);

  float estimateMicroseconds() const { return estimate_; }
  int skippedFrames() const { return skipped_; }

  static constexpr int kMaxSkippedFrames = 4;

 private:
  float budget_ = 0.0f;
  float estimate_ = 0.0f;
  bool owed_ = false;
  int skipped_ = 0;
};

}  // namespace sdfg
