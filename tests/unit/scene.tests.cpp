// The grasp scene's parts: analytic shapes, the broad phase (AABB tree and per-space index), the
// union field of several solids, the scene's exact source and the rule for what a hand takes.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "grasp/scene_exact_source.h"
#include "grasp/target_choice.h"
#include "io/shapes.h"
#include "mesh/mesh_distance.h"
#include "scene/aabb_tree.h"
#include "scene/analytic_shape.h"
#include "scene/scene_field.h"
#include "scene/scene_index.h"
#include "sdf/sdf_backend.h"

using namespace sdfg;

namespace {

std::unique_ptr<MeshDistance> sphereMesh(float radius) {
  auto d = MeshDistance::create(makeSphere(radius, 4));
  REQUIRE(d.ok());
  return std::move(d).value();
}

Pose at(const glm::vec3& p) {
  return Pose{glm::quat(1, 0, 0, 0), p};
}

Aabb randomBox(std::mt19937& rng, float world, float maxSize) {
  std::uniform_real_distribution<float> u(-world, world), s(0.001f, maxSize);
  const glm::vec3 lo(u(rng), u(rng), u(rng));
  return Aabb{lo, lo + glm::vec3(s(rng), s(rng), s(rng))};
}

}  // namespace

TEST_CASE("Analytic shapes give exact signed distances and closest points", "[core][scene]") {
  SECTION("Box: outside, inside, on edges and corners") {
    const AnalyticShape box{ShapeKind::box, glm::vec3(0.5f, 0.05f, 0.3f)};
    REQUIRE_FALSE(box.validate().has_value());
    glm::vec3 q;
    CHECK(box.closest(glm::vec3(0.0f, 0.15f, 0.0f), q) == Approx(0.1f));
    CHECK(q.y == Approx(0.05f));
    CHECK(box.signedDistance(glm::vec3(0.0f, 0.0f, 0.0f)) == Approx(-0.05f));
    CHECK(box.signedDistance(glm::vec3(0.6f, 0.15f, 0.0f)) == Approx(std::sqrt(0.02f)));
    CHECK(box.signedDistance(glm::vec3(0.45f, 0.0f, 0.0f)) == Approx(-0.05f));
    // Inside, the closest point is on the nearest face and the distance is minus the way to it.
    CHECK(box.closest(glm::vec3(0.48f, 0.0f, 0.1f), q) == Approx(-0.02f));
    CHECK(q.x == Approx(0.5f));
    CHECK(box.bounds().max.z == Approx(0.3f));
  }
  SECTION("Plane: the frame's y = 0, solid below") {
    const AnalyticShape plane{ShapeKind::plane, glm::vec3(0.0f)};
    REQUIRE_FALSE(plane.validate().has_value());
    glm::vec3 q;
    CHECK(plane.closest(glm::vec3(3.0f, 0.2f, -1.0f), q) == Approx(0.2f));
    CHECK(q == glm::vec3(3.0f, 0.0f, -1.0f));
    CHECK(plane.signedDistance(glm::vec3(0.0f, -0.4f, 0.0f)) == Approx(-0.4f));
    CHECK_FALSE(plane.bounded());
  }
  SECTION("Sizes that are not finite, not positive or too large are refused") {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (const glm::vec3& half :
         {glm::vec3(nan, 1, 1), glm::vec3(1, -1, 1), glm::vec3(0, 1, 1),
          glm::vec3(1, 1, std::numeric_limits<float>::infinity()), glm::vec3(1, 1, 2000.0f)}) {
      CHECK(AnalyticShape{ShapeKind::box, half}.validate().has_value());
    }
    CHECK(AnalyticShape{ShapeKind::plane, glm::vec3(1.0f, 0, 0)}.validate().has_value());
    CHECK(AnalyticShape{ShapeKind(7), glm::vec3(1.0f)}.validate().has_value());
  }
}

