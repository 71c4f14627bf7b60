#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "mesh/mesh.h"

namespace {

// A unit right tetrahedron with outward counter-clockwise faces.
const std::vector<glm::vec3> kPositions = {
    {0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, {0.0f, 0.0f, 1.0f}};
const std::vector<uint32_t> kIndices = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// The error makeMesh gives for these arrays; fails the test when there is none.
sdfg::Error rejection(const std::vector<glm::vec3>& positions,
                      const std::vector<uint32_t>& indices) {
  const auto validated = sdfg::validateMesh(positions, indices);
  const auto made = sdfg::makeMesh(std::span<const glm::vec3>(positions), indices);
  REQUIRE(validated.has_value());
  REQUIRE_FALSE(made.ok());
  CHECK(made.error().message == validated->message);
  CHECK(made.error().code == sdfg::Status::invalid_argument);
  return *validated;
}

}  // namespace

TEST_CASE("A valid mesh round-trips through makeMesh", "[core][mesh]") {
  SECTION("From vec3 positions") {
    CHECK_FALSE(sdfg::validateMesh(kPositions, kIndices).has_value());
    const auto mesh = sdfg::makeMesh(std::span<const glm::vec3>(kPositions), kIndices);
    REQUIRE(mesh.ok());
    CHECK(mesh->positions == kPositions);
    CHECK(mesh->indices == kIndices);
    CHECK(mesh->vertexCount() == 4);
    CHECK(mesh->triangleCount() == 4);
  }
  SECTION("From interleaved floats") {
    std::vector<float> xyz;
    for (const glm::vec3& p : kPositions) xyz.insert(xyz.end(), {p.x, p.y, p.z});
    const auto mesh = sdfg::makeMesh(std::span<const float>(xyz), kIndices);
    REQUIRE(mesh.ok());
    CHECK(mesh->positions == kPositions);
    CHECK(mesh->indices == kIndices);
  }
}

TEST_CASE("Bad mesh arrays are rejected with a message naming the element", "[core][mesh]") {
  SECTION("Empty positions or indices") {
    CHECK(contains(rejection({}, kIndices).message, "empty"));
    CHECK(contains(rejection(kPositions, {}).message, "empty"));
  }
  SECTION("Index count not a multiple of 3") {
    std::vector<uint32_t> indices = kIndices;
    indices.push_back(0);
    CHECK(contains(rejection(kPositions, indices).message, "13"));
  }
  SECTION("NaN or infinite coordinate") {
    for (float bad :
         {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
          -std::numeric_limits<float>::infinity()}) {
      std::vector<glm::vec3> positions = kPositions;
      positions[2].y = bad;
      CAPTURE(bad);
      CHECK(contains(rejection(positions, kIndices).message, "vertex 2"));
    }
  }
  SECTION("Index out of range") {
    std::vector<uint32_t> indices = kIndices;
    indices[7] = 4;
    const std::string message = rejection(kPositions, indices).message;
    CHECK(contains(message, "index 7"));
    CHECK(contains(message, "triangle 2"));
  }
  SECTION("Repeated index") {
    std::vector<uint32_t> indices = kIndices;
    indices[10] = indices[9];  // triangle 3 becomes (1, 1, 3)
    CHECK(contains(rejection(kPositions, indices).message, "triangle 3"));
  }
  SECTION("Zero area") {
    std::vector<glm::vec3> positions = kPositions;
    positions.push_back({2.0f, 0.0f, 0.0f});  // on the line through vertices 0 and 1
    std::vector<uint32_t> indices = kIndices;
    indices.insert(indices.end(), {0, 1, 4});
    const std::string message = rejection(positions, indices).message;
    CHECK(contains(message, "triangle 4"));
    CHECK(contains(message, "zero area"));
  }
  SECTION("Interleaved floats not a multiple of 3") {
    const std::vector<float> xyz = {0.0f, 0.0f, 0.0f, 1.0f};
    const auto mesh = sdfg::makeMesh(std::span<const float>(xyz), kIndices);
    REQUIRE_FALSE(mesh.ok());
    CHECK(mesh.error().code == sdfg::Status::invalid_argument);
    CHECK(contains(mesh.error().message, "4 floats"));
  }
}
