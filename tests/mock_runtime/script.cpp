// Timeline parser and sampler (format: docs/mock-runtime.md).
#include "script.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>

#include "pose_math.h"

namespace sdfg::mock {
namespace {

bool parseTarget(std::string_view word, Target& out) {
  if (word == "left")
    out = kLeft;
  else if (word == "right")
    out = kRight;
  else if (word == "head")
    out = kHead;
  else
    return false;
  return true;
}

bool isChannelName(std::string_view word) {
  if (word.empty()) return false;
  return std::all_of(word.begin(), word.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '/';
  });
}

bool endsWith(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

bool parseFloat(std::string_view word, float& out) {
  // strtof accepts what from_chars does not (leading '+'); both reject garbage.
  std::string copy(word);
  char* end = nullptr;
  out = std::strtof(copy.c_str(), &end);
  return end == copy.c_str() + copy.size() && std::isfinite(out);
}

std::vector<std::string_view> splitWords(std::string_view line) {
  std::vector<std::string_view> words;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
    if (j > i) words.push_back(line.substr(i, j - i));
    i = j;
  }
  return words;
}

// A logical line (continuations joined) and the number of its first physical line.
struct Line {
  size_t number;
  std::string text;
};

std::vector<Line> logicalLines(std::string_view text) {
  std::vector<Line> lines;
  std::string pending;
  size_t pendingStart = 0;
  size_t number = 0;
  size_t pos = 0;
  while (pos <= text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view raw = text.substr(pos, end - pos);
    ++number;
    if (const size_t hash = raw.find('#'); hash != std::string_view::npos)
      raw = raw.substr(0, hash);
    while (!raw.empty() && (raw.back() == ' ' || raw.back() == '\t' || raw.back() == '\r'))
      raw.remove_suffix(1);
    const bool continues = !raw.empty() && raw.back() == '\\';
    if (continues) raw.remove_suffix(1);
    if (pending.empty()) pendingStart = number;
    pending += ' ';
    pending += raw;
    if (!continues) {
      lines.push_back({pendingStart, pending});
      pending.clear();
    }
    pos = end + 1;
  }
  if (!pending.empty()) lines.push_back({pendingStart, pending});
  return lines;
}

// Number of values a channel takes, or 0 for "any count of 1" scalar channels.
size_t valueCount(Target target, std::string_view channel) {
  if (channel == "joints") return target == kHead ? 0 : size_t{kJointCount} * kFloatsPerJoint;
  if (channel == "grip/pose" || channel == "aim/pose") return target == kHead ? 0 : 7;
  if (channel == "pose") return target == kHead ? 7 : 0;
  return target == kHead ? 0 : 1;
}

}  // namespace

bool Script::parse(std::string_view text, Script& out, std::string& error) {
  Script result;
  for (const Line& line : logicalLines(text)) {
    const std::vector<std::string_view> words = splitWords(line.text);
    if (words.empty()) continue;
    auto fail = [&](const std::string& why) {
      error = "line " + std::to_string(line.number) + ": " + why;
      return false;
    };
    const std::string_view first = words[0];
    if (first == "profile" || first == "end_after_frames" || first == "capture") {
      if (words.size() != 2) return fail(std::string(first) + " takes exactly one value");
      if (first != "profile") {
        uint64_t n = 0;
        const auto [p, ec] = std::from_chars(words[1].data(), words[1].data() + words[1].size(), n);
        if (ec != std::errc() || p != words[1].data() + words[1].size())
          return fail(std::string(first) + " needs a non-negative integer");
      } else if (words[1].substr(0, 22) != "/interaction_profiles/") {
        return fail("profile must be an /interaction_profiles/... path");
      }
      result.directives_[std::string(first)] = std::string(words[1]);
      continue;
    }
    uint64_t frame = 0;
    const auto [p, ec] = std::from_chars(first.data(), first.data() + first.size(), frame);
    if (ec != std::errc() || p != first.data() + first.size())
      return fail("expected a frame number or a directive, got '" + std::string(first) + "'");
    if (words.size() < 4) return fail("expected: <frame> <target> <channel> <values...>");
    Target target{};
    if (!parseTarget(words[1], target)) return fail("target must be left, right or head");
    std::string channel(words[2]);
    if (!isChannelName(channel)) return fail("bad channel name '" + channel + "'");

    std::vector<float> values;
    for (size_t i = 3; i < words.size(); ++i) {
      float v = 0;
      if (!parseFloat(words[i], v))
        return fail("'" + std::string(words[i]) + "' is no finite number");
      values.push_back(v);
    }

    // Shorthands: "squeeze 0.5" is squeeze/value, "thumbstick 0.1 0.2" sets x and y.
    std::vector<std::pair<std::string, std::vector<float>>> writes;
    if (channel == "squeeze" || channel == "trigger") {
      channel += "/value";
    } else if (channel == "grip" || channel == "aim") {
      channel += "/pose";
    } else if (channel == "thumbstick" || channel == "trackpad") {
      if (values.size() != 2) return fail(channel + " takes two values (x y)");
      writes.push_back({channel + "/x", {values[0]}});
      writes.push_back({channel + "/y", {values[1]}});
    }
    if (writes.empty()) {
      const size_t expected = valueCount(target, channel);
      if (expected == 0) return fail("channel '" + channel + "' does not exist for this target");
      if (values.size() != expected)
        return fail(channel + " takes " + std::to_string(expected) + " values, got " +
                    std::to_string(values.size()));
      // Orientations are normalised here, so sampling never sees a zero quaternion.
      const size_t stride = channel == "joints" ? kFloatsPerJoint : 7;
      if (expected >= 7) {
        for (size_t j = 0; j + 7 <= values.size(); j += stride) {
          const XrQuaternionf q{values[j + 3], values[j + 4], values[j + 5], values[j + 6]};
          if (!(quatLength(q) > 1e-6f)) return fail("zero orientation quaternion");
          const XrQuaternionf n = normalized(q);
          values[j + 3] = n.x, values[j + 4] = n.y, values[j + 5] = n.z, values[j + 6] = n.w;
          if (channel == "joints" && !(values[j + 7] > 0))
            return fail("joint radius must be positive");
        }
      }
      writes.push_back({channel, values});
    }
    for (auto& [name, vals] : writes) {
      Track& track = result.tracks_[{target, name}];
      track.step = endsWith(name, "/click") || endsWith(name, "/touch") || name == "tracked" ||
                   name == "hand_tracked";
      // A later line for the same frame replaces the earlier one.
      auto it = std::lower_bound(track.keys.begin(), track.keys.end(), frame,
                                 [](const Key& k, uint64_t f) { return k.frame < f; });
      if (it != track.keys.end() && it->frame == frame)
        it->values = vals;
      else
        track.keys.insert(it, Key{frame, vals});
    }
  }
  out = std::move(result);
  return true;
}

