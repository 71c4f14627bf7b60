// autograsp-frame-cost's results: what one run with the layer on or off measured, the per-object
// summary of both runs, and the JSON that docs/benchmarks.md quotes (tools/frame-cost/plot.sh
// draws it). Apart from main.cpp so the unit tests write and read the same JSON.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "base/status.h"
#include "json_file.h"

namespace sdfg::frame_cost {

inline constexpr int kPhaseCount = 5;
inline constexpr const char* kPhases[kPhaseCount] = {"open", "grab", "held", "held_moving",
                                                     "held_deforming"};

struct Percentiles {
  double p50 = 0, p99 = 0, max = 0;
  size_t count = 0;
};
// Nearest-rank percentiles of `v` (all zero for an empty one).
Percentiles percentiles(std::vector<double> v);

// What one run (layer on or off) measured.
struct RunResult {
  bool ok = false;
  std::string error;
  // Per phase, the app's time in OpenXR calls for each frame (ms).
  std::array<std::vector<double>, kPhaseCount> frameMs;
  // Per call name, all frames (ms), for the breakdown.
  std::map<std::string, std::vector<double>> callMs;
  int grabLatencyFrames = -1;  // frames from the squeeze to the shown grasp; -1: never
  bool grasped = false;
  double createMs = 0;  // the xrCreateGraspTargetSDFG call
  double setupMs = 0;   // from create until the target is ready
  double maxUpdateCallMs = 0;
  std::array<uint64_t, kPhaseCount> builds{};  // CPU grab-box builds during each phase
};

struct MeshResult {
  std::string name;
  size_t triangles = 0;
  bool ok = false;
  std::string error;
  RunResult on, off;
  std::array<Percentiles, kPhaseCount> added;
  std::array<double, kPhaseCount> offMedian{};
  std::array<Percentiles, kPhaseCount> offStats;  // the layer-off run's own frame totals
};

// The results as JSON: the settings, the provenance of the build (json_file.h), the objects
// skipped (not found or unreadable), and per object its calls, set-up, grab latency and, per
// phase, the time added per frame.
tools::Json resultsJson(const std::vector<MeshResult>& results, int phaseFrames,
                        double framePeriodMs, const std::vector<std::string>& skipped);

}  // namespace sdfg::frame_cost
