#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>

#include "io/shapes.h"

namespace {

constexpr double kPi = std::numbers::pi;

struct Topology {
  size_t edges = 0;
  bool closed = false;  // every edge used by exactly two triangles, once in each direction
  size_t components = 0;
};

Topology topologyOf(const sdfg::TriangleMesh& mesh) {
  std::vector<std::pair<uint32_t, uint32_t>> directed;
  for (size_t t = 0; t < mesh.triangleCount(); ++t) {
    for (int k = 0; k < 3; ++k) {
      directed.emplace_back(mesh.indices[3 * t + k], mesh.indices[3 * t + (k + 1) % 3]);
    }
  }
  std::sort(directed.begin(), directed.end());
  Topology topology;
  // Closed and consistently wound: no directed edge twice, and each one's reverse present.
  topology.closed = std::adjacent_find(directed.begin(), directed.end()) == directed.end();
  for (const auto& [a, b] : directed) {
    topology.closed &= std::binary_search(directed.begin(), directed.end(), std::make_pair(b, a));
  }
  topology.edges = topology.closed ? directed.size() / 2 : 0;

  std::vector<uint32_t> parent(mesh.vertexCount());
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&parent](uint32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (const auto& [a, b] : directed) parent[find(a)] = find(b);
  for (uint32_t v = 0; v < parent.size(); ++v) topology.components += find(v) == v;
  return topology;
}

double signedVolume(const sdfg::TriangleMesh& mesh) {
  double volume = 0.0;
  for (size_t t = 0; t < mesh.triangleCount(); ++t) {
    const glm::dvec3 a(mesh.positions[mesh.indices[3 * t]]);
    const glm::dvec3 b(mesh.positions[mesh.indices[3 * t + 1]]);
    const glm::dvec3 c(mesh.positions[mesh.indices[3 * t + 2]]);
    volume += glm::dot(a, glm::cross(b, c)) / 6.0;
  }
  return volume;
}

// Triangles crossed by the segment from `from` to `to` (Moller-Trumbore, double precision).
int crossings(const sdfg::TriangleMesh& mesh, const glm::dvec3& from, const glm::dvec3& to) {
  const glm::dvec3 dir = to - from;
  int count = 0;
  for (size_t t = 0; t < mesh.triangleCount(); ++t) {
    const glm::dvec3 a(mesh.positions[mesh.indices[3 * t]]);
    const glm::dvec3 e1 = glm::dvec3(mesh.positions[mesh.indices[3 * t + 1]]) - a;
    const glm::dvec3 e2 = glm::dvec3(mesh.positions[mesh.indices[3 * t + 2]]) - a;
    const glm::dvec3 p = glm::cross(dir, e2);
    const double det = glm::dot(e1, p);
    if (std::abs(det) < 1e-300) continue;
    const glm::dvec3 s = from - a;
    const double u = glm::dot(s, p) / det;
    const glm::dvec3 q = glm::cross(s, e1);
    const double v = glm::dot(dir, q) / det;
    const double along = glm::dot(e2, q) / det;
    count += u >= 0.0 && v >= 0.0 && u + v <= 1.0 && along >= 0.0 && along <= 1.0;
  }
  return count;
}

// Inside a closed mesh when a ray from the point crosses it an odd number of times. The ray's
// direction is skewed so it meets no edge or vertex of these shapes exactly.
bool inside(const sdfg::TriangleMesh& mesh, const glm::dvec3& point) {
  const glm::dvec3 far = point + 10.0 * glm::normalize(glm::dvec3(0.5773, 0.6213, 0.5306));
  return crossings(mesh, point, far) % 2 == 1;
}

void checkClosedSolid(const sdfg::TriangleMesh& mesh) {
  const auto error = sdfg::validateMesh(mesh.positions, mesh.indices);
  CHECK_FALSE(error.has_value());
  if (error) FAIL(error->message);
  const Topology topology = topologyOf(mesh);
  CHECK(topology.closed);
  CHECK(topology.components == 1);
  CHECK(signedVolume(mesh) > 0.0);
}

long eulerCharacteristic(const sdfg::TriangleMesh& mesh) {
  return long(mesh.vertexCount()) - long(topologyOf(mesh).edges) + long(mesh.triangleCount());
}

}  // namespace

