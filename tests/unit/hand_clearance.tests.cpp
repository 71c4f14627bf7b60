// clearHand() on analytic shapes whose smallest correction is known exactly: a ball around one
// part, a floor under the palm, a concave corner (floor and wall), a thin plate through the
// fingers; the bound; a turn where sliding would move the hand more; and the "ours" solver's
// clearance before closing, thumb metacarpal included.
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <span>
#include <vector>

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "grasp/hand_clearance.h"
#include "grasp/solver.h"
#include "grasp/solver_ours.h"
#include "hand/hand_model.h"
#include "sdf/sdf_grid.h"

namespace {

using namespace sdfg;

// An analytic target: signed distance (negative inside) and closest surface point.
struct Shape {
  std::function<float(const glm::vec3&)> distance;
  std::function<glm::vec3(const glm::vec3&)> closest;
};

// The shape as an exact source, as MeshExactSource answers for a mesh (searches bounded).
class AnalyticSource final : public ExactDistanceSource {
 public:
  explicit AnalyticSource(Shape shape) : shape_(std::move(shape)) {}
  void sample(std::span<const glm::vec3> points, std::span<const float> maxDistances,
              std::span<ExactSample> out) const override {
    for (size_t i = 0; i < points.size(); ++i) {
      const float d = shape_.distance(points[i]);
      out[i] = ExactSample{};
      if (std::abs(d) > maxDistances[i]) continue;
      out[i].distance = d;
      out[i].closest = shape_.closest(points[i]);
      out[i].feature = 0;
    }
  }

 private:
  Shape shape_;
};

// The reference grab box at 16^3 with the shape's exact distance at every node.
SdfGrid analyticGrid(const Shape& shape) {
  GridBox box = GridBox::referenceDefault();
  SdfGrid grid(box);
  const glm::uvec3 n = box.resolution;
  for (uint32_t k = 0; k < n.z; ++k)
    for (uint32_t j = 0; j < n.y; ++j)
      for (uint32_t i = 0; i < n.x; ++i)
        grid.values()[grid.index(i, j, k)] =
            shape.distance(box.handFromBox.transformPoint(box.nodeLocal(i, j, k)));
  return grid;
}

Shape halfSpace(const glm::vec3& onPlane, const glm::vec3& outward) {
  const glm::vec3 n = glm::normalize(outward);
  return {[=](const glm::vec3& p) { return glm::dot(p - onPlane, n); },
          [=](const glm::vec3& p) { return p - glm::dot(p - onPlane, n) * n; }};
}

Shape ball(const glm::vec3& centre, float radius) {
  return {[=](const glm::vec3& p) { return glm::length(p - centre) - radius; },
          [=](const glm::vec3& p) {
            const glm::vec3 d = p - centre;
            const float l = glm::length(d);
            return centre + (l > 0.0f ? d / l : glm::vec3(0.0f, 1.0f, 0.0f)) * radius;
          }};
}

// A floor {y < y0} and a wall {x < x0} together: outside, the nearer of the two; inside, the
// distance to the free quadrant x >= x0, y >= y0.
Shape concaveCorner(float x0, float y0) {
  return {[=](const glm::vec3& p) {
            const glm::vec2 q(x0 - p.x, y0 - p.y);
            if (q.x <= 0.0f && q.y <= 0.0f) return std::min(-q.x, -q.y);
            return -glm::length(glm::max(q, glm::vec2(0.0f)));
          },
          [=](const glm::vec3& p) {
            const glm::vec2 q(x0 - p.x, y0 - p.y);
            if (q.x <= 0.0f && q.y <= 0.0f)
              return -q.x < -q.y ? glm::vec3(x0, p.y, p.z) : glm::vec3(p.x, y0, p.z);
            return glm::vec3(std::max(p.x, x0), std::max(p.y, y0), p.z);
          }};
}

// A plate |z - zc| <= half, unbounded in x and y.
Shape plateAcrossZ(float zc, float half) {
  return {[=](const glm::vec3& p) { return std::abs(p.z - zc) - half; },
          [=](const glm::vec3& p) { return glm::vec3(p.x, p.y, zc + (p.z >= zc ? half : -half)); }};
}

struct OpenHand {
  HandModel model = HandModel::defaultAdult(Hand::right);
  HandParts parts{};
  int count = 0;
  glm::vec3 palm{0.0f};
  OpenHand() {
    count = handParts(model, FingerCurls{}, parts);
    JointPoses joints{};
    model.pose(FingerCurls{}, joints);
    palm = joints[size_t(Joint::palm)].position;
  }
  std::span<const HandPart> span() const { return std::span(parts.data(), size_t(count)); }
};

// Smallest clearance of the parts placed by `c` on the exact shape.
float clearance(std::span<const HandPart> parts, const Shape& shape, const Pose& c = {}) {
  float m = std::numeric_limits<float>::infinity();
  for (const HandPart& p : parts)
    m = std::min(m, shape.distance(c.transformPoint(p.centre)) - p.coverRadius);
  return m;
}

}  // namespace