const Script::Track* Script::find(Target target, std::string_view channel) const {
  const auto it = tracks_.find({target, std::string(channel)});
  return it == tracks_.end() ? nullptr : &it->second;
}

std::vector<float> Script::sample(const Track& track, uint64_t frame, bool pose) {
  const auto& keys = track.keys;
  auto next = std::upper_bound(keys.begin(), keys.end(), frame,
                               [](uint64_t f, const Key& k) { return f < k.frame; });
  if (next == keys.begin()) return track.step ? std::vector<float>{} : keys.front().values;
  if (next == keys.end() || track.step) return std::prev(next)->values;
  const Key& a = *std::prev(next);
  const Key& b = *next;
  const float t = float(frame - a.frame) / float(b.frame - a.frame);
  std::vector<float> v(a.values.size());
  for (size_t i = 0; i < v.size(); ++i) v[i] = lerp(a.values[i], b.values[i], t);
  if (pose) {
    const size_t stride = a.values.size() == 7 ? 7 : kFloatsPerJoint;
    for (size_t j = 0; j + 7 <= v.size(); j += stride) {
      const XrQuaternionf q =
          nlerp({a.values[j + 3], a.values[j + 4], a.values[j + 5], a.values[j + 6]},
                {b.values[j + 3], b.values[j + 4], b.values[j + 5], b.values[j + 6]}, t);
      v[j + 3] = q.x, v[j + 4] = q.y, v[j + 5] = q.z, v[j + 6] = q.w;
    }
  }
  return v;
}

std::optional<XrPosef> Script::pose(Target target, std::string_view channel, uint64_t frame) const {
  std::string name(channel);
  if (target != kHead && name.find('/') == std::string::npos) name += "/pose";
  const Track* track = find(target, name);
  if (track == nullptr) return std::nullopt;
  const std::vector<float> v = sample(*track, frame, true);
  if (v.empty()) return std::nullopt;
  return XrPosef{{v[3], v[4], v[5], v[6]}, {v[0], v[1], v[2]}};
}

std::optional<float> Script::scalar(Target target, std::string_view channel, uint64_t frame) const {
  const Track* track = find(target, channel);
  if (track == nullptr) return std::nullopt;
  const std::vector<float> v = sample(*track, frame, false);
  if (v.empty()) return std::nullopt;
  return v[0];
}

std::optional<JointSet> Script::joints(Target target, uint64_t frame) const {
  const Track* track = find(target, "joints");
  if (track == nullptr) return std::nullopt;
  const std::vector<float> v = sample(*track, frame, true);
  if (v.empty()) return std::nullopt;
  JointSet set;
  for (uint32_t j = 0; j < kJointCount; ++j) {
    const float* f = &v[size_t{j} * kFloatsPerJoint];
    set.pose[j] = XrPosef{{f[3], f[4], f[5], f[6]}, {f[0], f[1], f[2]}};
    set.radius[j] = f[7];
  }
  return set;
}

std::optional<std::string> Script::directive(std::string_view name) const {
  const auto it = directives_.find(name);
  if (it == directives_.end()) return std::nullopt;
  return it->second;
}

}  // namespace sdfg::mock