TEST_CASE("Every procedural shape is one closed, outward-wound, valid mesh", "[core][shapes]") {
  SECTION("Box") {
    checkClosedSolid(sdfg::makeBox(glm::vec3(0.1f, 0.02f, 0.05f)));
  }
  SECTION("Thin plate") {
    checkClosedSolid(sdfg::makeThinPlate());
  }
  SECTION("Sphere at every subdivision level") {
    for (int level = 0; level <= 4; ++level) {
      CAPTURE(level);
      checkClosedSolid(sdfg::makeSphere(0.03f, level));
    }
  }
  SECTION("Torus, default and coarse") {
    checkClosedSolid(sdfg::makeTorus());
    checkClosedSolid(sdfg::makeTorus(0.04f, 0.01f, 3, 3));
  }
  SECTION("Mug") {
    checkClosedSolid(sdfg::makeMug());
  }
  SECTION("Spoon") {
    checkClosedSolid(sdfg::makeSpoon());
  }
}

TEST_CASE("Shapes have the topology of what they model", "[core][shapes]") {
  // V - E + F = 2 - 2 * genus for a closed orientable surface.
  CHECK(eulerCharacteristic(sdfg::makeBox(glm::vec3(1.0f))) == 2);
  CHECK(eulerCharacteristic(sdfg::makeSphere(1.0f, 2)) == 2);
  CHECK(eulerCharacteristic(sdfg::makeTorus()) == 0);
  CHECK(eulerCharacteristic(sdfg::makeMug()) == 0);
  CHECK(eulerCharacteristic(sdfg::makeSpoon()) == 2);
}

TEST_CASE("Shape volumes match the analytic solids", "[core][shapes]") {
  SECTION("Box: exact") {
    const glm::vec3 extent(0.1f, 0.02f, 0.05f);
    CHECK(signedVolume(sdfg::makeBox(extent)) ==
          Approx(double(extent.x) * extent.y * extent.z).epsilon(1e-6));
  }
  SECTION("Sphere: inscribed, so a little below, closer with each level") {
    const double r = 0.03, exact = 4.0 / 3.0 * kPi * r * r * r;
    double previous = 0.0;
    for (int level = 0; level <= 4; ++level) {
      const double volume = signedVolume(sdfg::makeSphere(float(r), level));
      CAPTURE(level, volume, exact);
      CHECK(volume < exact);
      CHECK(volume > previous);
      previous = volume;
    }
    // 1,280 triangles: the faces sit within cos(~4.6 degrees) of the radius.
    CHECK(signedVolume(sdfg::makeSphere(float(r), 3)) == Approx(exact).epsilon(0.015));
  }
  SECTION("Torus: 2 pi^2 R r^2 within the loss of a 48 x 24 tessellation") {
    const double R = 0.05, r = 0.015, exact = 2.0 * kPi * kPi * R * r * r;
    const double volume = signedVolume(sdfg::makeTorus(float(R), float(r), 48, 24));
    CHECK(volume < exact);
    // Each n-gon keeps n / (2 pi) * sin(2 pi / n) of its circle's area: the tube's 24-gon
    // section, and (nearly) the 48-gon path it is swept along.
    auto kept = [](double n) { return n / (2.0 * kPi) * std::sin(2.0 * kPi / n); };
    CHECK(volume == Approx(exact * kept(24) * kept(48)).epsilon(1e-3));
  }
  SECTION("Mug: the cup's walls and floor, plus a handle tube") {
    const double ro = 0.04, ri = 0.035, height = 0.095, floor = 0.006;
    const double ring = 40.0 / (2.0 * kPi) * std::sin(2.0 * kPi / 40.0);  // 40-gon / circle
    const double cup = ring * kPi * (ro * ro * height - ri * ri * (height - floor));
    // Octagon section (9 x 11 mm) along half an ellipse of semi-axes 25 mm.
    const double tube = 2.0 * std::sqrt(2.0) * 0.0045 * 0.0055 * kPi * 0.025;
    const double volume = signedVolume(sdfg::makeMug());
    CAPTURE(volume, cup, tube);
    CHECK(volume > cup);
    CHECK(volume == Approx(cup + tube).epsilon(0.02));
  }
}

