// Scripted input of the mock runtime: a timeline of keyframes per target (left hand, right
// hand, head) and channel (grip pose, squeeze value, joints...), parsed from text and sampled
// at a frame index. The format is documented in docs/mock-runtime.md.
//
// Sampling rules: channels ending in /click or /touch and the tracked flags are steps: each
// keyframe holds until the next, and before the first one the channel has its default ("8 left
// tracked 0" loses the hand from frame 8 on). Every other channel interpolates linearly between
// keyframes (orientations by normalised lerp along the shorter arc) and holds its first value
// before the first keyframe and its last value after the last.
#pragma once

#include <openxr/openxr.h>

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace sdfg::mock {

enum Target : int { kLeft = 0, kRight = 1, kHead = 2, kTargetCount = 3 };

inline constexpr uint32_t kJointCount = XR_HAND_JOINT_COUNT_EXT;  // 26
inline constexpr uint32_t kFloatsPerJoint = 8;                    // px py pz qx qy qz qw radius

struct JointSet {
  std::array<XrPosef, kJointCount> pose{};
  std::array<float, kJointCount> radius{};
};

class Script {
 public:
  // Parses `text`. On failure returns false and sets `error` to "line N: why"; `out` is then
  // unchanged.
  static bool parse(std::string_view text, Script& out, std::string& error);

  // Pose channels ("grip", "aim" for hands; "pose" for the head), in LOCAL space.
  std::optional<XrPosef> pose(Target target, std::string_view channel, uint64_t frame) const;
  // Scalar channels: input components such as "squeeze/value", "a/click", "thumbstick/x".
  std::optional<float> scalar(Target target, std::string_view channel, uint64_t frame) const;
  // Hand joints in LOCAL space, when the script has any for that hand.
  std::optional<JointSet> joints(Target target, uint64_t frame) const;

  bool empty() const { return tracks_.empty() && directives_.empty(); }
  // Value of a directive line ("profile", "end_after_frames", "capture"), if present.
  std::optional<std::string> directive(std::string_view name) const;

 private:
  struct Key {
    uint64_t frame = 0;
    std::vector<float> values;
  };
  struct Track {
    bool step = false;
    std::vector<Key> keys;  // sorted by frame
  };
  const Track* find(Target target, std::string_view channel) const;
  // Empty when a step track is sampled before its first keyframe.
  static std::vector<float> sample(const Track& track, uint64_t frame, bool pose);

  std::map<std::pair<int, std::string>, Track> tracks_;
  std::map<std::string, std::string, std::less<>> directives_;
};

}  // namespace sdfg::mock