TEST_CASE("hand parts cover every bone of the open hand", "[clearance]") {
  const OpenHand hand;
  REQUIRE(hand.count > 0);
  CHECK(hand.count < kMaxHandParts);
  // Every joint of every finger, metacarpal to tip, is the centre of a part.
  JointPoses joints{};
  hand.model.pose(FingerCurls{}, joints);
  for (int j = 0; j < kJointCount; ++j) {
    if (Joint(j) == Joint::wrist) continue;
    float nearest = 1.0f;
    for (const HandPart& p : hand.span())
      nearest = std::min(nearest, glm::length(p.centre - joints[size_t(j)].position));
    CAPTURE(jointName(Joint(j)));
    CHECK(nearest < 1e-5f);
  }
  // Neighbours along a bone overlap: the cover radius is never below the capsule's.
  for (const HandPart& p : hand.span()) CHECK(p.coverRadius >= p.radius);
}

TEST_CASE("clearance: a hand already clear is not moved", "[clearance]") {
  const OpenHand hand;
  const Shape floor = halfSpace(glm::vec3(0.0f, -0.06f, 0.0f), glm::vec3(0.0f, 1.0f, 0.0f));
  REQUIRE(clearance(hand.span(), floor) > 0.0f);
  const SdfGrid grid = analyticGrid(floor);
  const AnalyticSource exact(floor);
  Result<ClearanceResult> r = clearHand(hand.span(), hand.palm, &grid, &exact);
  REQUIRE(r.ok());
  CHECK_FALSE(r->wasInside);
  CHECK(r->displacement == 0.0f);
  CHECK(glm::length(r->handCorrection.position) == 0.0f);
}

TEST_CASE("clearance: one part in a ball leaves along the radius", "[clearance]") {
  // One sphere of 1 cm radius whose centre is 6 mm inside a 3 cm ball: the smallest move puts it
  // radius + margin outside, straight away from the ball's centre.
  const glm::vec3 centre(0.01f, -0.05f, -0.08f);
  const glm::vec3 dir = glm::normalize(glm::vec3(0.2f, 1.0f, -0.3f));
  HandPart part;
  part.centre = centre + dir * 0.024f;
  part.radius = part.coverRadius = 0.01f;
  const Shape target = ball(centre, 0.03f);
  const AnalyticSource exact(target);
  const SdfGrid grid = analyticGrid(target);
  ClearanceOptions o;
  o.margin = 0.0005f;
  Result<ClearanceResult> r = clearHand(std::span(&part, 1), part.centre, &grid, &exact, o);
  REQUIRE(r.ok());
  CHECK(r->wasInside);
  CHECK(r->clearanceBefore == Approx(-0.016f).margin(1e-6f));
  const float expected = 0.03f + 0.01f + o.margin - 0.024f;
  CHECK(r->displacement == Approx(expected).margin(2e-5f));
  CHECK(glm::dot(glm::normalize(r->handCorrection.position), dir) > 0.9999f);
  CHECK(r->clearanceAfter >= o.margin - 2e-5f);
}

