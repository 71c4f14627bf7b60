#include "eval/scenes.h"

#include <cmath>
#include <numbers>

#include <glm/gtc/quaternion.hpp>

#include "eval/quality.h"
#include "io/shapes.h"

namespace sdfg {

namespace {

constexpr glm::vec3 kTableHalf{0.25f, 0.02f, 0.25f};
// The mug of shapes.h: centred on its origin, 9.5 cm tall, handle on +X reaching x = 7.35 cm.
constexpr float kMugHalfHeight = 0.0475f;
constexpr float kMugRadius = 0.04f;
constexpr float kMugHandleReach = 0.0735f;
constexpr float kMugGap = 0.005f;                  // between the two mugs
constexpr float kMugNearGap = 0.01f;               // between the two mugs of "mug-near-mug"
constexpr glm::vec3 kRuler{0.15f, 0.003f, 0.03f};  // a ruler's length, thickness, width
constexpr float kWallGap = 0.015f;                 // from the handle's end to the wall
constexpr float kWallHalfThickness = 0.01f;

SceneObject boxObject(const std::string& name, const glm::vec3& half, const glm::vec3& centre) {
  SceneObject o;
  o.name = name;
  o.mesh = makeBox(2.0f * half);
  o.shape = AnalyticShape{ShapeKind::box, half};
  o.worldFromObject.position = centre;
  o.graspable = false;
  return o;
}

SceneObject mugAt(const std::string& name, const glm::vec3& floorCentre, float turnY) {
  SceneObject o;
  o.name = name;
  o.mesh = makeMug();
  o.worldFromObject = Pose{glm::angleAxis(turnY, glm::vec3(0, 1, 0)),
                           floorCentre + glm::vec3(0.0f, kMugHalfHeight, 0.0f)};
  return o;
}

// A scene of `mesh` scaled to the benchmark's size, named "<name>/<suffix>".
BenchScene scaledScene(const std::string& name, const TriangleMesh& mesh, const char* suffix,
                       const char* where) {
  BenchScene scene;
  scene.name = name + "/" + suffix;
  scene.description = name + " (scaled to the benchmark's size) " + where;
  SceneObject object;
  object.name = name;
  object.mesh = normalizedToDiagonal(mesh, kBenchObjectDiagonal);
  scene.objects.push_back(std::move(object));
  return scene;
}

}  // namespace

SceneObject makeTable() {
  return boxObject("table", kTableHalf, glm::vec3(0.0f, -kTableHalf.y, 0.0f));
}

BenchScene aloneScene(const std::string& name, const TriangleMesh& mesh) {
  return scaledScene(name, mesh, "alone", "alone");
}

BenchScene tableScene(const std::string& name, const TriangleMesh& mesh) {
  BenchScene scene = scaledScene(name, mesh, "table", "resting on a table top");
  SceneObject& object = scene.objects[0];
  const Aabb bounds = computeBounds(object.mesh.positions);
  object.worldFromObject.position = glm::vec3(0.0f, -bounds.min.y, 0.0f);
  scene.objects.push_back(makeTable());
  scene.reachedFor = 0;
  return scene;
}

// Two mugs `gap` apart on the table, the second turned half a turn (its body ends at
// x = centre + radius, its handle away), the hand reaching for the first.
BenchScene mugBesideMug(const std::string& name, float gap, const std::string& description) {
  BenchScene s;
  s.name = name;
  s.description = description;
  s.objects.push_back(mugAt("mug", glm::vec3(0.0f), 0.0f));
  const float centre = -kMugRadius - gap - kMugRadius;
  s.objects.push_back(mugAt("mug-2", glm::vec3(centre, 0.0f, 0.0f), std::numbers::pi_v<float>));
  s.objects.push_back(makeTable());
  return s;
}

std::vector<BenchScene> objectScenes() {
  std::vector<BenchScene> scenes;
  scenes.push_back(mugBesideMug(
      "mug-beside-mug", kMugGap,
      "two mugs 5 mm apart on a table, both graspable (the second turned, handle away); the "
      "hand reaches for the first"));
  scenes.push_back(mugBesideMug("mug-near-mug", kMugNearGap,
                                "two mugs 1 cm apart on a table, as mug-beside-mug"));
  {
    // Thin and narrower than a hand: fingers that close past its edges land on the table.
    BenchScene s;
    s.name = "ruler-on-table";
    s.description = "a ruler (15 x 3 cm, 3 mm thick) lying flat on a table";
    SceneObject ruler;
    ruler.name = "ruler";
    ruler.mesh = makeBox(kRuler);
    ruler.worldFromObject.position = glm::vec3(0.0f, 0.5f * kRuler.y, 0.0f);
    s.objects.push_back(std::move(ruler));
    s.objects.push_back(makeTable());
    scenes.push_back(std::move(s));
  }
  {
    BenchScene s;
    s.name = "spoon-in-mug";
    s.description =
        "a 15 cm spoon standing slanted in a mug (bowl near the floor, handle out over the rim), "
        "both graspable; the hand reaches for the spoon";
    s.objects.push_back(mugAt("mug", glm::vec3(0.0f), 0.0f));
    SceneObject spoon;
    spoon.name = "spoon";
    spoon.mesh = makeSpoon(0.15f);
    // The bowl's tip 1.25 cm above the mug's inner floor, the handle leaning 21 degrees off the
    // axis towards +X: it clears the wall by more than a centimetre all the way up to the rim.
    const glm::vec3 direction = glm::normalize(glm::vec3(0.05f, 0.13f, 0.0f));
    spoon.worldFromObject =
        Pose{glm::angleAxis(std::atan2(direction.y, direction.x), glm::vec3(0, 0, 1)),
             glm::vec3(-0.02f, kMugHalfHeight - 0.035f, 0.0f)};
    s.objects.push_back(std::move(spoon));
    s.objects.push_back(makeTable());
    s.reachedFor = 1;
    scenes.push_back(std::move(s));
  }
  {
    BenchScene s;
    s.name = "mug-handle-wall";
    s.description = "a mug on a table whose handle ends 1.5 cm from a wall (2 cm thick)";
    s.objects.push_back(mugAt("mug", glm::vec3(0.0f), 0.0f));
    s.objects.push_back(
        boxObject("wall", glm::vec3(kWallHalfThickness, 0.15f, kTableHalf.z),
                  glm::vec3(kMugHandleReach + kWallGap + kWallHalfThickness, 0.15f, 0.0f)));
    s.objects.push_back(makeTable());
    scenes.push_back(std::move(s));
  }
  return scenes;
}

std::vector<BenchScene> embeddedScenes() {
  std::vector<BenchScene> scenes;
  for (const NamedMesh& m : embeddedObjects()) scenes.push_back(tableScene(m.name, m.mesh));
  for (BenchScene& s : objectScenes()) scenes.push_back(std::move(s));
  return scenes;
}

}  // namespace sdfg
