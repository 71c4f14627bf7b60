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
#include "percentiles.h"

namespace sdfg::frame_cost {

inline constexpr int kPhaseCount = 5;
inline constexpr const char* kPhases[kPhaseCount] = {"open", "grab", "held", "held_moving",
                                                     "held_deforming"};

using tools::Percentiles;
using tools::percentiles;

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
  // Vulkan sessions (--session vulkan) only:
  std::array<uint64_t, kPhaseCount> gpuBuilds{};  // GPU grab-box builds during each phase
  double gpuPrepareMs = 0;       // from the session's start until its GPU path was ready
  std::string graspBackend;      // where the shown grasp's field was built: "vulkan", "cpu"
  bool gpuFailed = false;        // the layer's GPU path failed (it builds on the CPU since)
  std::string vulkanDevice;      // VkPhysicalDeviceProperties::deviceName
  std::string vulkanDeviceType;  // "discrete-gpu", "cpu", ...
};

struct MeshResult {
  std::string name;
  size_t triangles = 0;
  bool ok = false;
  std::string error;
  RunResult on, off;
  std::array<Percentiles, kPhaseCount> added;
  std::array<Percentiles, kPhaseCount> offStats;  // the layer-off run's own frame totals
};

// The outer-hand scenario (issue 27): the hand near, then pressed into and sliding along, the
// targets in its grab box, among `targets` registered in all (--room N: the rest spread over a
// room, away from the hand).
inline constexpr int kOuterPhaseCount = 2;
inline constexpr const char* kOuterPhases[kOuterPhaseCount] = {"near", "touching"};

struct OuterRun {
  bool ok = false;
  std::string error;
  std::array<std::vector<double>, kOuterPhaseCount> frameMs;
  std::map<std::string, std::vector<double>> callMs;
  // Frames whose XrGraspHandOffsetSDFG::offset moved the hand (the outer hand at work).
  std::array<int, kOuterPhaseCount> movedFrames{};
  double createTotalMs = 0;  // every xrCreateGraspTargetSDFG call
  double createMaxMs = 0;    // the slowest one
  double setupMs = 0;        // from the first create until every target is ready
  // --session vulkan: as RunResult's.
  std::string vulkanDevice, vulkanDeviceType;
};

struct OuterResult {
  int targets = 0;    // registered in all
  int inHandBox = 0;  // of them, in the hand's grab box
  bool ok = false;
  std::string error;
  // Layer on (its defaults: the outer hand on), layer off, and layer on with the outer hand
  // switched off (its configuration's outer_hand): the outer hand's own share.
  OuterRun on, off, onWithoutOuter;
  std::array<Percentiles, kOuterPhaseCount> added, addedWithoutOuter;
  std::array<Percentiles, kOuterPhaseCount> offStats;
};

// How the app ran (--session, --target, --gpu) and on which Vulkan device. The JSON of a headless
// run has none of these keys, as before they existed: a file without "session" is headless.
struct SessionInfo {
  std::string session = "headless";  // "headless" or "vulkan"
  std::string target = "arrays";     // the objects' targets: "arrays" or "buffer"
  std::string gpu;                   // the layer's gpu setting the tool set (vulkan)
  std::string vulkanDevice, vulkanDeviceType;
};

// What the layer adds per frame: each of `frameMs` (layer on) less `offMedianMs` (the layer-off
// run's median of the same phase).
Percentiles addedOver(const std::vector<double>& frameMs, double offMedianMs);

// The results as JSON: the settings, the provenance of the build (json_file.h), the objects
// skipped (not found or unreadable), and per object its calls, set-up, grab latency and, per
// phase, the time added per frame; with `outer`, the outer-hand scenario as "outer"; with a
// Vulkan `session`, its kind, target kind and device, and per object and phase the GPU's share.
tools::Json resultsJson(const std::vector<MeshResult>& results, int phaseFrames,
                        double framePeriodMs, const std::vector<std::string>& skipped,
                        const OuterResult* outer = nullptr, const SessionInfo* session = nullptr);

}  // namespace sdfg::frame_cost
