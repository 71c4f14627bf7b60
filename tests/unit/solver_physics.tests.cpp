// The physics baseline (Algorithm 1 over Bullet colliders) on box-built scenes where the true
// contact is known in closed form.
#include <catch2/catch.hpp>

#include <cmath>
#include <ctime>
#include <iostream>
#include <limits>

#include "eval/solver_physics.h"
#include "grasp_scenes.h"

namespace {

using namespace sdfg;
using sdfg::test::appendBox;
using sdfg::test::boxDistance;
using sdfg::test::firstContactCurl;

using Kind = PhysicsCollider::Kind;

std::unique_ptr<PhysicsCollider> makeCollider(const TriangleMesh& mesh, Kind kind) {
  auto collider = PhysicsCollider::create(mesh, kind);
  REQUIRE(collider.ok());
  return std::move(collider).value();
}

// Bounds of one finger's tip curve (sampled finely).
struct CurveBounds {
  glm::vec3 lo{1e9f}, hi{-1e9f};
};
CurveBounds curveBounds(const HandModel& hand, Finger finger) {
  CurveBounds b;
  for (int s = 0; s <= 200; ++s) {
    const glm::vec3 p = hand.tipPosition(finger, s / 200.0f);
    b.lo = glm::min(b.lo, p);
    b.hi = glm::max(b.hi, p);
  }
  return b;
}

constexpr float kBulletSlack = 0.003f;  // curl; Bullet's GJK/EPA tolerance along the curve

}  // namespace

TEST_CASE("physics colliders report sphere overlaps at known distances", "[solver][physics]") {
  const Kind kind = GENERATE(Kind::convexHull, Kind::triangleMesh);
  CAPTURE(int(kind));
  TriangleMesh cube;
  appendBox(cube, glm::vec3(-0.05f), glm::vec3(0.05f));
  const auto collider = makeCollider(cube, kind);
  CHECK(collider->kind() == kind);
  CHECK(collider->shapeVertexCount() == 8);
  const float r = 0.01f;

  SECTION("against a face: 1 mm in overlaps, 1.5 mm out does not") {
    float centreDistance = -1.0f;
    CHECK(collider->sphereOverlaps(glm::vec3(0.0f, 0.05f + r - 0.001f, 0.0f), r, centreDistance));
    CHECK(centreDistance == Approx(r - 0.001f).margin(2e-4));
    CHECK_FALSE(collider->sphereOverlaps(glm::vec3(0.0f, 0.05f + r + 0.0015f, 0.0f), r));
    CHECK_FALSE(collider->sphereOverlaps(glm::vec3(-0.05f - r - 0.0015f, 0.01f, 0.02f), r));
    CHECK(collider->sphereOverlaps(glm::vec3(0.01f, -0.02f, -0.05f - r + 0.001f), r));
  }
  SECTION("against an edge and a corner, along the diagonal") {
    const glm::vec3 edge(0.05f, 0.05f, 0.0f), corner(0.05f);
    const glm::vec3 edgeDir = glm::normalize(glm::vec3(1, 1, 0));
    const glm::vec3 cornerDir = glm::normalize(glm::vec3(1, 1, 1));
    CHECK(collider->sphereOverlaps(edge + edgeDir * (r - 0.001f), r));
    CHECK_FALSE(collider->sphereOverlaps(edge + edgeDir * (r + 0.0015f), r));
    CHECK(collider->sphereOverlaps(corner + cornerDir * (r - 0.001f), r));
    CHECK_FALSE(collider->sphereOverlaps(corner + cornerDir * (r + 0.0015f), r));
  }
  SECTION("a sphere deep inside: the hull is solid, a mesh collider sees no triangle") {
    // Documented behaviour of triangle-mesh colliders, not a bug of this wrapper.
    const bool inside = collider->sphereOverlaps(glm::vec3(0.0f), r);
    CHECK(inside == (kind == Kind::convexHull));
  }
  SECTION("a sphere crossing a face from inside overlaps with both") {
    CHECK(collider->sphereOverlaps(glm::vec3(0.0f, 0.045f, 0.0f), r));
  }
}

TEST_CASE("physics colliders reject invalid meshes", "[solver][physics]") {
  const Kind kind = GENERATE(Kind::convexHull, Kind::triangleMesh);
  SECTION("an empty mesh") {
    auto collider = PhysicsCollider::create(TriangleMesh{}, kind);
    REQUIRE_FALSE(collider.ok());
    CHECK(collider.error().code == Status::invalid_argument);
    CHECK(collider.error().message.find("empty") != std::string::npos);
  }
  SECTION("an index out of range or a NaN vertex") {
    TriangleMesh mesh;
    appendBox(mesh, glm::vec3(0.0f), glm::vec3(1.0f));
    mesh.indices[4] = 99;
    CHECK_FALSE(PhysicsCollider::create(mesh, kind).ok());
    mesh.indices[4] = 1;
    mesh.positions[2].y = std::numeric_limits<float>::quiet_NaN();
    CHECK_FALSE(PhysicsCollider::create(mesh, kind).ok());
  }
}

