// The paper's solver, strategy "paper": Algorithm 3 with the fine-tune of eq. 3, without the
// reference code's defects.
//
// prepare() samples each finger's tip curve at a_k = min(k * da, 1) (a = 1 included, any da in
// (0, 1]) and caches the points in normalized box coordinates (eq. 2) plus the length in metres
// of the segment that ends at each point. solve() samples the grab-box SDF at the cached points,
// finger by finger, and stops a finger at the first sample closer than the threshold; eq. 3 then
// pulls it back along the segment it just travelled. Fixed here, compared with the reference:
// no division by zero (a stop at k = 0 stays at 0; a zero-length segment is not fine-tuned), no
// skipped early samples, no sample ceiling, and a = 1 is really sampled before a finger is said
// to close fully. solve() does not allocate.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "grasp/solver.h"

namespace sdfg {

// Where one finger stopped.
struct PaperFingerStop {
  float curl = 1.0f;      // final curl, fine-tuned when the finger touched
  float distance = 0.0f;  // the SDF sample that decided it (the last one when nothing was hit)
  uint32_t sample = 0;    // index of that sample
  bool contact = false;
};

// Eq. 3 with the segment just travelled: the finger reached sample a (distance d < threshold)
// from aPrev over `backSegment` metres; returns a + (d - threshold) / backSegment * (a - aPrev)
// clamped to [aPrev, a]. A segment that is zero, negative or not finite returns `a` unchanged.
float paperFineTune(float aPrev, float a, float d, float threshold, float backSegment);

// Algorithm 3 for one finger over its cached samples (all spans hold the same count K >= 1):
// `uvw` the points in normalized box coordinates, `params` their curls (increasing, from 0 to 1),
// `backSegments[k]` = |p_k - p_{k-1}| in metres (entry 0 unused). Samples `field` in order and
// stops at the first value below `threshold`; no sample below it closes the finger (curl 1).
PaperFingerStop paperSolveFinger(const SdfGrid& field, std::span<const glm::vec3> uvw,
                                 std::span<const float> params, std::span<const float> backSegments,
                                 float threshold);

class PaperSolver final : public GraspSolver {
 public:
  std::string_view name() const override { return "paper"; }
  bool needsField() const override { return true; }
  bool needsCollider() const override { return false; }

  // Fails (invalid_argument) on invalid options or box, or a hand model whose curves are not
  // finite. A failed prepare leaves the solver unprepared.
  Status prepare(const HandModel& hand, const GridBox& box, const SolverOptions& options) override;

  // Needs scene.field, built on the box given to prepare() (same pose and size; any
  // resolution). invalid_argument when unprepared, without a field, or on another box.
  Status solve(const GraspScene& scene, GraspResult& out) const override;

  std::string_view prepareError() const override { return error_; }

  // The cache, for tests and the benchmark: curls of the samples (same for every finger), and
  // one finger's samples in normalized box coordinates. Empty while unprepared.
  std::span<const float> sampleCurls() const { return params_; }
  std::span<const glm::vec3> normalizedSamples(Finger finger) const;
  // Samples per grasp: kFingerCount * sampleCurls().size().
  size_t sampleCount() const { return uvw_.size(); }

 private:
  bool prepared_ = false;
  HandModel hand_;                               // copy: contact points at fine-tuned curls
  GridBox box_;                                  // the box the cache is expressed in
  std::array<float, kFingerCount> threshold_{};  // stop distance per finger, metres
  std::vector<float> params_;                    // K curls a_k
  std::vector<glm::vec3> uvw_;                   // K per finger, finger-major, normalized box
  std::vector<glm::vec3> handTips_;              // same points in hand space
  std::vector<float> backSegments_;              // |p_k - p_{k-1}| in metres, 0 at k = 0
  std::string error_;
};

}  // namespace sdfg
