// autograsp-outer: how well the outer hand (issue 27) keeps a tracked hand's shown pose out of
// objects, and what it costs per frame.
//
// Scripted trajectories of a tracked right hand (26 joints of the default adult model, open, or
// every finger curled by --squeeze: the model's curl) meet a table, a thin plate, the mug and a
// thin ring (trajectories.h). Each runs twice in one process through an engine-level
// GraspSession (CPU builds): with GraspSettings::outerHand off, then on. Frames are paced at 90 Hz;
// the shown hand is read as the layer reads it for an app: takeShownHand right after the update,
// drawTrackedHand 8 ms into the frame (--draw-at).
//
// Per trajectory (the outer-on run): the shown hand's penetration into any object per frame
// (joint spheres with their radii, exact distances), its distance from the tracked hand over the
// frames where the tracked hand is clear (and not past a thin part: there the shown hand stays on
// its side by design), its frame-to-frame motion while the tracked hand is still (jitter), whether
// a shown joint went through the thin part, and the per-frame cost of update + drawing, on and
// off side by side. The targets: penetration p99 <= 1 mm and max <= 2 mm, 0 off tracking
// while clear, jitter <= 0.1 mm, no pass-through. The distance from tracking is also reported
// over the frames the tracked hand is clear of the outer hand's keep-out (its 0.5 mm margin
// around the bone capsules' cover radii): closer than that the shown hand stays at the margin by
// design, so a clear tracked hand within about a millimetre of a surface is shown up to that far
// off it. --check holds that figure, not the stricter one, to 0. Where the world moves, and in
// paced runs (a late answer holds the hand a frame where the last one showed it), the figure
// counts only frames whose tracked hand is clear by 1 cm (issue 36's reading). Issue 36 adds:
// the shown hand at a clear pose the tracked hand jumped to, in that very frame; frames with no
// hand shown (it appeared or jumped where a target's bounds reach it, before the worker's
// answer: outer_view.h) in runs of at most 9, and never while the tracked hand is clear by 1 cm.
//
// The worker is asynchronous: in a paced run whether the draw finds the frame's own result or
// the fallback depends on the machine, so the quality figures vary from run to run.
// --wait-worker waits for the worker before each draw instead (no pacing): the figures are then
// the same on every run (the quality test uses it with --check).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "build_info.h"
#include "cli_options.h"
#include "grasp/outer_hand.h"
#include "json_file.h"
#include "percentiles.h"
#include "run.h"
#include "trajectories.h"