TEST_CASE("The AABB tree finds exactly the boxes a query overlaps", "[core][scene]") {
  std::mt19937 rng(7);
  AabbTree tree(0.0f);  // no margin: its answers must equal the brute force exactly
  std::vector<Aabb> boxes;
  std::vector<AabbTree::Proxy> proxies;
  for (uint64_t i = 0; i < 1000; ++i) {
    boxes.push_back(randomBox(rng, 5.0f, 0.5f));
    proxies.push_back(tree.insert(boxes.back(), i));
  }
  CHECK(tree.size() == 1000);
  // A tree that is a list would be 1000 high; a balanced one about 10.
  CHECK(tree.height() <= 40);
  auto check = [&] {
    for (int q = 0; q < 200; ++q) {
      const Aabb query = randomBox(rng, 5.0f, 1.0f);
      std::set<uint64_t> expected, found;
      for (size_t i = 0; i < boxes.size(); ++i) {
        if (proxies[i] != AabbTree::kNone && overlaps(boxes[i], query)) expected.insert(i);
      }
      tree.query(query, [&](uint64_t item) { found.insert(item); });
      REQUIRE(found == expected);
    }
  };
  check();
  SECTION("after moves and removals") {
    for (size_t i = 0; i < boxes.size(); i += 3) {
      boxes[i] = randomBox(rng, 5.0f, 0.5f);
      tree.update(proxies[i], boxes[i]);
    }
    for (size_t i = 1; i < boxes.size(); i += 7) {
      tree.remove(proxies[i]);
      proxies[i] = AabbTree::kNone;
    }
    check();
  }
  SECTION("a leaf that moves within its margin stays where it is") {
    AabbTree fat(0.02f);
    const AabbTree::Proxy p = fat.insert(Aabb{glm::vec3(0.0f), glm::vec3(0.1f)}, 1);
    CHECK_FALSE(fat.update(p, Aabb{glm::vec3(0.01f), glm::vec3(0.11f)}));
    CHECK(fat.update(p, Aabb{glm::vec3(0.05f), glm::vec3(0.15f)}));
  }
}

TEST_CASE("The scene index finds the targets near a box through their spaces", "[core][scene]") {
  SceneIndex index;
  // A thousand small targets on a 10 x 10 x 10 lattice 0.5 m apart, in space 1.
  for (uint64_t i = 0; i < 1000; ++i) {
    const glm::vec3 p(float(i % 10), float((i / 10) % 10), float(i / 100));
    index.place(i + 1, 1, at(p * 0.5f), Aabb{glm::vec3(-0.05f), glm::vec3(0.05f)});
  }
  // A table (space 2) and a floor plane (space 2).
  index.place(5000, 2, at(glm::vec3(0.0f)), Aabb{glm::vec3(-1, -0.02f, -1), glm::vec3(1, 0, 1)});
  index.place(5001, 2, at(glm::vec3(0.0f, -0.8f, 0.0f)), std::nullopt);
  const std::vector<SpaceFrame> spaces{{1, true, at(glm::vec3(0.0f))},
                                       {2, true, at(glm::vec3(10.0f, 0.0f, 0.0f))}};
  index.setSpaces(spaces);
  std::vector<SceneHit> hits;
  SECTION("a box around one lattice point finds that target only") {
    index.query(at(glm::vec3(1.0f, 1.5f, 2.0f)), glm::vec3(0.1f), hits);
    REQUIRE(hits.size() == 1);
    const uint64_t expected = 1 + 2 + 3 * 10 + 4 * 100;
    CHECK(hits[0].target == expected);
    CHECK(glm::length(hits[0].worldFromObject.position - glm::vec3(1.0f, 1.5f, 2.0f)) < 1e-5f);
  }
  SECTION("a space that moved takes its targets along; an unlocated one has none") {
    index.query(at(glm::vec3(10.0f, 0.05f, 0.5f)), glm::vec3(0.1f), hits);
    REQUIRE(hits.size() == 1);
    CHECK(hits[0].target == 5000);
    hits.clear();
    index.query(at(glm::vec3(10.0f, -0.85f, 3.0f)), glm::vec3(0.1f), hits);
    REQUIRE(hits.size() == 1);
    CHECK(hits[0].target == 5001);  // the floor, 0.8 m below the table's space origin
    hits.clear();
    const std::vector<SpaceFrame> only1{{1, true, at(glm::vec3(0.0f))}};
    index.setSpaces(only1);
    index.query(at(glm::vec3(10.0f, 0.05f, 0.5f)), glm::vec3(0.1f), hits);
    CHECK(hits.empty());
    CHECK_FALSE(index.worldFromObject(5000).has_value());
  }
  SECTION("removed and re-placed targets") {
    index.remove(1);
    index.query(at(glm::vec3(0.0f)), glm::vec3(0.1f), hits);
    CHECK(hits.empty());
    index.place(2, 1, at(glm::vec3(0.0f)), Aabb{glm::vec3(-0.05f), glm::vec3(0.05f)});
    index.query(at(glm::vec3(0.0f)), glm::vec3(0.1f), hits);
    REQUIRE(hits.size() == 1);
    CHECK(hits[0].target == 2);
    CHECK(index.size() == 1001);
  }
}