TEST_CASE("clearance: a palm in a floor rises by its deepest part", "[clearance]") {
  const OpenHand hand;
  // A floor whose surface cuts the palm 8 mm above the palm joint's lowest point.
  const float palmBottom = hand.palm.y - hand.model.jointRadius(Joint::palm);
  const Shape floor = halfSpace(glm::vec3(0.0f, palmBottom + 0.008f, 0.0f), glm::vec3(0, 1, 0));
  const SdfGrid grid = analyticGrid(floor);
  const AnalyticSource exact(floor);
  ClearanceOptions o;
  // Exactly known: up, by the deepest part's depth plus the margin.
  const float expected = o.margin - clearance(hand.span(), floor);
  REQUIRE(expected > 0.008f);
  SECTION("on the exact distance") {
    Result<ClearanceResult> r = clearHand(hand.span(), hand.palm, &grid, &exact, o);
    REQUIRE(r.ok());
    CHECK(r->wasInside);
    CHECK_FALSE(r->exceeded);
    CHECK_FALSE(r->rotated);
    CHECK(r->displacement == Approx(expected).margin(2e-5f));
    CHECK(r->handCorrection.position.y == Approx(expected).margin(2e-5f));
    CHECK(clearance(hand.span(), floor, r->handCorrection) >= o.margin - 2e-5f);
  }
  SECTION("on the field alone") {
    // A plane is exact in a trilinear field: the same answer without an exact source.
    Result<ClearanceResult> r = clearHand(hand.span(), hand.palm, &grid, nullptr, o);
    REQUIRE(r.ok());
    CHECK(r->displacement == Approx(expected).margin(1e-4f));
    CHECK(clearance(hand.span(), floor, r->handCorrection) >= 0.0f);
  }
}

TEST_CASE("clearance: a hand in a concave corner leaves both faces at once", "[clearance]") {
  const OpenHand hand;
  // A wall at the thumb side and a floor under the palm, both cutting into the hand.
  float minX = 1.0f;
  for (const HandPart& p : hand.span()) minX = std::min(minX, p.centre.x - p.coverRadius);
  const float palmBottom = hand.palm.y - hand.model.jointRadius(Joint::palm);
  const float x0 = minX + 0.006f, y0 = palmBottom + 0.005f;
  const Shape corner = concaveCorner(x0, y0);
  const SdfGrid grid = analyticGrid(corner);
  const AnalyticSource exact(corner);
  ClearanceOptions o;
  o.rotation = false;
  // Each part must end beyond both planes by its radius and the margin.
  float tx = 0.0f, ty = 0.0f;
  for (const HandPart& p : hand.span()) {
    tx = std::max(tx, x0 + p.coverRadius + o.margin - p.centre.x);
    ty = std::max(ty, y0 + p.coverRadius + o.margin - p.centre.y);
  }
  Result<ClearanceResult> r = clearHand(hand.span(), hand.palm, &grid, &exact, o);
  REQUIRE(r.ok());
  CHECK(r->wasInside);
  CHECK(r->handCorrection.position.x == Approx(tx).margin(5e-5f));
  CHECK(r->handCorrection.position.y == Approx(ty).margin(5e-5f));
  CHECK(std::abs(r->handCorrection.position.z) < 5e-5f);
  CHECK(clearance(hand.span(), corner, r->handCorrection) >= 0.0f);
}

TEST_CASE("clearance: a thin plate through the fingers", "[clearance]") {
  const OpenHand hand;
  // A 4 mm plate across the fingers' middle phalanges. Sliding sideways never clears an
  // unbounded plate, and forward would take the palm through it: the smallest correction pulls
  // the hand back until the fingertips are behind the plate.
  JointPoses joints{};
  hand.model.pose(FingerCurls{}, joints);
  const float zc = joints[size_t(Joint::middle_intermediate)].position.z;
  const float half = 0.002f;
  const Shape plate = plateAcrossZ(zc, half);
  const SdfGrid grid = analyticGrid(plate);
  const AnalyticSource exact(plate);
  ClearanceOptions o;
  o.rotation = false;
  float back = 0.0f;
  for (const HandPart& p : hand.span())
    back = std::max(back, zc + half + p.coverRadius + o.margin - p.centre.z);
  REQUIRE(back > 0.03f);  // more than the default bound
  SECTION("past the bound the hand is not moved") {
    Result<ClearanceResult> r = clearHand(hand.span(), hand.palm, &grid, &exact, o);
    REQUIRE(r.ok());
    CHECK(r->wasInside);
    CHECK(r->exceeded);
    CHECK(glm::length(r->handCorrection.position) == 0.0f);
    CHECK(r->displacement == 0.0f);
  }
  SECTION("within a larger bound it pulls back by exactly what the fingertips need") {
    o.maxCorrection = 0.1f;
    Result<ClearanceResult> r = clearHand(hand.span(), hand.palm, &grid, &exact, o);
    REQUIRE(r.ok());
    CHECK_FALSE(r->exceeded);
    CHECK(r->handCorrection.position.z == Approx(back).margin(5e-5f));
    CHECK(glm::length(glm::vec2(r->handCorrection.position)) < 5e-5f);
    CHECK(clearance(hand.span(), plate, r->handCorrection) >= 0.0f);
  }
}

