// The demo's report: per object the grasp picture (physics-convex, paper, ours side by side),
// the SDF slice, and per strategy and finger the numbers; then the table scene (which object each
// grasp took, how deep the hand is in the table) and the outer hand's frames (tracked and shown
// hand per frame), as Markdown and as HTML.
#pragma once

#include <array>
#include <string>
#include <vector>

namespace sdfg::demo {

struct FingerRow {
  float curl = 0.0f;
  bool contact = false;
  float reportedMm =
      0.0f;               // distance the strategy reported at its contact (finite only on contact)
  float tipGapMm = 0.0f;  // exact distance of the tip sphere to the surface (negative: inside)
  float clearanceMm = 0.0f;  // least exact clearance of any part of the finger (negative: inside)
};

struct StrategyResult {
  std::string name;    // physics-convex, paper, ours
  std::string source;  // "layer" (through OpenXR) or "core" (in-process, same hand pose)
  bool ok = false;
  std::string error;
  std::array<FingerRow, 5> fingers{};
  int contacts = 0;
  // The whole hand (palm, metacarpals, phalanges: capsules of the joint radii): least exact
  // clearance, mm (negative: inside); how far the layer moved the hand off the controller pose
  // (XrGraspHandOffsetSDFG), mm; and the open hand's clearance before it did, mm.
  float wholeHandMm = 0.0f;
  float handMovedMm = 0.0f;
  float openClearanceMm = 0.0f;
  int frames = 0;           // frames from the squeeze to the reported grasp (layer)
  double milliseconds = 0;  // that time, or the solve time (core)
};

struct ObjectResult {
  std::string name;
  std::string origin;  // "embedded" or the file
  size_t triangles = 0;
  std::string graspPng, slicePng;  // file names in the output folder
  std::vector<StrategyResult> strategies;
};

// One grasp in the table scene (table_scene.h).
struct SceneGraspRow {
  std::string aim;   // the object the hand was placed on
  std::string took;  // the object the grasp took ("nothing" when it holds none)
  bool ok = false;   // a grasp was shown within the time bound
  std::string error;
  std::array<std::string, 5> touched{};  // per finger: the object its contact is on, or "-"
  std::array<float, 5> curl{};
  int contacts = 0;
  int fingersOnTaken = 0;  // of those, the fingers whose contact is on the object taken
  // Least exact clearance of the whole hand, mm (negative: inside), against the table and against
  // every object of the scene but the table.
  float tableMm = 0.0f;
  float objectsMm = 0.0f;
  float handMovedMm = 0.0f;  // the solver's correction of the open hand (largest part motion)
  double milliseconds = 0;   // from the squeeze to the shown grasp
};

struct SceneReport {
  std::string png;          // file name in the output folder; empty: the scene did not run
  std::string description;  // what is in the scene and where the hands were placed
  std::vector<SceneGraspRow> grasps;
};

// One frame of the outer hand sequence (outer_sequence.h).
struct OuterFrameRow {
  int frame = 0;
  std::string phase;       // reach, slide, lift
  float trackedMm = 0.0f;  // least exact clearance of the tracked hand in the table, mm
  float shownMm = 0.0f;    // the same for the shown hand
  float offsetMm = 0.0f;   // how far the shown wrist is from the tracked one
  bool constrained = false;
  bool pictured = false;  // one of the picture's columns
};

struct OuterReport {
  std::string png;  // empty: the sequence did not run
  std::string description;
  std::vector<OuterFrameRow> frames;
  // How deep the tracked and the shown hand went into the table over the frames, mm (>= 0).
  float deepestTrackedMm() const;
  float deepestShownMm() const;
};

struct ReportInfo {
  std::string runtime, device, environment;
  std::string commit;  // the code that made the report (build_info.h: describeBuild())
  int width = 0;
  std::vector<std::string> failures;  // meshes that could not be used, with the reason
};

// Writes report.md and report.html into `dir`. False with `error` on an I/O failure.
bool writeReports(const std::string& dir, const std::vector<ObjectResult>& objects,
                  const SceneReport& scene, const OuterReport& outer, const ReportInfo& info,
                  std::string& error);

}  // namespace sdfg::demo
