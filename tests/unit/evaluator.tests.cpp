#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtx/quaternion.hpp>

#include "eval/evaluator.h"
#include "eval/placements.h"
#include "hand/hand_model.h"
#include "io/shapes.h"
#include "mesh/mesh.h"

using namespace sdfg;

namespace {

float boxSignedDistance(const glm::vec3& p, const glm::vec3& half) {
  const glm::vec3 q = glm::abs(p) - half;
  const float outside = glm::length(glm::max(q, glm::vec3(0.0f)));
  const float inside = std::min(std::max(q.x, std::max(q.y, q.z)), 0.0f);
  return outside + inside;
}

std::unique_ptr<ExactMeshQuery> queryOf(const TriangleMesh& mesh) {
  auto q = ExactMeshQuery::create(mesh);
  REQUIRE(q.ok());
  return std::move(q).value();
}

TriangleMesh sphereAt(const glm::vec3& centre, float radius) {
  TriangleMesh s = makeSphere(radius, 4);
  transformMesh(s, Pose{glm::quat(1, 0, 0, 0), centre});
  return s;
}

// Where the bone ending at the fingertip points, hand space, at curl a.
glm::vec3 tipDirection(const HandModel& hand, Finger finger, float a) {
  std::vector<Pose> poses(fingerJoints(finger).size());
  hand.fingerPose(finger, a, poses);
  return glm::normalize(poses.back().position - poses[poses.size() - 2].position);
}

GraspResult allAt(float curl) {
  GraspResult g;
  for (auto& f : g.fingers) {
    f.curl = curl;
    f.jointCurls = {curl, curl, curl, curl};
  }
  return g;
}

}  // namespace

TEST_CASE("Exact signed distance matches a box and a sphere analytically", "[core][evaluator]") {
  SECTION("Box: points inside, outside and near edges and corners") {
    const glm::vec3 extent(0.10f, 0.06f, 0.04f);
    auto q = queryOf(makeBox(extent));
    int checked = 0;
    for (float x = -0.08f; x <= 0.08f; x += 0.0173f) {
      for (float y = -0.05f; y <= 0.05f; y += 0.0131f) {
        for (float z = -0.04f; z <= 0.04f; z += 0.0117f) {
          const glm::vec3 p(x, y, z);
          const float expected = boxSignedDistance(p, extent * 0.5f);
          CHECK(q->signedDistance(p) == Approx(expected).margin(1e-5));
          CHECK(q->inside(p) == (expected < 0.0f));
          ++checked;
        }
      }
    }
    CHECK(checked > 500);
  }
  SECTION("Sphere: distance within the tessellation's chord error") {
    const float radius = 0.05f;
    auto q = queryOf(makeSphere(radius, 4));
    for (int i = 0; i < 200; ++i) {
      // A deterministic spread of directions and radii, inside and outside.
      const float t = float(i) * 0.61803398875f;
      const glm::vec3 dir = glm::normalize(
          glm::vec3(std::sin(t * 7.1f), std::cos(t * 3.3f), std::sin(t * 1.7f + 0.4f)));
      const float r = 0.005f + 0.09f * std::fmod(t, 1.0f);
      const glm::vec3 p = dir * r;
      CHECK(q->signedDistance(p) == Approx(r - radius).margin(3e-4));
    }
  }
  SECTION("Chained queries agree with one query per point") {
    auto q = queryOf(makeTorus());
    std::vector<glm::vec3> chain;
    for (int i = 0; i <= 200; ++i) chain.push_back(glm::vec3(-0.08f + 0.0008f * i, 0.001f, 0.002f));
    std::vector<double> d(chain.size());
    q->signedDistances(chain, d);
    for (size_t i = 0; i < chain.size(); ++i) CHECK(d[i] == Approx(q->signedDistance(chain[i])));
  }
  SECTION("Inside stays right on a sphere with a small hole (open mesh)") {
    TriangleMesh open = makeSphere(0.05f, 3);
    // Drop the 6 triangles nearest the +Y pole: a small hole like the bunny's base.
    std::vector<std::pair<float, size_t>> byHeight;
    for (size_t t = 0; t < open.triangleCount(); ++t) {
      byHeight.emplace_back(
          -(open.positions[open.indices[3 * t]].y + open.positions[open.indices[3 * t + 1]].y +
            open.positions[open.indices[3 * t + 2]].y),
          t);
    }
    std::sort(byHeight.begin(), byHeight.end());
    std::vector<uint32_t> kept;
    for (size_t k = 6; k < byHeight.size(); ++k) {
      const size_t t = byHeight[k].second;
      kept.insert(kept.end(), &open.indices[3 * t], &open.indices[3 * t] + 3);
    }
    REQUIRE(kept.size() + 18 == open.indices.size());
    open.indices = kept;
    auto q = queryOf(open);
    int wrong = 0;
    for (int i = 0; i < 100; ++i) {
      const float t = float(i) * 0.61803398875f;
      const glm::vec3 dir = glm::normalize(
          glm::vec3(std::sin(t * 7.1f), std::cos(t * 3.3f), std::sin(t * 1.7f + 0.4f)));
      wrong += q->inside(dir * 0.03f) ? 0 : 1;
      wrong += q->inside(dir * 0.07f) ? 1 : 0;
    }
    CHECK(wrong == 0);
  }
  SECTION("An invalid mesh is an error, not a crash") {
    TriangleMesh bad;
    bad.positions = {glm::vec3(0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0)};
    bad.indices = {0, 1, 7};
    auto q = ExactMeshQuery::create(bad);
    REQUIRE_FALSE(q.ok());
    CHECK(q.error().code == Status::invalid_argument);
  }
}