namespace {

using namespace sdfg::outer_bench;
using sdfg::tools::Json;
using sdfg::tools::jsonNumber;

const char* const kUsage =
    "usage: autograsp-outer [--quick] [--only NAME]... [--wait-worker] [--draw-at MS]\n"
    "                       [--squeeze S] [--check | --check-penetration]\n"
    "                       [--json FILE [--per-frame]]\n"
    "  --quick        shorter holds and slides (the smoke test); speeds and depths stay\n"
    "  --only NAME    run only the trajectory NAME (repeatable)\n"
    "  --wait-worker  wait for the worker before each draw, unpaced: the same figures every run\n"
    "  --draw-at MS   when in its 11.1 ms frame the hand is drawn (default 8)\n"
    "  --squeeze S    the tracked hand's fingers curled by S in [0, 1] (default 0: open)\n"
    "  --check        exit 3 when a trajectory misses a quality target (distance from tracking\n"
    "                 counted outside the outer hand's keep-out)\n"
    "  --check-penetration  exit 3 when the shown hand goes into anything beyond the targets\n"
    "                 (penetration p99 1 mm, max 2 mm) or through a thin part, is not shown at\n"
    "                 a clear pose it jumped to, or goes unshown more than 9 frames in a row:\n"
    "                 the gate that holds on a busy machine too, paced (a late answer may\n"
    "                 leave the hand a frame behind tracking, never inside)\n"
    "  --json FILE    write the results as JSON\n"
    "  --per-frame    with --json: every frame's clearances, distances and flags too\n"
    "  --help         this text\n"
    "exit codes: 0 done (and, with --check, every target met); 1 a run failed or the JSON could\n"
    "not be written; 2 bad option; 3 a target missed (--check, --check-penetration)\n";

// Targets of issue 27.
constexpr double kPenetrationP99Mm = 1.0;
constexpr double kPenetrationMaxMm = 2.0;
constexpr double kJitterMm = 0.1;
// The most frames in a row a hand may go unshown (OuterNow::withhold) before the worker's
// answer places it: 0.1 s.
constexpr size_t kWithheldRun = 9;
// A still hand's first frames are the shown hand catching up with where the tracked one stopped,
// not jitter: the settled figure starts 100 ms into the stillness.
constexpr int kSettleFrames = 9;
// OuterHandOptions::margin's default: the clearance the shown hand keeps.
const float kClearMargin = sdfg::OuterHandOptions{}.margin;

using sdfg::tools::Percentiles;
using sdfg::tools::percentiles;

struct Summary {
  std::string name, description;
  size_t frames = 0;
  bool ok = false;
  std::string error;
  Percentiles penetrationMm;        // shown hand, outer on
  double capsulePenetrationMm = 0;  // the same over the bone capsules, max
  double trackedDepthMm = 0;        // deepest the tracked hand went
  size_t clearFrames = 0;           // tracked clear and not past a thin part
  double offWhileClearMm = 0;       // largest shown-tracked distance over them
  size_t offWhileClearCount = 0;    // of them, frames not bit-identical to tracking
  size_t keepOutFrames = 0;         // clear frames clear of the outer hand's keep-out too
  double offWhileKeepOutMm = 0;     // largest shown-tracked distance over them
  size_t stillFrames = 0;
  double jitterMm = 0;             // every still frame
  double jitterSettledMm = 0;      // from kSettleFrames into a stillness
  size_t lostFrames = 0;           // tracking lost: no hand shown, in no figure
  size_t withheldFrames = 0;       // no hand shown: it may have been inside, no answer yet
  size_t withheldRun = 0;          // the longest run of them
  size_t withheldClear = 0;        // of them, frames whose tracked hand was clear by 1 cm
  size_t clearJumps = 0;           // frames the tracked hand jumped onto a clear pose
  double clearJumpOffMm = 0;       // the largest shown-tracked distance in them
  bool clearJumpWithheld = false;  // one of them showed no hand at all
  bool hasPassCheck = false;
  bool passThrough = false;
  bool trackedPast = false;
  size_t activeFrames = 0, onTimeFrames = 0;
  Percentiles costOn, costOff;        // update + draw, ms
  std::vector<FrameRecord> perFrame;  // the outer-on run's, for --per-frame
  // The targets as stated.
  bool meets() const { return meetsByDesign() && offWhileClearMm == 0.0; }
  // The same with the distance from tracking counted only outside the keep-out (--check).
  bool keepsOut() const {
    return ok && penetrationMm.p99 <= kPenetrationP99Mm && penetrationMm.max <= kPenetrationMaxMm &&
           clearJumpOffMm == 0.0 && !clearJumpWithheld && withheldRun <= kWithheldRun &&
           !passThrough;
  }
  bool meetsByDesign() const {
    return ok && penetrationMm.p99 <= kPenetrationP99Mm && penetrationMm.max <= kPenetrationMaxMm &&
           offWhileKeepOutMm == 0.0 && clearJumpOffMm == 0.0 && !clearJumpWithheld &&
           withheldClear == 0 && withheldRun <= kWithheldRun && jitterSettledMm <= kJitterMm &&
           !passThrough;
  }
};

// Where targets move: the tracked hand's clearance past which it must be shown exactly (metres).
constexpr float kMovingClear = 0.01f;

Summary summarize(const Trajectory& t, const RunRecord& on, const RunRecord& off, bool waitWorker) {
  Summary s;
  s.name = t.name;
  s.description = t.description;
  s.frames = t.hand.size();
  s.ok = on.ok && off.ok;
  s.error = !on.ok ? "outer on: " + on.error : !off.ok ? "outer off: " + off.error : "";
  if (!s.ok) return s;
  s.hasPassCheck = t.pass.has_value();
  std::vector<double> pen, costOn, costOff;
  for (size_t k : t.clearJumps) {
    ++s.clearJumps;
    // A withheld frame has no shown hand to measure: it is not at the new pose either.
    s.clearJumpWithheld = s.clearJumpWithheld || on.frames[k].withheld;
    s.clearJumpOffMm = std::max(s.clearJumpOffMm, 1000.0 * on.frames[k].offTracking);
  }
  size_t run = 0;
  for (const FrameRecord& r : on.frames) {
    run = r.withheld ? run + 1 : 0;
    s.withheldRun = std::max(s.withheldRun, run);
    if (!r.valid) {
      ++s.lostFrames;
      continue;
    }
    if (r.withheld) {
      ++s.withheldFrames;
      s.withheldClear += r.trackedPartClearance >= kMovingClear;
      continue;
    }
    pen.push_back(1000.0 * std::max(0.0f, -r.shownClearance));
    s.capsulePenetrationMm =
        std::max(s.capsulePenetrationMm, 1000.0 * std::max(0.0f, -r.shownPartClearance));
    s.trackedDepthMm = std::max(s.trackedDepthMm, 1000.0 * std::max(0.0f, -r.trackedClearance));
    // Clear: no joint sphere and no bone capsule inside anything. Past a thin part the shown hand
    // stays on its side by design: those frames do not count.
    if (r.trackedClearance > 0.0f && r.trackedPartClearance > 0.0f && !r.trackedPast) {
      ++s.clearFrames;
      s.offWhileClearMm = std::max(s.offWhileClearMm, 1000.0 * r.offTracking);
      if (!r.identical) ++s.offWhileClearCount;
      // Clear of the outer hand's keep-out too: the margin, kept on the capsules' cover radii
      // (about 0.67 mm more than the radii on this hand), is by design. Where the world moves, a
      // target that just pushed the hand and moved on is still within the keep-out of the next
      // step: the shown hand comes back over a frame, and only a tracked hand clear by 1 cm (the
      // issue's gate) must be shown exactly.
      // Paced, as apps draw, a late answer may hold the hand a frame where the last one showed
      // it: there too only a tracked hand clear by 1 cm must be shown exactly.
      const float keepOut = t.objectPoses.empty() && waitWorker ? kClearMargin : kMovingClear;
      if (r.trackedKeepOut > keepOut) {
        ++s.keepOutFrames;
        s.offWhileKeepOutMm = std::max(s.offWhileKeepOutMm, 1000.0 * r.offTracking);
      }
    }
    if (r.trackedStill) {
      ++s.stillFrames;
      s.jitterMm = std::max(s.jitterMm, 1000.0 * r.shownMotion);
      if (r.stillFrames > kSettleFrames)
        s.jitterSettledMm = std::max(s.jitterSettledMm, 1000.0 * r.shownMotion);
    }
    s.passThrough = s.passThrough || r.shownPast;
    s.trackedPast = s.trackedPast || r.trackedPast;
    s.activeFrames += r.outerActive;
    s.onTimeFrames += r.onTime;
    costOn.push_back(r.updateMs + r.drawMs);
  }
  for (const FrameRecord& r : off.frames)
    if (r.valid) costOff.push_back(r.updateMs + r.drawMs);
  s.penetrationMm = percentiles(pen);
  s.costOn = percentiles(costOn);
  s.costOff = percentiles(costOff);
  s.perFrame = on.frames;
  return s;
}

Json percentilesJson(const Percentiles& s) {
  return Json{{"p50", jsonNumber(s.p50)}, {"p99", jsonNumber(s.p99)}, {"max", jsonNumber(s.max)}};
}

// Per frame of the outer-on run, in millimetres: what the table sums up, for a closer look.
Json framesJson(const std::vector<FrameRecord>& frames) {
  Json shown = Json::array(), tracked = Json::array(), shownParts = Json::array(),
       trackedParts = Json::array(), keepOut = Json::array(), off = Json::array(),
       motion = Json::array(), flags = Json::array();
  for (const FrameRecord& r : frames) {
    if (!r.valid || r.withheld) {
      for (Json* a : {&shown, &tracked, &shownParts, &trackedParts, &keepOut, &off, &motion})
        a->push_back(nullptr);
      flags.push_back(r.valid ? "w" : "l");
      continue;
    }
    shown.push_back(jsonNumber(1000.0 * double(r.shownClearance)));
    tracked.push_back(jsonNumber(1000.0 * double(r.trackedClearance)));
    shownParts.push_back(jsonNumber(1000.0 * double(r.shownPartClearance)));
    trackedParts.push_back(jsonNumber(1000.0 * double(r.trackedPartClearance)));
    keepOut.push_back(jsonNumber(1000.0 * double(r.trackedKeepOut)));
    off.push_back(jsonNumber(1000.0 * double(r.offTracking)));
    motion.push_back(jsonNumber(1000.0 * double(r.shownMotion)));
    std::string f;
    if (r.outerActive) f += 'a';
    if (r.onTime) f += 'o';
    if (r.identical) f += 'i';
    if (r.trackedStill) f += 's';
    if (r.trackedPast) f += 't';
    if (r.shownPast) f += 'p';
    flags.push_back(f);
  }
  return Json{{"shown_clearance_mm", shown},
              {"tracked_clearance_mm", tracked},
              {"shown_capsule_clearance_mm", shownParts},
              {"tracked_capsule_clearance_mm", trackedParts},
              {"tracked_keep_out_clearance_mm", keepOut},
              {"off_tracking_mm", off},
              {"shown_motion_mm", motion},
              {"flags", flags},
              {"flags_legend",
               "a outer active, o drawn on time, i shown bit-identical to tracked, s tracked "
               "still, t tracked past the thin part, p shown past it, l tracking lost, w withheld "
               "(no hand shown: every figure null)"}};
}

Json summaryJson(const Summary& s, bool perFrame) {
  Json j{{"name", s.name}, {"description", s.description}, {"frames", s.frames}, {"ok", s.ok}};
  if (!s.ok) {
    j["error"] = s.error;
    return j;
  }
  j["penetration_mm"] = percentilesJson(s.penetrationMm);
  j["capsule_penetration_max_mm"] = jsonNumber(s.capsulePenetrationMm);
  j["tracked_depth_max_mm"] = jsonNumber(s.trackedDepthMm);
  j["clear_frames"] = s.clearFrames;
  j["off_tracking_while_clear_max_mm"] = jsonNumber(s.offWhileClearMm);
  j["off_tracking_while_clear_frames"] = s.offWhileClearCount;
  j["keep_out_clear_frames"] = s.keepOutFrames;
  j["off_tracking_while_clear_of_keep_out_max_mm"] = jsonNumber(s.offWhileKeepOutMm);
  j["still_frames"] = s.stillFrames;
  j["jitter_max_mm"] = jsonNumber(s.jitterMm);
  j["jitter_settled_max_mm"] = jsonNumber(s.jitterSettledMm);
  j["lost_frames"] = s.lostFrames;
  j["withheld_frames"] = s.withheldFrames;
  j["withheld_longest_run"] = s.withheldRun;
  j["withheld_while_clear_frames"] = s.withheldClear;
  j["clear_jumps"] = s.clearJumps;
  j["clear_jump_off_tracking_max_mm"] =
      s.clearJumps > 0 ? jsonNumber(s.clearJumpOffMm) : Json(nullptr);
  j["clear_jump_withheld"] = s.clearJumpWithheld;
  j["pass_through"] = s.hasPassCheck ? Json(s.passThrough) : Json(nullptr);
  j["tracked_past_thin_part"] = s.hasPassCheck ? Json(s.trackedPast) : Json(nullptr);
  j["outer_active_frames"] = s.activeFrames;
  j["on_time_frames"] = s.onTimeFrames;
  j["cost_on_ms"] = percentilesJson(s.costOn);
  j["cost_off_ms"] = percentilesJson(s.costOff);
  j["meets_targets"] = s.meets();
  j["meets_targets_outside_keep_out"] = s.meetsByDesign();
  if (perFrame) j["per_frame"] = framesJson(s.perFrame);
  return j;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false, waitWorker = false, check = false, checkPenetration = false, perFrame = false;
  float drawAt = 8.0f;
  float squeeze = 0.0f;
  std::string json;
  std::vector<std::string> only;
  CLI::App cli{"", "autograsp-outer"};
  cli.add_flag("--quick", quick);
  cli.add_flag("--wait-worker", waitWorker);
  cli.add_flag("--check", check);
  cli.add_flag("--check-penetration", checkPenetration)->excludes("--check");
  cli.add_flag("--per-frame", perFrame);
  sdfg::tools::cli::addNumber(
      cli, "--draw-at", drawAt, [](float v) { return v >= 0.0f && v <= 11.0f; },
      "a number of milliseconds from 0 to 11");
  sdfg::tools::cli::addNumber(
      cli, "--squeeze", squeeze, [](float v) { return v >= 0.0f && v <= 1.0f; },
      "a number from 0 to 1");
  sdfg::tools::cli::addRepeatable(cli, "--only", only);
  sdfg::tools::cli::addName(cli, "--json", json, "file name");
  if (auto exit = sdfg::tools::cli::parseOrUsage(cli, argc, argv, "autograsp-outer", kUsage))
    return *exit;

  const TrackedHand hand(squeeze);
  std::vector<Trajectory> trajectories = makeTrajectories(hand, quick ? 0.25f : 1.0f);
  for (const std::string& name : only) {
    if (std::none_of(trajectories.begin(), trajectories.end(),
                     [&](const Trajectory& t) { return t.name == name; })) {
      std::string known;
      for (const Trajectory& t : trajectories) known += (known.empty() ? "" : ", ") + t.name;
      std::fprintf(stderr, "autograsp-outer: --only: unknown trajectory \"%s\"; known: %s\n%s",
                   name.c_str(), known.c_str(), kUsage);
      return 2;
    }
  }
  if (!only.empty())
    std::erase_if(trajectories, [&](const Trajectory& t) {
      return std::find(only.begin(), only.end(), t.name) == only.end();
    });

  std::vector<Summary> summaries;
  for (const Trajectory& t : trajectories) {
    std::printf("%s (%zu frames): outer off...", t.name.c_str(), t.hand.size());
    std::fflush(stdout);
    RunOptions o;
    o.waitWorker = waitWorker;
    o.drawAtMs = drawAt;
    o.outer = false;
    const RunRecord off = runTrajectory(t, hand, o);
    std::printf(" on...");
    std::fflush(stdout);
    o.outer = true;
    const RunRecord on = runTrajectory(t, hand, o);
    std::printf(" done\n");
    summaries.push_back(summarize(t, on, off, waitWorker));
  }

  std::printf(
      "\nThe outer hand on scripted tracked-hand trajectories (squeeze %.2f), %s; code at commit "
      "%s\n"
      "penetration: the shown hand's joint spheres, exact distance (capsules: spheres along the "
      "bones); off tracking: largest joint distance shown - tracked over the frames the tracked "
      "hand is clear (and, keep-out, clear by the 0.5 mm margin on the capsules' cover radii, or "
      "by 1 cm where the world moves or paced); withheld: frames with no hand shown (it may have "
      "been inside, no answer yet); "
      "jitter: shown motion per still frame from 100 ms on (from the first); cost: update + draw, "
      "ms\n\n",
      double(squeeze),
      waitWorker
          ? "each draw waits for the worker (unpaced)"
          : ("paced at 90 Hz, drawn " + std::to_string(int(drawAt)) + " ms into the frame").c_str(),
      sdfg::tools::describeBuild().c_str());
  std::printf(
      "| trajectory | frames | penetration p99 / max mm | capsules max mm | tracked depth mm | off "
      "tracking while clear mm (frames) | off tracking outside keep-out mm | off at a clear jump "
      "mm "
      "| withheld frames (longest run) | jitter mm | pass-through | on time | cost off p50 / p99 / "
      "max | cost on p50 / p99 / max | "
      "targets |\n"
      "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|---|\n");
  int failures = 0, missed = 0;
  for (const Summary& s : summaries) {
    if (!s.ok) {
      std::printf("| %s | %zu | failed: %s |\n", s.name.c_str(), s.frames, s.error.c_str());
      ++failures;
      continue;
    }
    missed += checkPenetration ? !s.keepsOut() : check ? !s.meetsByDesign() : !s.meets();
    const char* pass = !s.hasPassCheck ? "n/a" : s.passThrough ? "yes" : "no";
    char jump[32] = "n/a";
    if (s.clearJumpWithheld)
      std::snprintf(jump, sizeof jump, "withheld");
    else if (s.clearJumps > 0)
      std::snprintf(jump, sizeof jump, "%.3f", s.clearJumpOffMm);
    const char* verdict = s.meets()           ? "met"
                          : s.meetsByDesign() ? "missed: off tracking inside the keep-out"
                                              : "missed";
    std::printf(
        "| %s | %zu | %.3f / %.3f | %.3f | %.1f | %.3f (%zu of %zu) | %.3f | %s | %zu (%zu) | %.4f "
        "(%.4f) | %s | %zu/%zu | %.3f / %.3f / %.3f | %.3f / %.3f / %.3f | %s |\n",
        s.name.c_str(), s.frames, s.penetrationMm.p99, s.penetrationMm.max, s.capsulePenetrationMm,
        s.trackedDepthMm, s.offWhileClearMm, s.offWhileClearCount, s.clearFrames,
        s.offWhileKeepOutMm, jump, s.withheldFrames, s.withheldRun, s.jitterSettledMm, s.jitterMm,
        pass, s.onTimeFrames, s.activeFrames, s.costOff.p50, s.costOff.p99, s.costOff.max,
        s.costOn.p50, s.costOn.p99, s.costOn.max, verdict);
  }
  if (!json.empty()) {
    Json root{{"tool", "autograsp-outer"},
              {"provenance", sdfg::tools::provenanceJson()},
              {"mode", waitWorker ? "wait_worker" : "paced"},
              {"frame_period_ms", jsonNumber(1000.0 * kFrameSeconds)},
              {"draw_at_ms", waitWorker ? Json(nullptr) : jsonNumber(double(drawAt))},
              {"quick", quick},
              {"squeeze", jsonNumber(squeeze)},
              {"hardware_threads", std::thread::hardware_concurrency()},
              {"targets",
               {{"penetration_p99_mm", kPenetrationP99Mm},
                {"penetration_max_mm", kPenetrationMaxMm},
                {"off_tracking_while_clear_mm", 0.0},
                {"jitter_mm", kJitterMm},
                {"pass_through", false}}}};
    Json list = Json::array();
    for (const Summary& s : summaries) list.push_back(summaryJson(s, perFrame));
    root["trajectories"] = std::move(list);
    if (auto error = sdfg::tools::writeJsonFile(json, root)) {
      std::fprintf(stderr, "autograsp-outer: %s\n", error->message.c_str());
      return 1;
    }
    std::printf("\nwrote %s\n", json.c_str());
  }
  if (failures > 0) return 1;
  if ((check || checkPenetration) && missed > 0) {
    std::printf("%d trajectories missed a target\n", missed);
    return 3;
  }
  return 0;
}