TEST_CASE("the convex hull keeps only hull vertices", "[solver][physics]") {
  // Two boxes, one inside the other: the inner box's 8 corners are not on the hull.
  TriangleMesh mesh;
  appendBox(mesh, glm::vec3(-0.05f), glm::vec3(0.05f));
  appendBox(mesh, glm::vec3(-0.01f), glm::vec3(0.01f));
  CHECK(makeCollider(mesh, Kind::convexHull)->shapeVertexCount() == 8);
  CHECK(makeCollider(mesh, Kind::triangleMesh)->shapeVertexCount() == 16);
}

TEST_CASE("physics solvers stop within one fine step of the true contact on a slab",
          "[solver][physics]") {
  const Kind kind = GENERATE(Kind::convexHull, Kind::triangleMesh);
  CAPTURE(int(kind));
  const HandModel hand = HandModel::defaultAdult(Hand::right);
  // A wide slab under the palm whose top the long fingers reach mid-curl.
  float lowest = 1.0f, open = -1.0f;
  for (Finger f : {Finger::index, Finger::middle, Finger::ring}) {
    const CurveBounds b = curveBounds(hand, f);
    lowest = std::min(lowest, b.lo.y);
    open = std::max(open, hand.tipPosition(f, 0.0f).y);
  }
  const float top = lowest + 0.4f * (open - lowest);
  const glm::vec3 lo(-0.4f, top - 0.05f, -0.5f), hi(0.4f, top, 0.3f);
  TriangleMesh slab;
  appendBox(slab, lo, hi);
  const auto collider = makeCollider(slab, kind);
  const auto distance = [&](const glm::vec3& p) { return boxDistance(p, lo, hi); };

  SolverOptions options;
  const float coarse = GENERATE(0.1f, 0.25f);
  options.da = coarse;
  PhysicsSolver solver(kind);
  REQUIRE(solver.prepare(hand, GridBox::referenceDefault(), options) == Status::ok);
  GraspScene scene;
  scene.collider = collider.get();
  GraspResult result;
  REQUIRE(solver.solve(scene, result) == Status::ok);

  int touching = 0, tunnelled = 0;
  for (int f = 0; f < kFingerCount; ++f) {
    const Finger finger = Finger(f);
    const FingerState& state = result.fingers[f];
    const std::optional<float> truth =
        firstContactCurl(hand, finger, distance, hand.tipRadius(finger));
    CAPTURE(fingerName(finger), coarse, state.curl, truth.value_or(-1.0f));
    CHECK(state.jointCurls[2] == state.curl);
    CHECK(glm::distance(state.contactPoint, hand.tipPosition(finger, state.curl)) < 1e-6f);
    if (!truth) {
      CHECK_FALSE(state.contact);
      CHECK(state.curl == 1.0f);
      CHECK(std::isinf(state.distance));
      continue;
    }
    ++touching;
    // A mesh collider has no inside: when the first coarse step past the contact puts the whole
    // tip sphere inside the slab, no triangle is touched and the finger passes through. That is
    // the real behaviour of mesh colliders; the hull is solid and never misses.
    const float firstPast = std::min(std::ceil(*truth / coarse) * coarse, 1.0f);
    if (kind == Kind::triangleMesh &&
        distance(hand.tipPosition(finger, firstPast)) < -hand.tipRadius(finger) - 1e-4f) {
      ++tunnelled;
      continue;
    }
    CHECK(state.contact);
    // Algorithm 1 stops on the first fine step that overlaps: at or after the true contact,
    // less than one fine step past it.
    CHECK(state.curl >= *truth - kBulletSlack);
    CHECK(state.curl <= *truth + options.refineStep + kBulletSlack);
    CHECK(state.distance <= hand.tipRadius(finger) + 1e-4f);
    CHECK(state.distance == Approx(distance(state.contactPoint)).margin(5e-4));
  }
  CHECK(touching >= 3);
  CHECK(tunnelled < touching);
}

