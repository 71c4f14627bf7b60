// autograsp-outer's frame loop: one trajectory driven through a GraspSession frame by frame, the
// shown hand read as the layer reads it for an app (takeShownHand after the update,
// drawTrackedHand when the app locates the joints), and what each frame showed.
#pragma once

#include <string>
#include <vector>

#include "trajectories.h"

namespace sdfg::outer_bench {

struct RunOptions {
  bool outer = true;  // GraspSettings::outerHand
  // Each frame waits for the worker (at most 10 s) before the hand is drawn: the draw then always
  // has the frame's own result, the figures are the same on every run and frames are not paced.
  // Otherwise frames are paced at 90 Hz and the hand is drawn drawAtMs into its frame.
  bool waitWorker = false;
  double drawAtMs = 8.0;
};

struct FrameRecord {
  bool valid = true;  // the hand was tracked (Trajectory::valid); the others hold no figures
  // No hand shown (OuterNow::withhold: it appeared or jumped where a target may be, before the
  // worker's answer): no figures either, counted apart.
  bool withheld = false;
  float shownClearance = 0.0f;    // smallest over joint spheres and objects, metres
  float trackedClearance = 0.0f;  // likewise for the tracked hand
  // The same over the bone capsules (smallestPartClearance), shown and tracked.
  float shownPartClearance = 0.0f;
  float trackedPartClearance = 0.0f;
  float trackedKeepOut = 0.0f;  // the tracked capsules' clearance over their cover radii
  float offTracking = 0.0f;     // largest joint distance shown - tracked, metres
  bool identical = false;       // every shown joint is bit-identical to the tracked one
  bool trackedStill = false;    // the tracked hand is where it was in the frame before
  int stillFrames = 0;          // how many frames it has been still, this one included
  float shownMotion = 0.0f;     // largest joint motion of the shown hand since the last frame
  bool shownPast = false;       // a shown joint went through the thin part (PassCheck)
  bool trackedPast = false;     // a tracked joint is past it
  bool outerActive = false;     // OuterView::active
  bool onTime = false;          // the draw had the frame's own result (read after the draw)
  double updateMs = 0.0;        // GraspSession::update + takeShownHand
  double drawMs = 0.0;          // drawTrackedHand
};

struct RunRecord {
  bool ok = false;
  std::string error;
  std::vector<FrameRecord> frames;
};

RunRecord runTrajectory(const Trajectory& trajectory, const TrackedHand& hand,
                        const RunOptions& options);

}  // namespace sdfg::outer_bench