TEST_CASE("Grasp metrics report penetration, residual and early stops", "[core][evaluator]") {
  const HandModel hand = HandModel::defaultAdult(Hand::right);
  const Finger index = Finger::index;
  const float rTip = hand.tipRadius(index);
  const Pose identity;

  SECTION("A fingertip pushed into a small sphere penetrates by the known depth") {
    const float a = 0.3f, depth = 0.003f, radius = 0.006f;
    const glm::vec3 tip = hand.tipPosition(index, a);
    const glm::vec3 centre = tip + tipDirection(hand, index, a) * (radius + rTip - depth);
    auto q = queryOf(sphereAt(centre, radius));
    GraspResult g = allAt(0.0f);
    g.fingers[int(index)].curl = a;
    g.fingers[int(index)].jointCurls = {a, a, a, a};
    g.fingers[int(index)].contact = true;
    const GraspMetrics m = evaluateGrasp(*q, hand, identity, g);
    CHECK(m.fingers[int(index)].penetrationMm == Approx(depth * 1000.0f).margin(0.1));
    CHECK(m.penetrationMm == Approx(depth * 1000.0f).margin(0.1));
    CHECK(m.fingers[int(index)].touching);
    CHECK(m.fingers[int(Finger::little)].penetrationMm == 0.0f);
  }
  SECTION("A fingertip stopped at a known gap has that residual and touches") {
    const float a = 0.4f, gap = 0.0015f, radius = 0.01f;
    const glm::vec3 tip = hand.tipPosition(index, a);
    const glm::vec3 centre = tip + tipDirection(hand, index, a) * (radius + rTip + gap);
    auto q = queryOf(sphereAt(centre, radius));
    GraspResult g = allAt(0.0f);
    g.fingers[int(index)].curl = a;
    g.fingers[int(index)].jointCurls = {a, a, a, a};
    g.fingers[int(index)].contact = true;
    const GraspMetrics m = evaluateGrasp(*q, hand, identity, g);
    const FingerMetrics& f = m.fingers[int(index)];
    CHECK(f.contact);
    CHECK(f.tipResidualMm == Approx(gap * 1000.0f).margin(0.1));
    CHECK(f.tipGapMm == Approx(gap * 1000.0f).margin(0.1));
    CHECK(f.penetrationMm == 0.0f);
    CHECK(f.touching);
    CHECK_FALSE(f.earlyStop);
    CHECK(m.contacts >= 1);
    // The tip is the contact: both residuals agree.
    CHECK(f.tipIsContact);
    CHECK(f.contactResidualMm == Approx(gap * 1000.0f).margin(0.1));
    CHECK_FALSE(f.passThrough);
  }
  SECTION("A finger touching with its middle phalanx has that gap as contact residual") {
    // Straight finger (curl 0); a sphere just under the intermediate joint, on the side the
    // finger closes towards, at a known gap from that joint's sphere.
    const float gap = 0.001f, radius = 0.01f;
    const std::span<const Joint> joints = fingerJoints(index);
    std::vector<Pose> poses(joints.size());
    hand.fingerPose(index, 0.0f, poses);
    const glm::vec3 joint = poses[2].position;
    const float r = hand.jointRadius(joints[2]);
    const glm::vec3 bone = glm::normalize(poses[3].position - poses[2].position);
    glm::vec3 closing = hand.tipPosition(index, 0.2f) - hand.tipPosition(index, 0.0f);
    closing = glm::normalize(closing - bone * glm::dot(closing, bone));
    auto q = queryOf(sphereAt(joint + closing * (r + gap + radius), radius));
    GraspResult g = allAt(0.0f);
    g.fingers[int(index)].contact = true;
    const GraspMetrics m = evaluateGrasp(*q, hand, identity, g);
    const FingerMetrics& f = m.fingers[int(index)];
    CHECK(f.clearanceMm == Approx(gap * 1000.0f).margin(0.15));
    CHECK(f.contactResidualMm == Approx(gap * 1000.0f).margin(0.15));
    CHECK_FALSE(f.tipIsContact);
    CHECK(f.tipResidualMm > f.contactResidualMm + 2.0f);
    CHECK(f.penetrationMm == 0.0f);
    CHECK_FALSE(f.passThrough);
  }
  SECTION("The fingers are graded where the solver moved the hand (handCorrection)") {
    // A tip touching a sphere at a known gap in the corrected hand frame; the correction moves
    // the hand 2 cm. Graded in the placement's frame without the correction, the tip would be
    // 2 cm from where it was put.
    const float a = 0.4f, gap = 0.0015f, radius = 0.01f;
    const Pose correction{glm::quat(1, 0, 0, 0), glm::vec3(0.0f, 0.02f, 0.0f)};
    const glm::vec3 tip = hand.tipPosition(index, a);
    const glm::vec3 centre = tip + tipDirection(hand, index, a) * (radius + rTip + gap);
    auto q = queryOf(sphereAt(correction.transformPoint(centre), radius));
    GraspResult g = allAt(0.0f);
    g.handCorrection = correction;
    g.fingers[int(index)].curl = a;
    g.fingers[int(index)].jointCurls = {a, a, a, a};
    g.fingers[int(index)].contact = true;
    const FingerMetrics f = evaluateGrasp(*q, hand, identity, g).fingers[int(index)];
    CHECK(f.tipGapMm == Approx(gap * 1000.0f).margin(0.1));
    CHECK(f.contactResidualMm == Approx(gap * 1000.0f).margin(0.1));
  }
  SECTION("A thumb metacarpal that turns as the thumb closes is graded with its phalanges") {
    // The thumb's metacarpal turns at its base (the others are fixed): a part pressed into its
    // middle is penetration of the thumb, and the closest part there is its contact.
    const Finger thumb = Finger::thumb;
    const std::span<const Joint> joints = fingerJoints(thumb);
    std::vector<Pose> poses(joints.size());
    hand.fingerPose(thumb, 0.0f, poses);
    const glm::vec3 mid = 0.5f * (poses[0].position + poses[1].position);
    const float r = 0.5f * (hand.jointRadius(joints[0]) + hand.jointRadius(joints[1]));
    const glm::vec3 bone = glm::normalize(poses[1].position - poses[0].position);
    glm::vec3 side = glm::cross(bone, glm::vec3(0.0f, 1.0f, 0.0f));
    side = glm::normalize(side);
    const float depth = 0.002f, radius = 0.006f;
    auto q = queryOf(sphereAt(mid + side * (r + radius - depth), radius));
    GraspResult g = allAt(0.0f);
    g.fingers[int(thumb)].contact = true;
    const FingerMetrics f = evaluateGrasp(*q, hand, identity, g).fingers[int(thumb)];
    CHECK(f.penetrationMm == Approx(depth * 1000.0f).margin(0.3));
    CHECK(f.contactResidualMm == Approx(depth * 1000.0f).margin(0.3));
  }
  SECTION("A finger whose sweep crosses a thin plate passes through; one stopped short does not") {
    // A 3 mm plate across the index tip's path at curl 0.5, square to the tip's motion there.
    const glm::vec3 at = hand.tipPosition(index, 0.5f);
    const glm::vec3 motion =
        glm::normalize(hand.tipPosition(index, 0.52f) - hand.tipPosition(index, 0.48f));
    TriangleMesh plate = makeBox(glm::vec3(0.02f, 0.003f, 0.02f));
    transformMesh(plate, Pose{glm::rotation(glm::vec3(0.0f, 1.0f, 0.0f), motion), at});
    auto q = queryOf(plate);
    // Precondition: the tip centre is inside the plate at curl 0.5 and outside at both ends.
    REQUIRE(q->inside(at));
    REQUIRE_FALSE(q->inside(hand.tipPosition(index, 1.0f)));
    REQUIRE(q->signedDistance(hand.tipPosition(index, 0.3f)) > rTip);

    GraspResult through = allAt(0.0f);
    through.fingers[int(index)] = allAt(1.0f).fingers[int(index)];
    const GraspMetrics m = evaluateGrasp(*q, hand, identity, through);
    CHECK(m.fingers[int(index)].passThrough);
    CHECK(m.passThroughs >= 1);

    GraspResult shortOf = allAt(0.0f);
    shortOf.fingers[int(index)] = allAt(0.3f).fingers[int(index)];
    const GraspMetrics s = evaluateGrasp(*q, hand, identity, shortOf);
    CHECK_FALSE(s.fingers[int(index)].passThrough);
  }
  SECTION("A finger left open above a plane it could reach is an early stop") {
    const float reach = 0.5f;
    const glm::vec3 tipAtReach = hand.tipPosition(index, reach);
    const float planeY = tipAtReach.y - rTip - 0.002f;
    // Precondition of the construction: at `reach` the whole finger is still above the plane.
    std::vector<BodySphere> spheres;
    hand.phalanxSpheres(index, reach, spheres);
    for (const BodySphere& s : spheres) REQUIRE(s.center.y - s.radius >= planeY - 1e-4f);
    REQUIRE(hand.tipPosition(index, 0.0f).y - rTip - planeY > 0.006f);

    TriangleMesh slab = makeBox(glm::vec3(0.6f, 0.02f, 0.6f));
    transformMesh(slab, Pose{glm::quat(1, 0, 0, 0), glm::vec3(0.0f, planeY - 0.01f, 0.0f)});
    auto q = queryOf(slab);

    GraspResult g = allAt(1.0f);            // closed without contact: not stopped
    g.fingers[int(index)] = FingerState{};  // open, curl 0
    const GraspMetrics open = evaluateGrasp(*q, hand, identity, g);
    CHECK(open.fingers[int(index)].stopped);
    CHECK(open.fingers[int(index)].tipGapMm > kEarlyStopGapMm);
    CHECK(open.fingers[int(index)].earlyStop);
    CHECK(open.earlyStops >= 1);

    // The same finger stopped at the plane is not early.
    g.fingers[int(index)].curl = reach;
    g.fingers[int(index)].jointCurls = {reach, reach, reach, reach};
    g.fingers[int(index)].contact = true;
    const GraspMetrics atPlane = evaluateGrasp(*q, hand, identity, g);
    CHECK_FALSE(atPlane.fingers[int(index)].earlyStop);
    CHECK(atPlane.fingers[int(index)].tipGapMm <= kEarlyStopGapMm);
  }
  SECTION("Non-finite input gives NaN metrics, not a crash") {
    auto q = queryOf(makeBox(glm::vec3(0.05f)));
    CHECK(std::isnan(q->signedDistance(glm::vec3(std::nanf(""), 0.0f, 0.0f))));
    Pose broken;
    broken.position.x = std::numeric_limits<float>::infinity();
    const GraspMetrics m = evaluateGrasp(*q, hand, broken, allAt(0.5f));
    CHECK(std::isnan(m.penetrationMm));
    GraspResult nanCurls = allAt(std::nanf(""));
    const GraspMetrics clamped =
        evaluateGrasp(*q, hand, Pose{glm::quat(1, 0, 0, 0), glm::vec3(0, 1, 0)}, nanCurls);
    CHECK(std::isfinite(clamped.penetrationMm));
  }
  SECTION("A finger far from anything it could reach is not an early stop") {
    auto q = queryOf(sphereAt(glm::vec3(0.0f, 0.5f, 0.0f), 0.02f));  // behind the back of the hand
    const GraspMetrics m = evaluateGrasp(*q, hand, identity, allAt(0.2f));
    for (const FingerMetrics& f : m.fingers) {
      CHECK(f.stopped);
      CHECK_FALSE(f.earlyStop);
      CHECK_FALSE(f.touching);
    }
    CHECK(m.contacts == 0);
  }
}