TEST_CASE("physics-convex stops early on a concave object where physics-mesh does not",
          "[solver][physics]") {
  const HandModel hand = HandModel::defaultAdult(Hand::right);
  const Finger finger = Finger::index;
  const float r = hand.tipRadius(finger);
  // A U-shaped channel under the index finger: a floor its tip reaches late in the curl, and
  // two walls beside the tip's path whose tops it passes early. The hull of the channel is its
  // bounding box, so the hull's top is the walls' top.
  const CurveBounds path = curveBounds(hand, finger);
  const float openY = hand.tipPosition(finger, 0.0f).y;
  const float wallTop = openY - r - 0.01f;
  const float floorTop = path.lo.y + 0.3f * (wallTop - path.lo.y);
  const float xc = 0.5f * (path.lo.x + path.hi.x);
  const float halfGap = 0.5f * (path.hi.x - path.lo.x) + r + 0.015f;
  const float z0 = path.lo.z - 0.03f, z1 = path.hi.z + 0.03f, t = 0.01f;
  const glm::vec3 floorLo(xc - halfGap - t, floorTop - 0.02f, z0),
      floorHi(xc + halfGap + t, floorTop, z1);
  const glm::vec3 leftLo(xc - halfGap - t, floorTop, z0), leftHi(xc - halfGap, wallTop, z1);
  const glm::vec3 rightLo(xc + halfGap, floorTop, z0), rightHi(xc + halfGap + t, wallTop, z1);
  TriangleMesh channel;
  appendBox(channel, floorLo, floorHi);
  appendBox(channel, leftLo, leftHi);
  appendBox(channel, rightLo, rightHi);
  const auto meshDistance = [&](const glm::vec3& p) {
    return std::min({boxDistance(p, floorLo, floorHi), boxDistance(p, leftLo, leftHi),
                     boxDistance(p, rightLo, rightHi)});
  };
  const auto hullDistance = [&](const glm::vec3& p) {
    return boxDistance(p, floorLo, glm::vec3(rightHi.x, wallTop, z1));
  };
  const std::optional<float> hullTruth = firstContactCurl(hand, finger, hullDistance, r);
  const std::optional<float> meshTruth = firstContactCurl(hand, finger, meshDistance, r);
  REQUIRE(hullTruth);
  REQUIRE(meshTruth);
  CAPTURE(*hullTruth, *meshTruth);
  REQUIRE(*hullTruth + 0.05f < *meshTruth);

  const auto convex = makeCollider(channel, Kind::convexHull);
  const auto exact = makeCollider(channel, Kind::triangleMesh);
  PhysicsSolver convexSolver(Kind::convexHull), meshSolver(Kind::triangleMesh);
  const SolverOptions options;
  REQUIRE(convexSolver.prepare(hand, GridBox::referenceDefault(), options) == Status::ok);
  REQUIRE(meshSolver.prepare(hand, GridBox::referenceDefault(), options) == Status::ok);
  GraspScene scene;
  GraspResult convexResult, meshResult;
  scene.collider = convex.get();
  REQUIRE(convexSolver.solve(scene, convexResult) == Status::ok);
  scene.collider = exact.get();
  REQUIRE(meshSolver.solve(scene, meshResult) == Status::ok);

  const FingerState& onHull = convexResult.fingers[int(finger)];
  const FingerState& onMesh = meshResult.fingers[int(finger)];
  CAPTURE(onHull.curl, onMesh.curl);
  CHECK(onHull.contact);
  CHECK(onMesh.contact);
  CHECK(onHull.curl <= *hullTruth + options.refineStep + kBulletSlack);
  CHECK(onHull.curl >= *hullTruth - kBulletSlack);
  CHECK(onMesh.curl <= *meshTruth + options.refineStep + kBulletSlack);
  CHECK(onMesh.curl >= *meshTruth - kBulletSlack);
  CHECK(onHull.curl < onMesh.curl);
}

