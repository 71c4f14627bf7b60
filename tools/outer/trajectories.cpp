#include "trajectories.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "grasp/hand_clearance.h"
#include "io/shapes.h"

namespace sdfg::outer_bench {
namespace {

// Frames of linear motion and holds, 90 Hz.
class Path {
 public:
  explicit Path(const Pose& start) { frames_.push_back(start); }
  void moveTo(const Pose& to, float speed) {
    const Pose from = frames_.back();
    const float d = glm::length(to.position - from.position);
    const int n = std::max(1, int(std::ceil(d / (speed * float(kFrameSeconds)))));
    for (int i = 1; i <= n; ++i) {
      const float t = float(i) / float(n);
      frames_.push_back(Pose{glm::slerp(from.orientation, to.orientation, t),
                             from.position + (to.position - from.position) * t});
    }
  }
  void hold(double seconds) {
    const int n = std::max(1, int(std::lround(seconds / kFrameSeconds)));
    for (int i = 0; i < n; ++i) frames_.push_back(frames_.back());
  }
  // Turns the hand about the world Y axis through `centre` from its angle now by `radians`, at
  // `radiansPerSecond`.
  void orbit(const glm::vec3& centre, float radians, float radiansPerSecond) {
    const Pose from = frames_.back();
    const int n =
        std::max(1, int(std::ceil(std::abs(radians) / (radiansPerSecond * float(kFrameSeconds)))));
    for (int i = 1; i <= n; ++i) {
      const glm::quat q = glm::angleAxis(radians * float(i) / float(n), glm::vec3(0, 1, 0));
      frames_.push_back(Pose{q * from.orientation, centre + q * (from.position - centre)});
    }
  }
  const Pose& last() const { return frames_.back(); }
  size_t size() const { return frames_.size(); }
  std::vector<Pose> take() { return std::move(frames_); }

 private:
  std::vector<Pose> frames_;
};

Pose moved(const Pose& p, const glm::vec3& by) {
  return Pose{p.orientation, p.position + by};
}

// The offset along `dir` (unit) from `base` at which the tracked hand first touches the objects:
// steps of 0.5 mm (no thin part is skipped), then bisection to 1 micrometre. `base` must be clear
// and the hand must touch within `reach`.
float touchOffset(const TrackedHand& hand, const std::vector<SceneObject>& objects,
                  const Pose& base, const glm::vec3& dir, float reach) {
  JointPoses j;
  auto clearance = [&](float s) {
    hand.world(moved(base, dir * s), j);
    return smallestClearance(j, hand.radii, objects);
  };
  if (!(clearance(0.0f) > 0.0f))
    throw std::logic_error("a trajectory's approach does not start clear");
  float lo = 0.0f, hi = 0.0f;
  for (hi = 0.0005f; hi <= reach && clearance(hi) > 0.0f; hi += 0.0005f) lo = hi;
  if (hi > reach) throw std::logic_error("a trajectory's approach touches nothing");
  while (hi - lo > 1e-6f) {
    const float mid = 0.5f * (lo + hi);
    (clearance(mid) > 0.0f ? lo : hi) = mid;
  }
  return lo;
}

SceneObject table() {
  SceneObject o;
  o.name = "table";
  o.id = 1;
  o.role = TargetRole::scene;  // stop only: hands rest on it and never take it
  o.shape = AnalyticShape{ShapeKind::box, glm::vec3(0.6f, 0.02f, 0.6f)};
  o.worldFromObject = Pose{glm::quat(1, 0, 0, 0), glm::vec3(0.0f, -0.02f, 0.0f)};  // top at y = 0
  return o;
}

SceneObject meshObject(const std::string& name, uint64_t id, TriangleMesh mesh, const Pose& at) {
  SceneObject o;
  o.name = name;
  o.id = id;
  o.worldFromObject = at;
  o.mesh = std::make_shared<const TriangleMesh>(std::move(mesh));
  auto d = MeshDistance::create(*o.mesh);
  if (!d) throw std::runtime_error(name + ": " + d.error().message);
  o.distance = std::shared_ptr<const MeshDistance>(std::move(*d));
  return o;
}

Pose at(const glm::quat& q, const glm::vec3& p) {
  return Pose{q, p};
}

// Along `dir` from `base`, where the hand first touches at `touch`: from 10 cm before the touch
// in to `depth` past it at `speed`, `stay` seconds there and back out at `speed`, with pauses
// before and after (holds shortened by `scale`).
std::vector<Pose> pushAndBack(const Pose& base, const glm::vec3& dir, float touch, float depth,
                              float speed, double stay, float scale) {
  const Pose start = moved(base, dir * (touch - 0.10f));
  Path p(start);
  p.hold(0.2 * double(scale));
  p.moveTo(moved(base, dir * (touch + depth)), speed);
  p.hold(stay * double(scale));
  p.moveTo(start, speed);
  p.hold(0.3 * double(scale));
  return p.take();
}

// Along `dir` from `base`, where the hand first touches at `touch`: from 5 cm before the touch
// pressed 1 cm past it at 0.2 m/s, then held still for 2 s (shortened by `scale`).
std::vector<Pose> pressAndHold(const Pose& base, const glm::vec3& dir, float touch, float scale) {
  Path p(moved(base, dir * (touch - 0.05f)));
  p.moveTo(moved(base, dir * (touch + 0.01f)), 0.2f);
  p.hold(2.0 * double(scale));
  return p.take();
}

// Tracking noise: a point uniform in a ball of `radius`, the same sequence for a seed on every
// machine (the engine's own mt19937, mapped by hand: the standard distributions are not).
class Noise {
 public:
  Noise(uint32_t seed, float radius) : rng_(seed), radius_(radius) {}
  glm::vec3 next() {
    for (;;) {
      const glm::vec3 v(unit(), unit(), unit());
      if (glm::dot(v, v) <= 1.0f) return v * radius_;
    }
  }