TEST_CASE("Placements are seeded, counted and put the palm over the surface",
          "[core][evaluator][placements]") {
  const HandModel hand = HandModel::defaultAdult(Hand::right);
  const GridBox box = GridBox::referenceDefault();
  const TriangleMesh mesh = normalizedToDiagonal(makeMug(), 0.18f);
  auto q = queryOf(mesh);
  const int count = 24;
  const std::vector<Placement> a = generatePlacements(mesh, *q, hand, box, count, 7);
  const std::vector<Placement> b = generatePlacements(mesh, *q, hand, box, count, 7);
  const std::vector<Placement> c = generatePlacements(mesh, *q, hand, box, count, 8);

  SECTION("The count is honoured and every attempt is accounted for") {
    CHECK(a.size() == size_t(count));
    PlacementStats stats;
    CHECK(generatePlacements(mesh, *q, hand, box, count, 7, &stats).size() == size_t(count));
    CHECK(stats.attempts == count + stats.outsideBox + stats.handIntersecting);
    CHECK(c.size() == size_t(count));
    CHECK(generatePlacements(mesh, *q, hand, box, 0, 7).empty());
  }
  SECTION("The same seed gives the same placements, another seed others") {
    REQUIRE(a.size() == b.size());
    for (size_t i = 0; i < a.size(); ++i) {
      CHECK(a[i].surfacePoint == b[i].surfacePoint);
      CHECK(a[i].objectFromHand.position == b[i].objectFromHand.position);
      CHECK(a[i].objectFromHand.orientation == b[i].objectFromHand.orientation);
    }
    int differing = 0;
    for (size_t i = 0; i < std::min(a.size(), c.size()); ++i) {
      differing += glm::length(a[i].surfacePoint - c[i].surfacePoint) > 1e-4f ? 1 : 0;
    }
    CHECK(differing > count / 2);
  }
  SECTION("The palm is 1 to 4 cm from the surface, facing it, and the open hand is clear") {
    JointPoses joints;
    hand.pose(FingerCurls{}, joints);
    const Pose handFromPalm = joints[size_t(Joint::palm)];
    for (const Placement& p : a) {
      const Pose objectFromPalm = p.objectFromHand * handFromPalm;
      const glm::vec3 palm = objectFromPalm.position;
      const float along = glm::dot(palm - p.surfacePoint, p.normal);
      CHECK(along >= kMinPalmDistance - 1e-4f);
      CHECK(along <= kMaxPalmDistance + 1e-4f);
      CHECK(glm::length(palm - p.surfacePoint) == Approx(p.palmDistance).margin(1e-4));
      CHECK(q->unsignedDistance(p.surfacePoint) < 1e-5);
      CHECK(q->unsignedDistance(palm) <= p.palmDistance + 1e-4);
      // The palm side is -Y: it must point along -normal.
      const glm::vec3 palmSide = objectFromPalm.transformVector(glm::vec3(0, -1, 0));
      CHECK(glm::dot(palmSide, p.normal) == Approx(-1.0f).margin(1e-4));
      CHECK_FALSE(openHandIntersects(*q, hand, p.objectFromHand));
    }
  }
}