TEST_CASE("physics solvers: nothing to touch, touching when open, and bad scenes",
          "[solver][physics]") {
  const Kind kind = GENERATE(Kind::convexHull, Kind::triangleMesh);
  CAPTURE(int(kind));
  const HandModel hand = HandModel::defaultAdult(Hand::right);
  PhysicsSolver solver(kind);
  GraspScene scene;
  GraspResult result;
  TriangleMesh cube;
  appendBox(cube, glm::vec3(-0.05f), glm::vec3(0.05f));
  const auto collider = makeCollider(cube, kind);

  SECTION("solve before prepare, without a collider or with the other kind fails") {
    scene.collider = collider.get();
    CHECK(solver.solve(scene, result) == Status::invalid_argument);
    REQUIRE(solver.prepare(hand, GridBox::referenceDefault(), SolverOptions{}) == Status::ok);
    const auto other =
        makeCollider(cube, kind == Kind::convexHull ? Kind::triangleMesh : Kind::convexHull);
    scene.collider = other.get();
    CHECK(solver.solve(scene, result) == Status::invalid_argument);
    scene.collider = nullptr;
    CHECK(solver.solve(scene, result) == Status::invalid_argument);
    scene.collider = collider.get();
    scene.objectFromHand.position.x = std::numeric_limits<float>::quiet_NaN();
    CHECK(solver.solve(scene, result) == Status::invalid_argument);
  }
  SECTION("invalid options fail prepare") {
    SolverOptions options;
    options.refineStep = std::numeric_limits<float>::quiet_NaN();
    CHECK(solver.prepare(hand, GridBox::referenceDefault(), options) == Status::invalid_argument);
    CHECK(solver.prepareError().find("refineStep") != std::string_view::npos);
    options = SolverOptions{};
    options.da = 0.0f;
    CHECK(solver.prepare(hand, GridBox::referenceDefault(), options) == Status::invalid_argument);
    scene.collider = collider.get();
    CHECK(solver.solve(scene, result) == Status::invalid_argument);
  }
  SECTION("an object out of reach closes every finger fully") {
    REQUIRE(solver.prepare(hand, GridBox::referenceDefault(), SolverOptions{}) == Status::ok);
    scene.collider = collider.get();
    scene.objectFromHand.position = glm::vec3(5.0f, 0.0f, 0.0f);  // the cube is 5 m away
    REQUIRE(solver.solve(scene, result) == Status::ok);
    for (const FingerState& state : result.fingers) {
      CHECK(state.curl == 1.0f);
      CHECK_FALSE(state.contact);
    }
  }
  SECTION("an object at the open fingertips stops every finger at 0") {
    // A thin plate through every open fingertip; objectFromHand puts hand space into its frame.
    CurveBounds open;
    for (int f = 0; f < kFingerCount; ++f) {
      const glm::vec3 p = hand.tipPosition(Finger(f), 0.0f);
      open.lo = glm::min(open.lo, p);
      open.hi = glm::max(open.hi, p);
    }
    TriangleMesh plate;
    appendBox(plate, open.lo - glm::vec3(0.02f, 0.002f, 0.02f),
              open.hi + glm::vec3(0.02f, 0.002f, 0.02f));
    const auto plateCollider = makeCollider(plate, kind);
    // A rotated object frame: objectFromHand must be applied to the tips.
    Pose handFromObject;
    handFromObject.orientation = glm::angleAxis(0.7f, glm::normalize(glm::vec3(1, 2, 3)));
    handFromObject.position = glm::vec3(0.1f, -0.2f, 0.3f);
    TriangleMesh moved = plate;
    transformMesh(moved, handFromObject.inverse());
    const auto movedCollider = makeCollider(moved, kind);
    scene.objectFromHand = handFromObject.inverse();
    scene.collider = movedCollider.get();
    REQUIRE(solver.prepare(hand, GridBox::referenceDefault(), SolverOptions{}) == Status::ok);
    REQUIRE(solver.solve(scene, result) == Status::ok);
    for (int f = 0; f < kFingerCount; ++f) {
      CAPTURE(f);
      CHECK(result.fingers[f].curl == 0.0f);
      CHECK(result.fingers[f].contact);
    }
    (void)plateCollider;
  }
}

TEST_CASE("physics solve time per grasp is printed", "[solver][physics]") {
  const HandModel hand = HandModel::defaultAdult(Hand::right);
  const float top = hand.tipPosition(Finger::middle, 0.0f).y - 0.03f;
  TriangleMesh slab;
  appendBox(slab, glm::vec3(-0.4f, top - 0.05f, -0.5f), glm::vec3(0.4f, top, 0.3f));
  for (Kind kind : {Kind::convexHull, Kind::triangleMesh}) {
    const auto collider = makeCollider(slab, kind);
    PhysicsSolver solver(kind);
    REQUIRE(solver.prepare(hand, GridBox::referenceDefault(), SolverOptions{}) == Status::ok);
    GraspScene scene;
    scene.collider = collider.get();
    GraspResult result;
    constexpr int kGrasps = 500;
    float sink = 0.0f;
    const std::clock_t start = std::clock();  // CPU time: the CI machine is shared
    for (int i = 0; i < kGrasps; ++i) {
      REQUIRE(solver.solve(scene, result) == Status::ok);
      sink += result.fingers[i % kFingerCount].curl;
    }
    const double us = 1e6 * double(std::clock() - start) / CLOCKS_PER_SEC;
    std::cout << solver.name() << " on a 12-triangle slab: " << us / kGrasps
              << " us CPU per grasp (checksum " << sink << ")\n";
    CHECK(std::isfinite(sink));
  }
}