 private:
  float unit() { return float(rng_() >> 8) * (2.0f / 16777216.0f) - 1.0f; }
  std::mt19937 rng_;
  float radius_;
};

// Every frame of `frames` moved by the noise, a new offset each frame.
void addNoise(std::vector<Pose>& frames, Noise& noise) {
  for (Pose& p : frames) p.position += noise.next();
}

}  // namespace

PassCheck Trajectory::passAt(size_t k) const {
  PassCheck c = *pass;
  if (c.object >= 0)
    c.worldFromCheck = objectsAt(k)[size_t(c.object)].worldFromObject * c.worldFromCheck;
  return c;
}

std::vector<SceneObject> Trajectory::objectsAt(size_t k) const {
  std::vector<SceneObject> now = objects;
  if (k < objectPoses.size())
    for (size_t i = 0; i < now.size() && i < objectPoses[k].size(); ++i)
      now[i].worldFromObject = objectPoses[k][i];
  return now;
}

float SceneObject::signedDistance(const glm::vec3& world) const {
  const glm::vec3 p = worldFromObject.inverse().transformPoint(world);
  return shape ? shape->signedDistance(p) : distance->signedDistance(p);
}

TrackedHand::TrackedHand(float curl) {
  FingerCurls c;
  c.fill(curl);
  model.pose(c, local);
  for (int j = 0; j < kJointCount; ++j) radii[size_t(j)] = model.jointRadius(Joint(j));
}

void TrackedHand::world(const Pose& worldFromHand, JointPoses& out) const {
  for (int j = 0; j < kJointCount; ++j) out[size_t(j)] = worldFromHand * local[size_t(j)];
}

float smallestClearance(const JointPoses& joints, const std::array<float, kJointCount>& radii,
                        const std::vector<SceneObject>& objects) {
  float c = std::numeric_limits<float>::infinity();
  for (const SceneObject& o : objects)
    for (int j = 0; j < kJointCount; ++j)
      c = std::min(c, o.signedDistance(joints[size_t(j)].position) - radii[size_t(j)]);
  return c;
}

PartClearance smallestPartClearance(const JointPoses& joints,
                                    const std::array<float, kJointCount>& radii,
                                    const std::vector<SceneObject>& objects) {
  HandParts parts;
  const int n = jointParts(joints, radii, parts);
  PartClearance c{std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity()};
  for (const SceneObject& o : objects)
    for (int i = 0; i < n; ++i) {
      const HandPart& part = parts[size_t(i)];
      const float d = o.signedDistance(part.centre);
      c.radius = std::min(c.radius, d - part.radius);
      c.cover = std::min(c.cover, d - part.coverRadius);
    }
  return c;
}

std::vector<Trajectory> makeTrajectories(const TrackedHand& hand, float scale) {
  const glm::vec3 down(0, -1, 0), east(1, 0, 0);
  const glm::quat flat(1, 0, 0, 0);  // palm down, fingers toward -Z
  const glm::quat palmEast =
      glm::angleAxis(0.5f * std::numbers::pi_v<float>, glm::vec3(0, 0, 1));  // palm toward +X
  auto secs = [&](double s) { return s * double(scale); };
  // Palm down 15 cm over the table; palm toward the mug's axis from -X, at the palm's height.
  const Pose overTable = at(flat, glm::vec3(0.0f, 0.15f, 0.09f));
  const glm::vec3 palmBesideMug = palmEast * hand.local[size_t(Joint::palm)].position;
  const Pose besideMug = at(palmEast, glm::vec3(-0.25f, -palmBesideMug.y, -palmBesideMug.z));
  std::vector<Trajectory> out;

  // 1. Into the table 2 cm past its surface, then along it.
  {
    Trajectory t;
    t.name = "table_slide";
    t.description = "reach 2 cm into a table (box, scene role) at 0.5 m/s, slide 20 cm + 10 cm";
    t.objects.push_back(table());
    const float touch = touchOffset(hand, t.objects, overTable, down, 0.3f);
    Path p(moved(overTable, down * (touch - 0.10f)));
    p.hold(secs(0.2));
    p.moveTo(moved(overTable, down * (touch + 0.02f)), 0.5f);
    p.hold(secs(0.2));
    p.moveTo(moved(p.last(), east * 0.2f * scale), 0.3f);
    p.moveTo(moved(p.last(), glm::vec3(0, 0, -0.1f * scale)), 0.3f);
    p.hold(secs(0.2));
    p.moveTo(moved(p.last(), -down * 0.12f), 0.5f);
    p.hold(secs(0.3));
    t.hand = p.take();
    out.push_back(std::move(t));
  }

  // 2. Through a 3 mm plate at 2, 3 and 5 m/s (6 cm past its touch: inside the release distance).
  for (float speed : {2.0f, 3.0f, 5.0f}) {
    Trajectory t;
    t.name = "plate_push_" + std::to_string(int(speed)) + "ms";
    t.description = "palm first through a 3 mm plate (30 x 30 cm mesh) to 6 cm past its touch";
    t.objects.push_back(meshObject("plate", 2, makeThinPlate(0.30f, 0.30f, 0.003f), Pose{}));
    t.pass = PassCheck{Pose{}, 0.0015f, glm::vec2(0.15f, 0.15f)};
    const float touch = touchOffset(hand, t.objects, overTable, down, 0.3f);
    t.hand = pushAndBack(overTable, down, touch, 0.06f, speed, 0.2, scale);
    out.push_back(std::move(t));
  }

  // 3. Along the mug 2 cm inside its wall: the palm faces its axis and the hand circles it.
  {
    Trajectory t;
    t.name = "mug_slide";
    t.description = "palm 2 cm inside the mug's wall, circling it +-60 degrees at 1.5 rad/s";
    t.objects.push_back(meshObject("mug", 4, makeMug(), Pose{}));
    const float touch = touchOffset(hand, t.objects, besideMug, east, 0.3f);
    const Pose start = moved(besideMug, east * (touch - 0.10f));
    Path p(start);
    p.hold(secs(0.2));
    p.moveTo(moved(besideMug, east * (touch + 0.02f)), 0.5f);
    p.hold(secs(0.2));
    const float turn = glm::radians(60.0f) * scale;
    p.orbit(glm::vec3(0.0f), -turn, 1.5f);
    p.orbit(glm::vec3(0.0f), 2.0f * turn, 1.5f);
    p.orbit(glm::vec3(0.0f), -turn, 1.5f);
    p.hold(secs(0.2));
    p.moveTo(start, 0.5f);
    p.hold(secs(0.3));
    t.hand = p.take();
    out.push_back(std::move(t));
  }

  // 4. Fast swipes through thin parts (2, 3 and 5 m/s): a ring 1 cm thick, and an upright plate
  // 1 cm below its top edge.
  for (float speed : {2.0f, 3.0f, 5.0f}) {
    Trajectory t;
    t.name = "ring_swipe_" + std::to_string(int(speed)) + "ms";
    t.description = "palm first into a torus ring (tube 1 cm across) to 6 cm past its touch";
    t.objects.push_back(meshObject("ring", 3, makeTorus(0.06f, 0.005f, 96, 16), Pose{}));
    // Middle finger's intermediate joint at the tube's height and at z = 0 (its nearest point).
    const glm::vec3 mid = palmEast * hand.local[size_t(Joint::middle_intermediate)].position;
    const Pose base = at(palmEast, glm::vec3(-0.25f, -mid.y, -mid.z));
    // The check's +Y is the world's -X (the hand comes from -X).
    t.pass =
        PassCheck{at(palmEast, glm::vec3(-0.06f, 0.0f, 0.0f)), 0.005f, glm::vec2(0.005f, 0.01f)};
    const float touch = touchOffset(hand, t.objects, base, east, 0.3f);
    t.hand = pushAndBack(base, east, touch, 0.06f, speed, 0.1, scale);
    out.push_back(std::move(t));
  }
  for (float speed : {2.0f, 3.0f, 5.0f}) {
    Trajectory t;
    t.name = "plate_edge_" + std::to_string(int(speed)) + "ms";
    t.description = "side of the flat hand into an upright 3 mm plate 1 cm below its top edge";
    // Upright: the plate's thin axis (its Y) along the world's -X, its top edge at y = 0.
    const Pose worldFromPlate = at(palmEast, glm::vec3(0.0f, -0.15f, 0.0f));
    t.objects.push_back(
        meshObject("plate", 2, makeThinPlate(0.30f, 0.30f, 0.003f), worldFromPlate));
    t.pass = PassCheck{worldFromPlate, 0.0015f, glm::vec2(0.15f, 0.15f)};
    const glm::vec3 palm = hand.local[size_t(Joint::palm)].position;
    const Pose base = at(flat, glm::vec3(-0.30f, -0.01f - palm.y, 0.09f));
    const float touch = touchOffset(hand, t.objects, base, east, 0.4f);
    t.hand = pushAndBack(base, east, touch, 0.06f, speed, 0.1, scale);
    out.push_back(std::move(t));
  }

  // 5. Still hands: 3 mm above the table (near, clear), and pressed 1 cm into the table and the
  // mug.
  {
    Trajectory t;
    t.name = "table_near_still";
    t.description = "held still 3 mm above a table for 2 s";
    t.objects.push_back(table());
    const float touch = touchOffset(hand, t.objects, overTable, down, 0.3f);
    Path p(moved(overTable, down * (touch - 0.003f)));
    p.hold(secs(2.0));
    t.hand = p.take();
    out.push_back(std::move(t));
  }
  {
    Trajectory t;
    t.name = "table_pressed_still";
    t.description = "pressed 1 cm into a table at 0.2 m/s, held still for 2 s";
    t.objects.push_back(table());
    const float touch = touchOffset(hand, t.objects, overTable, down, 0.3f);
    t.hand = pressAndHold(overTable, down, touch, scale);
    out.push_back(std::move(t));
  }
  {
    Trajectory t;
    t.name = "mug_pressed_still";
    t.description = "palm pressed 1 cm into the mug's wall at 0.2 m/s, held still for 2 s";
    t.objects.push_back(meshObject("mug", 4, makeMug(), Pose{}));
    const float touch = touchOffset(hand, t.objects, besideMug, east, 0.3f);
    t.hand = pressAndHold(besideMug, east, touch, scale);
    out.push_back(std::move(t));
  }

  // 6. The world moves, the hand holds still: a table top rising into the open hand at 0.3, 1 and
  // 2 m/s from 6 cm under it to 6 cm past its touch, then still (a lift, locomotion down a
  // slope); ten 4 cm boxes 12 cm apart passing under the hand at 1.5 m/s with their tops 1 cm
  // above its lowest part (smooth locomotion past a shelf).
  for (float speed : {0.3f, 1.0f, 2.0f}) {
    Trajectory t;
    t.name = speed < 1.0f ? "table_rise_03ms" : "table_rise_" + std::to_string(int(speed)) + "ms";
    t.description = "a table top rising into a still open hand to 6 cm past its touch";
    t.objects.push_back(table());
    const float touch = touchOffset(hand, t.objects, overTable, down, 0.3f);
    const Pose still = moved(overTable, down * (touch - 0.06f));
    const Pose tableStart = t.objects[0].worldFromObject;
    const int rise = int(std::ceil(0.12f / (speed * float(kFrameSeconds))));
    const int frames = rise + int(std::lround(secs(0.5) / kFrameSeconds)) + 10;
    for (int k = 0; k < frames; ++k) {
      t.hand.push_back(still);
      const float up = std::min(0.12f, speed * float(kFrameSeconds) * float(std::max(0, k - 10)));
      t.objectPoses.push_back({moved(tableStart, -down * up)});
    }
    out.push_back(std::move(t));
  }
  {
    Trajectory t;
    t.name = "boxes_pass_15ms";
    t.description = "ten 4 cm boxes passing under a still open hand at 1.5 m/s, 1 cm into it";
    const AnalyticShape box{ShapeKind::box, glm::vec3(0.02f)};
    // The hand's lowest point over the table, where the boxes' tops are 1 cm above it.
    std::vector<SceneObject> probe{table()};
    const float touch = touchOffset(hand, probe, overTable, down, 0.3f);
    const Pose still = moved(overTable, down * touch);  // its lowest part at y = 0
    for (int b = 0; b < 10; ++b) {
      SceneObject o;
      o.name = "box" + std::to_string(b);
      o.id = uint64_t(10 + b);
      o.shape = box;
      t.objects.push_back(o);
    }
    const float step = 1.5f * float(kFrameSeconds);
    const glm::vec3 palm = still.transformPoint(hand.local[size_t(Joint::palm)].position);
    const int frames = int((0.3f + 0.12f * 10.0f + 0.3f) / step);
    for (int k = 0; k < frames; ++k) {
      t.hand.push_back(still);
      std::vector<Pose> poses;
      for (int b = 0; b < 10; ++b)
        poses.push_back(at(flat, glm::vec3(palm.x - 0.3f - 0.12f * float(b) + step * float(k),
                                           0.01f - 0.02f, palm.z)));
      t.objectPoses.push_back(std::move(poses));
    }
    for (int b = 0; b < 10; ++b) t.objects[size_t(b)].worldFromObject = t.objectPoses[0][size_t(b)];
    out.push_back(std::move(t));
  }
  // 7. A thin plate moving through the still open hand at 2 m/s (an animated part, the world
  // moving past the user): from 6 cm under it to 6 cm past its touch, then back down.
  {
    Trajectory t;
    t.name = "plate_rise_2ms";
    t.description = "a 3 mm plate rising through a still open hand at 2 m/s to 6 cm past its touch";
    t.objects.push_back(meshObject("plate", 2, makeThinPlate(0.30f, 0.30f, 0.003f), Pose{}));
    t.pass = PassCheck{Pose{}, 0.0015f, glm::vec2(0.15f, 0.15f), 0};
    const float touch = touchOffset(hand, t.objects, overTable, down, 0.3f);
    const Pose still = moved(overTable, down * (touch - 0.06f));
    // The plate's path under the still hand: its top meets the hand after 6 cm of rise.
    Path plate(Pose{});
    plate.hold(secs(0.2));
    plate.moveTo(moved(Pose{}, -down * 0.12f), 2.0f);
    plate.hold(secs(0.3));
    plate.moveTo(Pose{}, 2.0f);
    plate.hold(secs(0.3));
    for (const Pose& p : plate.take()) {
      t.hand.push_back(still);
      t.objectPoses.push_back({p});
    }
    out.push_back(std::move(t));
  }

  // 8. A box brought into the still open hand from the side at 1 m/s, 3 cm past the touch, held
  // there, and taken away: what the other hand (or the app) carries into this one. The app moves
  // the box as the other hand holds it; for this hand it is a target that moves.
  {
    Trajectory t;
    t.name = "box_brought_1ms";
    t.description = "an 8 cm box brought from the side into a still open hand at 1 m/s, 3 cm in";
    SceneObject box;
    box.name = "box";
    box.id = 5;
    box.shape = AnalyticShape{ShapeKind::box, glm::vec3(0.04f)};
    const Pose still = overTable;
    const glm::vec3 palm = still.transformPoint(hand.local[size_t(Joint::palm)].position);
    // Its centre at the palm's height, coming from +X toward the hand.
    const Pose far = at(flat, palm + east * 0.25f);
    box.worldFromObject = far;
    t.objects.push_back(box);
    // Where the box first touches the hand: the hand moving toward it by the same amount.
    const float touch = touchOffset(hand, t.objects, still, east, 0.3f);
    Path p(far);
    p.hold(secs(0.2));
    p.moveTo(moved(far, -east * (touch + 0.03f)), 1.0f);
    p.hold(secs(0.5));
    p.moveTo(far, 1.0f);
    p.hold(secs(0.3));
    for (const Pose& b : p.take()) {
      t.hand.push_back(still);
      t.objectPoses.push_back({b});
    }
    out.push_back(std::move(t));
  }

  // 9. Jumps of 50 cm (tracking lost and found elsewhere within a frame, or the app teleporting
  // the hand): over a table 5 cm above it onto another pose 5 cm above it (clear: shown there at
  // once), and onto a pose 1 cm inside it (shown at the nearest clear pose), then lifted out.
  for (bool inside : {false, true}) {
    Trajectory t;
    t.name = inside ? "jump_inside_50cm" : "jump_clear_50cm";
    t.description = inside ? "a still hand 5 cm over a table jumps 50 cm onto a pose 1 cm inside it"
                           : "a still hand 5 cm over a table jumps 50 cm onto a pose 5 cm over it";
    t.objects.push_back(table());
    const Pose left = moved(overTable, -east * 0.25f);
    const float touch = touchOffset(hand, t.objects, left, down, 0.3f);
    Path p(moved(left, down * (touch - 0.05f)));
    p.hold(secs(0.3));
    const Pose right = moved(left, east * 0.5f);
    const Pose landing = moved(right, down * (inside ? touch + 0.01f : touch - 0.05f));
    p.moveTo(landing, 1000.0f);  // within one frame
    if (!inside) t.clearJumps.push_back(p.size() - 1);
    p.hold(secs(0.5));
    p.moveTo(moved(landing, -down * 0.08f), 0.3f);
    p.hold(secs(0.3));
    t.hand = p.take();
    out.push_back(std::move(t));
  }

  // 10. Tracking lost for 20 frames beside the mug and found with the palm 1 cm inside its wall,
  // held there, then drawn back out; and a hand that appears (its first frame) 1 cm inside it.
  for (bool lost : {true, false}) {
    Trajectory t;
    t.name = lost ? "lost_found_in_mug" : "appear_in_mug";
    t.description =
        lost ? "tracking lost for 20 frames 5 cm from the mug, found 1 cm inside its wall"
             : "a hand whose first frame is 1 cm inside the mug's wall, held there";
    t.objects.push_back(meshObject("mug", 4, makeMug(), Pose{}));
    const float touch = touchOffset(hand, t.objects, besideMug, east, 0.3f);
    const Pose inWall = moved(besideMug, east * (touch + 0.01f));
    Path p(lost ? moved(besideMug, east * (touch - 0.05f)) : inWall);
    if (lost) {
      p.hold(secs(0.3));
      const size_t before = p.size();
      for (int i = 0; i < 20; ++i) p.moveTo(inWall, 1000.0f);  // tracking lost: frames unshown
      t.valid.assign(p.size(), true);
      for (size_t i = before; i < p.size(); ++i) t.valid[i] = false;
      p.moveTo(inWall, 1000.0f);  // found inside
    }
    p.hold(secs(0.5));
    p.moveTo(moved(inWall, -east * 0.08f), 0.3f);
    p.hold(secs(0.3));
    t.hand = p.take();
    t.valid.resize(t.hand.size(), true);
    out.push_back(std::move(t));
  }

  // 11. A hand at rest on a table with 2 mm of tracking noise (uniform in a ball, every frame),
  // then reaching into the mug standing on it, pressed 1 cm into its wall, noise all along.
  {
    Trajectory t;
    t.name = "rest_noise_then_mug";
    t.description = "resting on a table with 2 mm tracking noise, then pressed 1 cm into a mug";
    SceneObject top = table();
    top.worldFromObject.position.y = -0.0475f - 0.02f;  // the mug stands on it
    t.objects.push_back(top);
    t.objects.push_back(meshObject("mug", 4, makeMug(), Pose{}));
    const Pose overLeft = at(flat, glm::vec3(-0.30f, 0.10f, 0.09f));
    const float rest = touchOffset(hand, t.objects, overLeft, down, 0.3f);
    // Beside the mug, raised so that the hand's lowest joint sphere is 1 cm over the table.
    float lowest = std::numeric_limits<float>::infinity();
    for (int j = 0; j < kJointCount; ++j)
      lowest = std::min(lowest, besideMug.transformPoint(hand.local[size_t(j)].position).y -
                                    hand.radii[size_t(j)]);
    const float lift = std::max(0.0f, -0.0475f + 0.01f - lowest);
    const Pose beside = moved(besideMug, glm::vec3(0.0f, lift, 0.0f));
    const float touch = touchOffset(hand, t.objects, beside, east, 0.3f);
    Path p(moved(overLeft, down * rest));
    p.hold(secs(1.0));
    p.moveTo(moved(overLeft, down * (rest - 0.08f)), 0.5f);
    p.moveTo(moved(beside, east * (touch - 0.08f)), 0.5f);
    p.moveTo(moved(beside, east * (touch + 0.01f)), 0.3f);
    p.hold(secs(0.5));
    p.moveTo(moved(beside, east * (touch - 0.08f)), 0.3f);
    t.hand = p.take();
    Noise noise(36, 0.002f);
    addNoise(t.hand, noise);
    out.push_back(std::move(t));
  }
  return out;
}

}  // namespace sdfg::outer_bench