TEST_CASE("clearance: a turn is taken where sliding would move the hand more", "[clearance]") {
  const OpenHand hand;
  // The fingertips dip into a floor in front and the wrist end of the metacarpals into a
  // ceiling behind: sliding up frees the fingers and drives the back of the hand further into
  // the ceiling, while tilting the hand about the palm frees both.
  JointPoses joints{};
  hand.model.pose(FingerCurls{}, joints);
  const float tipY = joints[size_t(Joint::middle_tip)].position.y;
  const float baseY = joints[size_t(Joint::middle_metacarpal)].position.y;
  const float zFront = joints[size_t(Joint::middle_distal)].position.z;
  const float zBack = joints[size_t(Joint::middle_metacarpal)].position.z - 0.01f;
  const float rTip = hand.model.jointRadius(Joint::middle_tip);
  const float rBase = hand.model.jointRadius(Joint::middle_metacarpal);
  const float floorY = tipY - rTip + 0.006f, ceilY = baseY + rBase - 0.006f;
  // Floor only in front of zFront (z more negative), ceiling only behind zBack.
  const Shape shape{[=](const glm::vec3& p) {
                      const float floor = std::max(p.y - floorY, p.z - zFront);
                      const float ceil = std::max(ceilY - p.y, zBack - p.z);
                      return std::min(floor, ceil);
                    },
                    [=](const glm::vec3& p) {
                      const float floor = std::max(p.y - floorY, p.z - zFront);
                      const float ceil = std::max(ceilY - p.y, zBack - p.z);
                      if (floor < ceil) {
                        return p.y - floorY > p.z - zFront ? glm::vec3(p.x, floorY, p.z)
                                                           : glm::vec3(p.x, p.y, zFront);
                      }
                      return ceilY - p.y > zBack - p.z ? glm::vec3(p.x, ceilY, p.z)
                                                       : glm::vec3(p.x, p.y, zBack);
                    }};
  const SdfGrid grid = analyticGrid(shape);
  const AnalyticSource exact(shape);
  REQUIRE(clearance(hand.span(), shape) < 0.0f);
  ClearanceOptions slide;
  slide.rotation = false;
  slide.maxCorrection = 0.1f;
  ClearanceOptions turn = slide;
  turn.rotation = true;
  Result<ClearanceResult> a = clearHand(hand.span(), hand.palm, &grid, &exact, slide);
  Result<ClearanceResult> b = clearHand(hand.span(), hand.palm, &grid, &exact, turn);
  REQUIRE(a.ok());
  REQUIRE(b.ok());
  CHECK(b->rotated);
  CHECK(b->displacement < 0.8f * a->displacement);
  CHECK(clearance(hand.span(), shape, b->handCorrection) >= 0.0f);
  CHECK(clearance(hand.span(), shape, a->handCorrection) >= 0.0f);
}

TEST_CASE("clearance: bad options and missing distances are rejected", "[clearance]") {
  const OpenHand hand;
  const Shape floor = halfSpace(glm::vec3(0.0f), glm::vec3(0, 1, 0));
  const SdfGrid grid = analyticGrid(floor);
  ClearanceOptions bad;
  bad.margin = std::nanf("");
  CHECK_FALSE(clearHand(hand.span(), hand.palm, &grid, nullptr, bad).ok());
  bad = ClearanceOptions{};
  bad.maxIterations = 0;
  CHECK_FALSE(clearHand(hand.span(), hand.palm, &grid, nullptr, bad).ok());
  CHECK_FALSE(clearHand(hand.span(), hand.palm, nullptr, nullptr).ok());
}

