#include <catch2/catch.hpp>

#include <atomic>
#include <utility>
#include <vector>

#include "io/shapes.h"
#include "mesh/mesh_distance.h"
#include "mesh/mesh_orientation.h"

namespace {

using namespace sdfg;

// Six times the signed volume of a triangle list: positive when it faces outward.
double signedVolume6(const TriangleMesh& m) {
  double v = 0.0;
  for (size_t i = 0; i < m.indices.size(); i += 3) {
    const glm::dvec3 a(m.positions[m.indices[i]]), b(m.positions[m.indices[i + 1]]),
        c(m.positions[m.indices[i + 2]]);
    v += glm::dot(a, glm::cross(b, c));
  }
  return v;
}

void flipTriangle(TriangleMesh& m, size_t t) {
  std::swap(m.indices[3 * t + 1], m.indices[3 * t + 2]);
}

TriangleMesh clockwise(TriangleMesh m) {
  for (size_t t = 0; t < m.triangleCount(); ++t) flipTriangle(m, t);
  return m;
}

// The triangles of `m` whose centroid has y > `cut`: an open bowl when cut < 0 on a sphere.
TriangleMesh keepAbove(const TriangleMesh& m, float cut) {
  TriangleMesh out;
  out.positions = m.positions;
  for (size_t i = 0; i < m.indices.size(); i += 3) {
    const float y = (m.positions[m.indices[i]].y + m.positions[m.indices[i + 1]].y +
                     m.positions[m.indices[i + 2]].y) /
                    3.0f;
    if (y > cut)
      out.indices.insert(out.indices.end(), m.indices.begin() + long(i),
                         m.indices.begin() + long(i) + 3);
  }
  return out;
}

}  // namespace

TEST_CASE("Mesh orientation: an outward sphere is left as given", "[mesh][orientation]") {
  TriangleMesh sphere = makeSphere(0.04f);
  const std::vector<uint32_t> before = sphere.indices;
  const MeshOrientation o = orientOutward(sphere.positions, sphere.indices);
  CHECK(o.components == 1);
  CHECK(o.closedComponents == 1);
  CHECK(o.flipped == 0);
  CHECK(sphere.indices == before);
  CHECK(std::string(o.describe()) == "counter-clockwise (outward)");
}

TEST_CASE("Mesh orientation: a clockwise sphere is turned outward whole", "[mesh][orientation]") {
  TriangleMesh sphere = clockwise(makeSphere(0.04f));
  REQUIRE(signedVolume6(sphere) < 0.0);
  const MeshOrientation o = orientOutward(sphere.positions, sphere.indices);
  CHECK(o.invertedComponents == 1);
  CHECK(o.inconsistent == 0);
  CHECK(o.flipped == sphere.triangleCount());
  CHECK(signedVolume6(sphere) > 0.0);
  CHECK(std::string(o.describe()) == "clockwise (inside-out)");
  // The core's sign convention holds again: negative inside, positive outside.
  auto distance = MeshDistance::create(sphere);
  REQUIRE(distance.ok());
  CHECK((*distance)->signedDistance({0, 0, 0}) == Approx(-0.04).margin(2e-3));
  CHECK((*distance)->signedDistance({0.1f, 0, 0}) == Approx(0.06).margin(2e-3));
}

TEST_CASE("Mesh orientation: mixed winding is made consistent and outward", "[mesh][orientation]") {
  const TriangleMesh reference = makeSphere(0.04f);
  // One triangle in three flipped (a minority), then the same with two in three (a majority).
  for (const int keepEvery : {3, 2}) {
    CAPTURE(keepEvery);
    TriangleMesh mixed = reference;
    size_t flippedIn = 0;
    for (size_t t = 0; t < mixed.triangleCount(); ++t) {
      const bool flip = keepEvery == 3 ? t % 3 == 0 : t % 3 != 0;
      if (flip) {
        flipTriangle(mixed, t);
        ++flippedIn;
      }
    }
    const MeshOrientation o = orientOutward(mixed.positions, mixed.indices);
    CHECK(o.inconsistent > 0);
    CHECK(std::string(o.describe()) == "mixed");
    CHECK(o.flipped == flippedIn);
    // Every triangle is back as the outward reference has it.
    CHECK(mixed.indices == reference.indices);
  }
}

TEST_CASE("Mesh orientation: an open bowl is judged by its winding number", "[mesh][orientation]") {
  const TriangleMesh bowl = keepAbove(makeSphere(0.04f), -0.02f);
  SECTION("Wound outward, it stays") {
    TriangleMesh m = bowl;
    const MeshOrientation o = orientOutward(m.positions, m.indices);
    CHECK(o.closedComponents == 0);
    CHECK(o.flipped == 0);
    CHECK(m.indices == bowl.indices);
  }
  SECTION("Wound clockwise, it is flipped") {
    TriangleMesh m = clockwise(bowl);
    const MeshOrientation o = orientOutward(m.positions, m.indices);
    CHECK(o.closedComponents == 0);
    CHECK(o.invertedComponents == 1);
    CHECK(m.indices == bowl.indices);
  }
}

TEST_CASE("Mesh orientation: separate parts are judged one by one", "[mesh][orientation]") {
  // Two spheres side by side, the second wound clockwise.
  TriangleMesh a = makeSphere(0.03f);
  TriangleMesh b = clockwise(makeSphere(0.03f));
  TriangleMesh both = a;
  const uint32_t base = uint32_t(both.positions.size());
  for (glm::vec3 p : b.positions) both.positions.push_back(p + glm::vec3(0.1f, 0, 0));
  for (uint32_t i : b.indices) both.indices.push_back(base + i);
  const MeshOrientation o = orientOutward(both.positions, both.indices);
  CHECK(o.components == 2);
  CHECK(o.closedComponents == 2);
  CHECK(o.invertedComponents == 1);
  CHECK(o.flipped == b.triangleCount());
  CHECK(std::equal(a.indices.begin(), a.indices.end(), both.indices.begin()));
}

TEST_CASE("Generalized winding number: 1 inside, 0 outside, -1 inside out", "[mesh][orientation]") {
  const TriangleMesh sphere = makeSphere(0.04f);
  const TriangleMesh inverted = clockwise(sphere);
  CHECK(windingNumberAt(sphere.positions, sphere.indices, {0, 0, 0}) == Approx(1.0).margin(1e-6));
  CHECK(windingNumberAt(sphere.positions, sphere.indices, {0.2, 0, 0}) == Approx(0.0).margin(1e-6));
  CHECK(windingNumberAt(inverted.positions, inverted.indices, {0, 0, 0}) ==
        Approx(-1.0).margin(1e-6));
}

TEST_CASE("A stopped orientation leaves the indices as given", "[mesh_orientation][work_limit]") {
  std::atomic<bool> stop{true};
  const WorkLimit stopped{WorkLimit::Clock::time_point::max(), &stop};
  TriangleMesh inverted = clockwise(makeSphere(0.04f, 4));
  const std::vector<uint32_t> given = inverted.indices;
  const MeshOrientation o = orientOutward(inverted.positions, inverted.indices, stopped);
  CHECK(o.stopped);
  CHECK(o.flipped == 0);
  CHECK(inverted.indices == given);
  // Not stopped, the same mesh is turned outward.
  stop = false;
  const MeshOrientation done = orientOutward(inverted.positions, inverted.indices, stopped);
  CHECK_FALSE(done.stopped);
  CHECK(done.flipped == inverted.triangleCount());
  CHECK(signedVolume6(inverted) > 0.0);
}