TEST_CASE("A scene's field is the union of its members' fields", "[core][scene]") {
  GridBox box = GridBox::referenceDefault();
  box.handFromBox = Pose{};
  auto sphere = sphereMesh(0.04f);
  const AnalyticShape table{ShapeKind::box, glm::vec3(0.2f, 0.02f, 0.2f)};
  std::vector<SceneMember> members(3);
  members[0] = SceneMember{1, sphere.get(), nullptr, at(glm::vec3(0.05f, 0.0f, 0.0f)), true};
  members[1] = SceneMember{2, sphere.get(), nullptr, at(glm::vec3(-0.05f, 0.0f, 0.0f)), true};
  members[2] = SceneMember{3, nullptr, &table, at(glm::vec3(0.0f, 0.06f, 0.0f)), false};
  auto backend = makeCpuSdfBackend(1);
  SdfGrid out(box), scratch(box);
  REQUIRE(buildSceneField(members, box, *backend, out, scratch) == Status::ok);
  // Every node: the least of the members' own distances.
  double worst = 0.0;
  for (uint32_t k = 0; k < box.resolution.z; ++k)
    for (uint32_t j = 0; j < box.resolution.y; ++j)
      for (uint32_t i = 0; i < box.resolution.x; ++i) {
        const glm::vec3 p = box.nodeLocal(i, j, k);
        float expected = std::numeric_limits<float>::infinity();
        for (const SceneMember& m : members) {
          const glm::vec3 q = m.objectFromHand.transformPoint(p);
          expected =
              std::min(expected, m.mesh ? m.mesh->signedDistance(q) : m.shape->signedDistance(q));
        }
        worst = std::max(worst, double(std::abs(out.at(i, j, k) - expected)));
      }
  CHECK(worst < 1e-5);
  CHECK(buildSceneField({}, box, *backend, out, scratch) == Status::invalid_argument);
  SECTION("a scene of shapes alone") {
    REQUIRE(buildSceneField(std::span(members).subspan(2), box, *backend, out, scratch) ==
            Status::ok);
    CHECK(out.at(0, 0, 0) == Approx(table.signedDistance(members[2].objectFromHand.transformPoint(
                                 box.nodeLocal(0, 0, 0)))));
  }
}

TEST_CASE("The scene's exact source answers the nearest surface and its owner", "[core][scene]") {
  auto sphere = sphereMesh(0.03f);
  const AnalyticShape plane{ShapeKind::plane, glm::vec3(0.0f)};
  std::vector<SceneMember> members(2);
  // The sphere's centre at hand (0, 0.08, 0); the plane is the hand frame's y = 0.
  members[0] = SceneMember{10, sphere.get(), nullptr, at(glm::vec3(0.0f, -0.08f, 0.0f)), true};
  members[1] = SceneMember{20, nullptr, &plane, Pose{}, false};
  const SceneExactSource source(members);
  std::array<glm::vec3, 2> points{glm::vec3(0.0f, 0.02f, 0.0f), glm::vec3(0.0f, 0.07f, 0.0f)};
  std::array<float, 2> bounds{0.1f, 0.1f};
  std::array<ExactSample, 2> out{};
  source.sample(points, bounds, out);
  // 2 cm above the plane and 3 cm from the sphere: the plane's.
  CHECK(out[0].member == 1);
  CHECK(out[0].distance == Approx(0.02f).margin(1e-5f));
  CHECK(glm::length(out[0].closest - glm::vec3(0.0f)) < 1e-5f);
  // 2 cm inside the sphere: its, negative (the union's least signed distance).
  CHECK(out[1].member == 0);
  CHECK(out[1].distance == Approx(-0.02f).margin(2e-4f));
  // A sample fed back its own feature as a hint gives the same answer.
  const ExactSample first = out[1];
  out[1].feature = first.feature;
  source.sample(points, bounds, out);
  CHECK(out[1].distance == first.distance);
  CHECK(out[1].member == first.member);
  CHECK(SceneExactSource::memberOf(first.feature) == first.member);
}