TEST_CASE("The mug has its documented size and a handle with a through-hole", "[core][shapes]") {
  const sdfg::TriangleMesh mug = sdfg::makeMug();
  REQUIRE(topologyOf(mug).closed);

  SECTION("Bounding box") {
    const sdfg::Aabb box = sdfg::computeBounds(mug.positions);
    CHECK(box.min.x == Approx(-0.04).margin(1e-6));
    CHECK(box.max.x == Approx(0.0735).margin(1e-6));
    CHECK(box.min.y == Approx(-0.0475).margin(1e-6));
    CHECK(box.max.y == Approx(0.0475).margin(1e-6));
    CHECK(box.min.z == Approx(-0.04).margin(1e-6));
    CHECK(box.max.z == Approx(0.04).margin(1e-6));
  }
  SECTION("Solid where the material is, empty in the cavity and the hole") {
    CHECK(inside(mug, {-0.0375, 0.0, 0.0}));      // in the wall opposite the handle
    CHECK(inside(mug, {0.0, -0.045, 0.0}));       // in the floor
    CHECK(inside(mug, {0.069, 0.0, 0.0}));        // in the handle, farthest from the wall
    CHECK(inside(mug, {0.05, 0.025, 0.0}));       // in the handle's upper arm
    CHECK_FALSE(inside(mug, {0.0, 0.0, 0.0}));    // in the cavity
    CHECK_FALSE(inside(mug, {0.052, 0.0, 0.0}));  // in the handle's hole
  }
  SECTION("A line through the hole misses the mug, and the handle closes round it") {
    // Off the y = 0 and z = 0 planes, where rows of vertices lie.
    const glm::dvec3 hole(0.052, 0.0013, 0.0011);
    CHECK(crossings(mug, hole + glm::dvec3(0, 0, -0.2), hole + glm::dvec3(0, 0, 0.2)) == 0);
    CHECK(crossings(mug, hole, hole + glm::dvec3(0.2, 0, 0)) == 2);   // the handle's far side
    CHECK(crossings(mug, hole, hole + glm::dvec3(0, 0.2, 0)) == 2);   // its upper arm
    CHECK(crossings(mug, hole, hole + glm::dvec3(0, -0.2, 0)) == 2);  // its lower arm
    CHECK(crossings(mug, hole, hole + glm::dvec3(-0.2, 0, 0)) == 4);  // the cup's two walls
  }
}

TEST_CASE("Spheres share vertices and lie on their radius", "[core][shapes]") {
  for (int level = 0; level <= 3; ++level) {
    CAPTURE(level);
    const sdfg::TriangleMesh sphere = sdfg::makeSphere(0.02f, level);
    const size_t faces = size_t(20) << (2 * level);
    CHECK(sphere.triangleCount() == faces);
    CHECK(sphere.vertexCount() == faces / 2 + 2);  // Euler: V = F/2 + 2 when shared
    double worst = 0.0;
    for (const glm::vec3& p : sphere.positions) {
      worst = std::max(worst, std::abs(double(glm::length(p)) - 0.02));
    }
    CHECK(worst < 1e-7);
  }
}

TEST_CASE("The embedded objects are the mug, the torus and the thin plate", "[core][shapes]") {
  const auto objects = sdfg::embeddedObjects();
  REQUIRE(objects.size() == 3);
  CHECK(objects[0].name == "mug");
  CHECK(objects[1].name == "torus");
  CHECK(objects[2].name == "thin-plate");
  for (const auto& object : objects) {
    CAPTURE(object.name);
    checkClosedSolid(object.mesh);
    // Hand-sized: larger than 5 cm and smaller than 30 cm across.
    const float diagonal = glm::length(sdfg::computeBounds(object.mesh.positions).extent());
    CHECK(diagonal > 0.05f);
    CHECK(diagonal < 0.3f);
  }
}
