// The benchmark's scenes (eval/scenes.h) are built as documented, the physics collider of several
// objects keeps each object's own hull, and a scene's figures (eval/scene_quality.h) are a
// function of the seed.
#include <catch2/catch.hpp>

#include <algorithm>
#include <limits>
#include <optional>
#include <string>

#include "eval/evaluator.h"
#include "eval/scene_quality.h"
#include "eval/scenes.h"
#include "eval/solver_physics.h"
#include "io/shapes.h"

using namespace sdfg;

namespace {

TriangleMesh worldMesh(const SceneObject& o) {
  TriangleMesh m = o.mesh;
  transformMesh(m, o.worldFromObject);
  return m;
}

const BenchScene& sceneNamed(const std::vector<BenchScene>& scenes, const std::string& name) {
  const auto it = std::find_if(scenes.begin(), scenes.end(),
                               [&](const BenchScene& s) { return s.name == name; });
  REQUIRE(it != scenes.end());
  return *it;
}

const SceneObject& objectNamed(const BenchScene& scene, const std::string& name) {
  const auto it = std::find_if(scene.objects.begin(), scene.objects.end(),
                               [&](const SceneObject& o) { return o.name == name; });
  REQUIRE(it != scene.objects.end());
  return *it;
}

// The smallest signed distance of a's vertices to b's surface (negative: a vertex inside b).
double closestVertex(const TriangleMesh& a, const TriangleMesh& b) {
  auto query = ExactMeshQuery::create(b);
  REQUIRE(query.ok());
  double out = std::numeric_limits<double>::infinity();
  for (const glm::vec3& p : a.positions) out = std::min(out, (*query)->signedDistance(p));
  return out;
}

}  // namespace

TEST_CASE("The scenes place their objects as documented", "[core][scenes]") {
  const std::vector<BenchScene> scenes = embeddedScenes();
  REQUIRE(scenes.size() == 8);
  for (const BenchScene& s : scenes) {
    CAPTURE(s.name);
    REQUIRE(s.reachedFor < s.objects.size());
    CHECK(s.objects[s.reachedFor].graspable);
    const SceneObject& table = objectNamed(s, "table");
    CHECK_FALSE(table.graspable);
    REQUIRE(table.shape.has_value());
    // Every object stands on the table top (y = 0) or above it, none in it.
    for (const SceneObject& o : s.objects) {
      if (&o == &table) continue;
      const Aabb b = computeBounds(worldMesh(o).positions);
      CHECK(b.min.y >= -1e-5f);
    }
  }
  SECTION("an object on the table rests on it") {
    const Aabb b = computeBounds(worldMesh(sceneNamed(scenes, "torus/table").objects[0]).positions);
    CHECK(b.min.y == Approx(0.0f).margin(1e-5));
  }
  SECTION("the two mugs are 5 mm apart (1 cm in mug-near-mug)") {
    const BenchScene& s = sceneNamed(scenes, "mug-beside-mug");
    const double gap =
        closestVertex(worldMesh(objectNamed(s, "mug-2")), worldMesh(objectNamed(s, "mug")));
    CHECK(gap == Approx(0.005).margin(5e-4));
    const BenchScene& near = sceneNamed(scenes, "mug-near-mug");
    CHECK(closestVertex(worldMesh(objectNamed(near, "mug-2")),
                        worldMesh(objectNamed(near, "mug"))) == Approx(0.01).margin(5e-4));
  }
  SECTION("the ruler lies flat on the table") {
    const BenchScene& s = sceneNamed(scenes, "ruler-on-table");
    const Aabb b = computeBounds(worldMesh(objectNamed(s, "ruler")).positions);
    CHECK(b.min.y == Approx(0.0f).margin(1e-5));
    CHECK(b.max.y == Approx(0.003f).margin(1e-5));
  }
  SECTION("the spoon stands in the mug touching neither wall nor floor") {
    const BenchScene& s = sceneNamed(scenes, "spoon-in-mug");
    CHECK(s.objects[s.reachedFor].name == "spoon");
    const double gap =
        closestVertex(worldMesh(objectNamed(s, "spoon")), worldMesh(objectNamed(s, "mug")));
    CHECK(gap > 0.002);
    CHECK(gap < 0.02);
    // Its handle's end is out over the rim (9.5 cm).
    CHECK(computeBounds(worldMesh(objectNamed(s, "spoon")).positions).max.y > 0.1f);
  }
  SECTION("the handle ends 1.5 cm from the wall") {
    const BenchScene& s = sceneNamed(scenes, "mug-handle-wall");
    CHECK_FALSE(objectNamed(s, "wall").graspable);
    const double gap =
        closestVertex(worldMesh(objectNamed(s, "mug")), worldMesh(objectNamed(s, "wall")));
    CHECK(gap == Approx(0.015).margin(5e-4));
  }
}

TEST_CASE("A collider of several objects is each object's own hull", "[core][scenes]") {
  TriangleMesh left = makeBox(glm::vec3(0.02f)), right = left;
  transformMesh(left, Pose{glm::quat(1, 0, 0, 0), glm::vec3(-0.05f, 0, 0)});
  transformMesh(right, Pose{glm::quat(1, 0, 0, 0), glm::vec3(0.05f, 0, 0)});
  const std::vector<TriangleMesh> parts{left, right};
  for (const auto kind : {PhysicsCollider::Kind::convexHull, PhysicsCollider::Kind::triangleMesh}) {
    auto collider = PhysicsCollider::create(parts, kind);
    REQUIRE(collider.ok());
    CHECK((*collider)->sphereOverlaps(glm::vec3(-0.04f, 0, 0), 0.001f));
    CHECK((*collider)->sphereOverlaps(glm::vec3(0.06f, 0, 0), 0.015f));
    // Between the boxes: inside the hull of both together, outside each.
    CHECK_FALSE((*collider)->sphereOverlaps(glm::vec3(0.0f, 0, 0), 0.005f));
  }
  CHECK_FALSE(
      PhysicsCollider::create(std::vector<TriangleMesh>{}, PhysicsCollider::Kind::convexHull).ok());
}

TEST_CASE("A scene's figures are a function of the seed", "[core][scenes]") {
  const BenchScene scene = sceneNamed(embeddedScenes(), "mug-handle-wall");
  SceneRun run;
  run.placements = 4;
  run.seed = 3;
  for (const std::string method : {"ours", "physics-mesh"}) {
    CAPTURE(method);
    run.method = method;
    run.threads = 1;
    const Result<SceneFigures> a = measureScene(scene, run);
    run.threads = 2;
    const Result<SceneFigures> b = measureScene(scene, run);
    REQUIRE(a.ok());
    REQUIRE(b.ok());
    CHECK(a->grasps == 4);
    CHECK(a->otherPenetrationMaxMm == b->otherPenetrationMaxMm);
    CHECK(a->held.contactsPerGrasp == b->held.contactsPerGrasp);
    CHECK(a->wrongObject == b->wrongObject);
    CHECK(a->facingGraspable == b->facingGraspable);
    CHECK(a->held.contactResidualP95Mm == b->held.contactResidualP95Mm);
  }
  run.method = "no-such-method";
  CHECK_FALSE(measureScene(scene, run).ok());
}