namespace {

// Smallest clearance of the whole hand after a grasp, on the exact shape: the palm's sphere and
// every bone's capsule, metacarpal to tip, densely sampled, in the corrected hand placed by the
// result's hand correction.
float wholeHandClearance(const HandModel& hand, const GraspResult& result, const Shape& shape) {
  JointPoses open{};
  hand.pose(FingerCurls{}, open);
  const Pose& c = result.handCorrection;
  float m = shape.distance(c.transformPoint(open[size_t(Joint::palm)].position)) -
            hand.jointRadius(Joint::palm);
  for (int f = 0; f < kFingerCount; ++f) {
    const auto joints = fingerJoints(Finger(f));
    std::vector<Pose> poses(joints.size());
    hand.fingerPose(Finger(f), result.fingers[f].jointCurls, poses);
    for (size_t b = 0; b + 1 < joints.size(); ++b) {
      for (int k = 0; k <= 40; ++k) {
        const float t = float(k) / 40.0f;
        const glm::vec3 p = glm::mix(poses[b].position, poses[b + 1].position, t);
        const float r = glm::mix(hand.jointRadius(joints[b]), hand.jointRadius(joints[b + 1]), t);
        m = std::min(m, shape.distance(c.transformPoint(p)) - r);
      }
    }
  }
  return m;
}

GraspResult solveOurs(const HandModel& hand, const SdfGrid& grid, const ExactDistanceSource* exact,
                      const SolverOptions& options = {}) {
  OursSolver solver;
  REQUIRE(solver.prepare(hand, grid.box(), options) == Status::ok);
  GraspScene scene;
  scene.field = &grid;
  scene.exact = exact;
  GraspResult out;
  REQUIRE(solver.solve(scene, out) == Status::ok);
  return out;
}

}  // namespace

TEST_CASE("ours: the thumb's metacarpal does not pass through what it sweeps",
          "[clearance][ours]") {
  const OpenHand open;
  // A 1 cm ball beside the middle of the thumb's metacarpal where it ends when the hand closes:
  // only the metacarpal's capsule between its two joints reaches it.
  std::array<Pose, 4> closed{}, opened{};
  open.model.fingerPose(Finger::thumb, 1.0f, closed);
  open.model.fingerPose(Finger::thumb, 0.0f, opened);
  const glm::vec3 midClosed = glm::mix(closed[0].position, closed[1].position, 0.5f);
  const glm::vec3 midOpen = glm::mix(opened[0].position, opened[1].position, 0.5f);
  const glm::vec3 centre = midClosed + glm::normalize(midClosed - midOpen) * 0.018f;
  const Shape target = ball(centre, 0.01f);
  REQUIRE(clearance(open.span(), target) > 0.001f);
  // The closed thumb's phalanges and joints miss it: without its metacarpal the thumb would
  // close fully, through the ball.
  float phalanges = 1.0f, metacarpal = 1.0f;
  const auto joints = fingerJoints(Finger::thumb);
  for (size_t b = 0; b + 1 < joints.size(); ++b) {
    for (int k = 0; k <= 40; ++k) {
      const float t = float(k) / 40.0f;
      const float r =
          glm::mix(open.model.jointRadius(joints[b]), open.model.jointRadius(joints[b + 1]), t);
      const float c = target.distance(glm::mix(closed[b].position, closed[b + 1].position, t)) - r;
      (b == 0 && k < 40 ? metacarpal : phalanges) =
          std::min(b == 0 && k < 40 ? metacarpal : phalanges, c);
    }
  }
  REQUIRE(phalanges > 0.0f);
  REQUIRE(metacarpal < -0.004f);
  const SdfGrid grid = analyticGrid(target);
  const AnalyticSource exact(target);
  const GraspResult r = solveOurs(open.model, grid, &exact);
  const FingerState& thumb = r.fingers[int(Finger::thumb)];
  CHECK(thumb.contact);
  CHECK(thumb.jointCurls[0] < 1.0f);
  CHECK(wholeHandClearance(open.model, r, target) > -2e-4f);
}

