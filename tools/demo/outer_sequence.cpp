#include "outer_sequence.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <filesystem>
#include <thread>
#include <vector>

#include <glm/geometric.hpp>

#include "grasp/hand_clearance.h"
#include "grasp/outer_hand.h"
#include "grasp/outer_view.h"
#include "grasp/scene_exact_source.h"
#include "hand/hand_synthesis.h"
#include "io/shapes.h"
#include "png_io.h"
#include "scene.h"

namespace sdfg::demo {
namespace {

constexpr double kFrameSeconds = 1.0 / 90.0;
constexpr int kColumns = 5;
constexpr float kRelaxedCurl = 0.15f;  // a hand reaching out is a little curled

struct Frame {
  Pose tracked;  // wrist, world
  const char* phase;
};

// Down from 5 cm above the touch to 4 cm below it at 1 cm a frame (0.9 m/s), along the table
// 4 cm inside it for 16 frames (0.54 m/s, toward the fingertips), then up and out.
std::vector<Frame> path(float touch) {
  std::vector<Frame> frames;
  const glm::quat palmDown(1, 0, 0, 0);  // the wrist frame: palm -Y, fingers -Z
  float z = 0.04f;
  for (int k = 0; k <= 9; ++k)
    frames.push_back({Pose{palmDown, glm::vec3(0.0f, touch + 0.05f - 0.01f * k, z)}, "reach"});
  for (int k = 1; k <= 16; ++k) {
    z -= 0.006f;
    frames.push_back({Pose{palmDown, glm::vec3(0.0f, touch - 0.04f, z)}, "slide"});
  }
  for (int k = 1; k <= 9; ++k)
    frames.push_back({Pose{palmDown, glm::vec3(0.0f, touch - 0.04f + 0.01f * k, z)}, "lift"});
  return frames;
}

HandPose toWorld(const JointPoses& wristJoints, const std::array<float, kJointCount>& radii,
                 const Pose& worldFromWrist) {
  HandPose h;
  for (int j = 0; j < kJointCount; ++j) {
    h.positions[size_t(j)] = worldFromWrist.transformPoint(wristJoints[size_t(j)].position);
    h.radii[size_t(j)] = radii[size_t(j)];
  }
  h.worldFromWrist = worldFromWrist;
  return h;
}

}  // namespace

bool runOuterSequence(Renderer& renderer, const OuterSequenceOptions& options, OuterReport& report,
                      std::string& error) {
  const HandModel model = HandModel::defaultAdult(Hand::right);
  FingerCurls relaxed;
  relaxed.fill(kRelaxedCurl);
  JointPoses joints;  // wrist frame
  JointRadii radii;
  placeJoints(model, relaxed, Pose{}, joints, radii);
  // The wrist height at which the hand's lowest point touches y = 0.
  HandParts parts;
  const int n = jointParts(joints, radii, parts);
  float lowest = 1e9f;
  for (int i = 0; i < n; ++i)
    lowest = std::min(lowest, parts[size_t(i)].centre.y - parts[size_t(i)].radius);
  const float touch = -lowest;

  const AnalyticShape table{ShapeKind::box, glm::vec3(0.2f, 0.04f, 0.2f)};
  const Pose worldFromTable{glm::quat(1, 0, 0, 0), glm::vec3(0.0f, -0.04f, -0.08f)};
  const Pose tableFromWorld = worldFromTable.inverse();
  const std::vector<SceneMember> members{{1, nullptr, &table, tableFromWorld, false}};
  const SceneExactSource scene(members);
  auto tableDistance = [&](const glm::vec3& p) {
    return table.signedDistance(tableFromWorld.transformPoint(p));
  };

  OuterHand outer(model);
  const std::vector<Frame> frames = path(touch);
  const std::array<size_t, kColumns> pictured = {0, 9, 17, 25, frames.size() - 1};
  std::array<HandPose, kColumns> trackedShots{}, shownShots{};
  report.frames.clear();
  // Paced as an app's frames are (the outer hand's own clock is in.time, so the pacing changes
  // no result; it keeps the demo's frame loops alike).
  auto next = std::chrono::steady_clock::now();
  for (size_t k = 0; k < frames.size(); ++k) {
    std::this_thread::sleep_until(next);
    next += std::chrono::microseconds(11111);
    OuterHandInput in;
    in.worldFromWrist = frames[k].tracked;
    in.joints = &joints;
    in.radii = &radii;
    in.time = double(k) * kFrameSeconds;
    const auto r = outer.update(in, &scene);
    if (!r) {
      error = "the outer hand refused frame " + std::to_string(k) + ": " + r.error().message;
      return false;
    }
    // The shown hand: capped fingers at the model's pose at their curl, the others as given.
    OuterNow now;
    now.capped = r->capped;
    now.curl = r->curl;
    JointPoses shown = joints;
    capFingers(model, now, Pose{}, shown);
    const HandPose trackedHand = toWorld(joints, radii, frames[k].tracked);
    const HandPose shownHand = toWorld(shown, radii, r->worldFromShownWrist);
    OuterFrameRow row;
    row.frame = int(k);
    row.phase = frames[k].phase;
    row.trackedMm = 1000.0f * leastClearance(trackedHand, tableDistance);
    row.shownMm = 1000.0f * leastClearance(shownHand, tableDistance);
    row.offsetMm =
        1000.0f * glm::length(r->worldFromShownWrist.position - frames[k].tracked.position);
    row.constrained = r->constrained;
    const auto at = std::find(pictured.begin(), pictured.end(), k);
    row.pictured = at != pictured.end();
    if (row.pictured) {
      trackedShots[size_t(at - pictured.begin())] = trackedHand;
      shownShots[size_t(at - pictured.begin())] = shownHand;
    }
    report.frames.push_back(row);
  }
  report.description =
      "A right hand, palm down and a little curled, reaches 4 cm into a table top (an "
      "analytic box 8 cm thick) at 0.9 m/s, slides 9.6 cm along it inside toward its fingertips, "
      "and "
      "lifts out: " +
      std::to_string(frames.size()) +
      " frames 11.1 ms apart, fed to the engine's `OuterHand` (grasp/outer_hand.h) one by "
      "one, as the layer's worker does with `outerHand` on. Top row: the tracked hand (grey), "
      "what a plain app would draw; bottom row: the hand shown (colour), which stops on the "
      "table and slides along its surface. Columns: frames " +
      std::to_string(pictured[0]) + ", " + std::to_string(pictured[1]) + ", " +
      std::to_string(pictured[2]) + ", " + std::to_string(pictured[3]) + " and " +
      std::to_string(pictured[4]) +
      ". Clearance: the least exact distance of the hand's surface (palm sphere, finger "
      "capsules) from the table, mm; negative: that deep inside.";

  // The picture: one camera for every panel, from the little finger's side, a little above.
  const uint32_t w = options.width / 2, gap = 4;
  const uint32_t totalW = kColumns * w + (kColumns - 1) * gap, totalH = 2 * w + gap;
  std::vector<uint8_t> picture(size_t(totalW) * totalH * 4, 255);
  const glm::vec3 centre(0.0f, 0.05f, -0.095f);
  const glm::vec3 toCamera = glm::normalize(glm::vec3(1.0f, 0.35f, 0.0f));
  glm::vec3 light;
  const glm::mat4 vp = lookCamera(centre, 0.2f, toCamera, {0, 1, 0}, 1.0f, light);
  const TriangleMesh tableMesh = makeBox(2.0f * table.halfExtents);
  for (int c = 0; c < kColumns; ++c) {
    for (int rowIndex = 0; rowIndex < 2; ++rowIndex) {
      DrawList list;
      appendMesh(list.lit, tableMesh, worldFromTable, kTableColour);
      appendHand(list.lit, rowIndex == 0 ? trackedShots[size_t(c)] : shownShots[size_t(c)],
                 rowIndex == 0 ? kTrackedColour : kHandColour);
      if (!renderPanel(renderer, list, vp, light, w, w, options.supersample, picture, totalW,
                       uint32_t(c) * (w + gap), uint32_t(rowIndex) * (w + gap), error))
        return false;
    }
  }
  const std::string file = (std::filesystem::path(options.outDir) / options.png).string();
  if (!writePng(file, totalW, totalH, picture, error)) return false;
  report.png = options.png;
  return true;
}

}  // namespace sdfg::demo