TEST_CASE("A grasp takes the graspable target most fingers touch, then the palm's nearest",
          "[core][scene]") {
  // The palm faces the table (not graspable) unless a section says otherwise.
  const glm::vec3 kDown(0.0f, -1.0f, 0.0f);
  // Two blocks side by side in the hand frame, a at x = -0.03 (member 0) and b at x = +0.03
  // (member 1), and a table under both.
  const AnalyticShape block{ShapeKind::box, glm::vec3(0.02f)};
  const AnalyticShape table{ShapeKind::box, glm::vec3(0.5f, 0.01f, 0.5f)};
  std::vector<SceneMember> members(3);
  members[0] = SceneMember{7, nullptr, &block, at(glm::vec3(0.03f, 0.0f, 0.0f)), true};   // a
  members[1] = SceneMember{3, nullptr, &block, at(glm::vec3(-0.03f, 0.0f, 0.0f)), true};  // b
  // The table's top at hand y = -0.19, well below the blocks.
  members[2] = SceneMember{9, nullptr, &table, at(glm::vec3(0.0f, 0.2f, 0.0f)), false};
  const SceneExactSource source(members);
  GraspResult r;
  // Finger contact points, hand frame: the member's face plus a sphere radius of 8 mm.
  auto touch = [&](int finger, const glm::vec3& point) {
    r.fingers[size_t(finger)].contact = true;
    r.fingers[size_t(finger)].contactPoint = point;
  };
  const float rad = 0.008f;
  SECTION("three fingers on a, two on b: a") {
    touch(0, glm::vec3(-0.03f, -0.02f - rad, 0.0f));  // under a
    touch(1, glm::vec3(-0.02f, -0.02f - rad, 0.0f));
    touch(2, glm::vec3(-0.04f, -0.02f - rad, 0.0f));
    touch(3, glm::vec3(0.03f, -0.02f - rad, 0.0f));  // under b
    touch(4, glm::vec3(0.02f, -0.02f - rad, 0.0f));
    const GraspChoice c =
        chooseTarget(members, source, r, glm::vec3(0.0f, -0.1f, 0.0f), 0.01f, kDown, 0.01f);
    CHECK(c.member == 0);
    CHECK(c.fingersOnChoice == 3);
    CHECK(c.touched[3] == 1);
  }
  SECTION("a tie goes to the target nearer the palm") {
    touch(1, glm::vec3(-0.03f, -0.02f - rad, 0.0f));  // a
    touch(2, glm::vec3(0.03f, -0.02f - rad, 0.0f));   // b
    CHECK(chooseTarget(members, source, r, glm::vec3(0.02f, -0.05f, 0.0f), 0.01f, kDown, 0.01f)
              .member == 1);
    CHECK(chooseTarget(members, source, r, glm::vec3(-0.02f, -0.05f, 0.0f), 0.01f, kDown, 0.01f)
              .member == 0);
  }
  SECTION("a target under the palm that no finger touches is taken; one farther is not") {
    touch(1, glm::vec3(0.2f, -0.19f + rad, 0.0f));  // fingers on the table, past block a
    touch(2, glm::vec3(0.21f, -0.19f + rad, 0.0f));
    // The palm's surface (radius 1 cm) 5 mm from block a's bottom face (y = -0.02).
    CHECK(chooseTarget(members, source, r, glm::vec3(-0.03f, -0.035f, 0.0f), 0.01f, kDown, 0.01f)
              .member == 0);
    // 3 cm from it: beyond the palm's touch.
    CHECK(chooseTarget(members, source, r, glm::vec3(-0.03f, -0.06f, 0.0f), 0.01f, kDown, 0.01f)
              .member == -1);
  }
  SECTION("the target the palm faces is taken when the hand touches it, whatever the count") {
    touch(0, glm::vec3(0.03f, -0.02f - rad, 0.0f));  // three under b
    touch(1, glm::vec3(0.02f, -0.02f - rad, 0.0f));
    touch(2, glm::vec3(0.04f, -0.02f - rad, 0.0f));
    touch(3, glm::vec3(-0.03f, -0.02f - rad, 0.0f));  // one under a
    const glm::vec3 up(0.0f, 1.0f, 0.0f);
    // The palm under a, facing up at it.
    GraspChoice c =
        chooseTarget(members, source, r, glm::vec3(-0.03f, -0.06f, 0.0f), 0.01f, up, 0.01f);
    CHECK(c.faced == 0);
    CHECK(c.member == 0);
    CHECK(c.fingersOnChoice == 1);
    // Facing a with no finger on it and the palm 4 cm off: not touched, so the count decides.
    r.fingers[3].contact = false;
    c = chooseTarget(members, source, r, glm::vec3(-0.03f, -0.07f, 0.0f), 0.01f, up, 0.01f);
    CHECK(c.faced == 0);
    CHECK(c.member == 1);
  }
  SECTION("fingers on the table alone hold nothing; a non-graspable target is never taken") {
    touch(1, glm::vec3(0.2f, -0.19f + rad, 0.0f));  // resting on the table's top
    const GraspChoice c =
        chooseTarget(members, source, r, glm::vec3(0.2f, -0.1f, 0.0f), 0.01f, kDown, 0.01f);
    CHECK(c.member == -1);
    members[0].graspable = false;
    r = GraspResult{};
    touch(1, glm::vec3(-0.03f, -0.02f - rad, 0.0f));
    CHECK(chooseTarget(members, source, r, glm::vec3(0.2f, -0.1f, 0.0f), 0.01f, kDown, 0.01f)
              .member == -1);
  }
}