TEST_CASE("ours: a palm inside the target is cleared before the fingers close",
          "[clearance][ours]") {
  const OpenHand open;
  const float palmBottom = open.palm.y - open.model.jointRadius(Joint::palm);
  const Shape floor = halfSpace(glm::vec3(0.0f, palmBottom + 0.01f, 0.0f), glm::vec3(0, 1, 0));
  const SdfGrid grid = analyticGrid(floor);
  const AnalyticSource exact(floor);
  REQUIRE(clearance(open.span(), floor) < -0.01f);
  SECTION("on by default: the whole hand ends clear") {
    const GraspResult r = solveOurs(open.model, grid, &exact);
    CHECK(r.openClearance < -0.01f);
    CHECK_FALSE(r.clearanceExceeded);
    CHECK(r.handMoved == Approx(SolverOptions{}.clearanceMargin - r.openClearance).margin(1e-4f));
    CHECK(wholeHandClearance(open.model, r, floor) > -2e-4f);
    int contacts = 0;
    for (const FingerState& f : r.fingers) contacts += f.contact ? 1 : 0;
    CHECK(contacts >= 4);
  }
  SECTION("switched off: the hand stays where it was, inside") {
    SolverOptions o;
    o.clearance = false;
    const GraspResult r = solveOurs(open.model, grid, &exact, o);
    CHECK(r.handMoved == 0.0f);
    CHECK(wholeHandClearance(open.model, r, floor) < -0.01f);
  }
  SECTION("a bound below the need leaves the hand and reports it") {
    SolverOptions o;
    o.clearanceBound = 0.005f;
    const GraspResult r = solveOurs(open.model, grid, &exact, o);
    CHECK(r.clearanceExceeded);
    CHECK(r.handMoved == 0.0f);
  }
}

TEST_CASE("ours: the approach brings only a palm within its range and angle onto the surface",
          "[clearance][ours][approach]") {
  const OpenHand open;
  // A floor 2 cm under the palm's lowest point, the palm facing it.
  const float palmBottom = open.palm.y - open.model.jointRadius(Joint::palm);
  const Shape floor = halfSpace(glm::vec3(0.0f, palmBottom - 0.02f, 0.0f), glm::vec3(0, 1, 0));
  const SdfGrid grid = analyticGrid(floor);
  const AnalyticSource exact(floor);
  REQUIRE(clearance(open.span(), floor) > 0.0f);
  SolverOptions o;
  o.approach = true;
  o.approachRange = 0.05f;
  SECTION("within range: the hand comes down onto the floor and ends clear") {
    const GraspResult r = solveOurs(open.model, grid, &exact, o);
    // Down toward the floor (the clearance then keeps the fingers, lower than the palm, out).
    CHECK(r.handMoved > 0.003f);
    CHECK(r.handCorrection.position.y < -0.003f);
    CHECK(wholeHandClearance(open.model, r, floor) > -2e-4f);
  }
  SECTION("out of range: the hand stays") {
    o.approachRange = 0.01f;
    const GraspResult r = solveOurs(open.model, grid, &exact, o);
    CHECK(r.handMoved == 0.0f);
  }
  SECTION("turned away beyond the angle: the hand stays") {
    // A floor whose normal is 0.3 rad off the palm's: refused at 0.2, taken at 0.4.
    JointPoses joints{};
    open.model.pose(FingerCurls{}, joints);
    const glm::vec3 palmNormal =
        joints[size_t(Joint::palm)].transformVector(glm::vec3(0.0f, -1.0f, 0.0f));
    const glm::vec3 axis = glm::normalize(glm::cross(palmNormal, glm::vec3(1.0f, 0.0f, 0.0f)));
    const glm::vec3 down = glm::angleAxis(0.3f, axis) * palmNormal;
    const Shape tilted =
        halfSpace(open.palm + down * (open.model.jointRadius(Joint::palm) + 0.02f), -down);
    const SdfGrid tiltedGrid = analyticGrid(tilted);
    const AnalyticSource tiltedExact(tilted);
    REQUIRE(clearance(open.span(), tilted) > 0.0f);
    o.approachMaxAngle = 0.2f;
    CHECK(solveOurs(open.model, tiltedGrid, &tiltedExact, o).handMoved == 0.0f);
    o.approachMaxAngle = 0.4f;
    CHECK(solveOurs(open.model, tiltedGrid, &tiltedExact, o).handMoved > 0.003f);
  }
}
