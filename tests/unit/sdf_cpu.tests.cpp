#include <catch2/catch.hpp>

#include <chrono>
#include <cmath>
#include <ctime>
#include <iostream>
#include <random>

#include "distance_test_meshes.h"
#include "sdf_cpu.h"

using namespace sdfg;
using namespace sdfg::test;

namespace {

std::unique_ptr<MeshDistance> makeDistance(const TriangleMesh& m) {
  auto result = MeshDistance::create(m);
  REQUIRE(result.ok());
  return std::move(result).value();
}

GridBox boxAt(const glm::vec3& centre, uint32_t resolution, float size = 0.12f) {
  GridBox box;
  box.handFromBox.position = centre;
  box.handFromBox.orientation = glm::angleAxis(0.4f, glm::normalize(glm::vec3(1, -1, 2)));
  box.size = glm::vec3(size, 0.8f * size, 1.1f * size);
  box.resolution = glm::uvec3(resolution);
  return box;
}

// A pose placing hand space somewhere else in object space, so the builder's transform chain
// is exercised.
const Pose kObjectFromHand{glm::angleAxis(-1.1f, glm::normalize(glm::vec3(0.3f, 1, -0.2f))),
                           glm::vec3(0.01f, -0.02f, 0.015f)};

glm::vec3 nodeInObject(const GridBox& box, uint32_t i, uint32_t j, uint32_t k) {
  return kObjectFromHand.transformPoint(box.handFromBox.transformPoint(box.nodeLocal(i, j, k)));
}

// Hand-space centre of a box that puts object-space point `p` at the box centre.
glm::vec3 handPointFor(const glm::vec3& p) {
  return kObjectFromHand.inverse().transformPoint(p);
}

}  // namespace

TEST_CASE("CpuSdfBuilder holds the exact signed distance at every node", "[sdf_cpu]") {
  const auto d = makeDistance(icosphereMesh(0.05f, 3));
  CpuSdfBuilder builder(2);
  const GridBox box = boxAt(handPointFor(glm::vec3(0.03f, 0.0f, 0.02f)), 20);
  SdfGrid grid;
  REQUIRE(builder.build(*d, kObjectFromHand, box, grid) == Status::ok);
  REQUIRE(grid.values().size() == box.nodeCount());
  CHECK(grid.box().resolution == box.resolution);
  int negative = 0;
  for (uint32_t k = 0; k < 20; ++k) {
    for (uint32_t j = 0; j < 20; ++j) {
      for (uint32_t i = 0; i < 20; ++i) {
        const float expected = d->signedDistance(nodeInObject(box, i, j, k));
        CHECK(grid.at(i, j, k) == Approx(expected).margin(1e-6));
        negative += grid.at(i, j, k) < 0.0f;
      }
    }
  }
  // The box reaches deep into the sphere: many nodes inside, all of them negative.
  CHECK(negative > 500);
}

TEST_CASE("CpuSdfBuilder gives the same grid with 1 and 2 threads", "[sdf_cpu]") {
  const auto d = makeDistance(icosphereMesh(0.05f, 3));
  const GridBox box = boxAt(handPointFor(glm::vec3(0.0f, 0.05f, 0.0f)), 33);
  CpuSdfBuilder one(1), two(2), automatic(0);
  SdfGrid a, b, c;
  REQUIRE(one.build(*d, kObjectFromHand, box, a) == Status::ok);
  REQUIRE(two.build(*d, kObjectFromHand, box, b) == Status::ok);
  REQUIRE(automatic.build(*d, kObjectFromHand, box, c) == Status::ok);
  CHECK(std::equal(a.values().begin(), a.values().end(), b.values().begin(), b.values().end()));
  CHECK(std::equal(a.values().begin(), a.values().end(), c.values().begin(), c.values().end()));
  // A second build on the same pool (workers reused) gives the same grid again.
  SdfGrid again;
  REQUIRE(two.build(*d, kObjectFromHand, box, again) == Status::ok);
  CHECK(std::equal(a.values().begin(), a.values().end(), again.values().begin(),
                   again.values().end()));
}

TEST_CASE("CpuSdfBuilder accepts resolutions 2 to 128 and rejects others", "[sdf_cpu]") {
  const auto d = makeDistance(cubeMesh(0.05f));
  CpuSdfBuilder builder(2);
  SECTION("accepted") {
    for (uint32_t n : {2u, 3u, 17u, 128u}) {
      GridBox box = boxAt(glm::vec3(0.0f), 2);
      box.resolution = glm::uvec3(n, 2u, n == 128 ? 2u : n);
      SdfGrid grid;
      CAPTURE(n);
      REQUIRE(builder.build(*d, Pose{}, box, grid) == Status::ok);
      CHECK(grid.values().size() == box.nodeCount());
    }
  }
  SECTION("rejected, output untouched") {
    const GridBox good = boxAt(glm::vec3(0.0f), 4);
    SdfGrid grid(good);
    std::fill(grid.values().begin(), grid.values().end(), 55.0f);
    for (const glm::uvec3 n : {glm::uvec3(1, 4, 4), glm::uvec3(4, 129, 4), glm::uvec3(4, 4, 0)}) {
      GridBox box = good;
      box.resolution = n;
      CHECK(builder.build(*d, Pose{}, box, grid) == Status::invalid_argument);
    }
    GridBox nanBox = good;
    nanBox.size.x = std::nanf("");
    CHECK(builder.build(*d, Pose{}, nanBox, grid) == Status::invalid_argument);
    CHECK(grid.values().size() == good.nodeCount());
    CHECK(std::all_of(grid.values().begin(), grid.values().end(),
                      [](float v) { return v == 55.0f; }));
  }
}

TEST_CASE("The 100k and 400k armadillo give the same grid", "[sdf_cpu][shared]") {
  const TriangleMesh* coarse = normalizedSharedMesh("stanford-armadillo-100k.obj");
  const TriangleMesh* fine = normalizedSharedMesh("stanford-armadillo-400k-subdiv.obj");
  if (coarse == nullptr || fine == nullptr) SDFG_SKIP("shared armadillo meshes missing");
  const auto dc = makeDistance(*coarse);
  const auto df = makeDistance(*fine);
  REQUIRE(dc->isClosed());
  REQUIRE(df->isClosed());
  CpuSdfBuilder builder(0);
  std::mt19937 rng(8);
  std::uniform_int_distribution<size_t> vertex(0, coarse->positions.size() - 1);
  for (int b = 0; b < 4; ++b) {
    // A box centred on a surface point, as a grab would place it.
    const GridBox box = boxAt(handPointFor(coarse->positions[vertex(rng)]), 24, 0.1f);
    SdfGrid gc, gf;
    REQUIRE(builder.build(*dc, kObjectFromHand, box, gc) == Status::ok);
    REQUIRE(builder.build(*df, kObjectFromHand, box, gf) == Status::ok);
    float worst = 0.0f;
    int negative = 0;
    for (size_t i = 0; i < gc.values().size(); ++i) {
      worst = std::max(worst, std::abs(gc.values()[i] - gf.values()[i]));
      negative += gc.values()[i] < 0.0f;
    }
    CAPTURE(b, worst, negative);
    // 1e-6 of the 0.18 m diagonal: what float coordinates of the subdivided copy allow.
    CHECK(worst < 1e-6f * 0.18f);
    CHECK(negative > 0);
    CHECK(negative < int(gc.values().size()));
  }
}

// Timings for the report; hidden from the default run. Run: sdf_cpu_tests "[timing]".
TEST_CASE("Timing of CPU grab-box builds on the armadillo", "[.][timing]") {
  using Clock = std::chrono::steady_clock;
  const auto ms = [](Clock::duration d) {
    return std::chrono::duration<double, std::milli>(d).count();
  };
  for (const char* name : {"stanford-armadillo-100k.obj", "stanford-armadillo-400k-subdiv.obj",
                           "stanford-bunny.obj"}) {
    const TriangleMesh* m = normalizedSharedMesh(name);
    if (m == nullptr) SDFG_SKIP("shared meshes missing");
    const std::clock_t c0 = std::clock();
    const auto t0 = Clock::now();
    const auto d = makeDistance(*m);
    const auto t1 = Clock::now();
    std::cout << name << ": " << m->triangleCount() << " triangles, MeshDistance::create "
              << ms(t1 - t0) << " ms wall, " << 1000.0 * double(std::clock() - c0) / CLOCKS_PER_SEC
              << " ms CPU\n";
    for (unsigned threads : {1u, 2u}) {
      CpuSdfBuilder builder(threads);
      for (uint32_t n : {16u, 32u, 64u}) {
        GridBox box = GridBox::referenceDefault();
        box.resolution = glm::uvec3(n);
        // Box centre on a surface point (hand pose = identity, so hand space = object space).
        box.handFromBox.position = m->positions[m->indices[3 * (m->triangleCount() / 3)]];
        SdfGrid grid;
        double best = 1e30, bestCpu = 1e30;
        for (int rep = 0; rep < 3; ++rep) {
          // Process CPU time too: on a shared machine wall time counts other jobs' turns.
          const std::clock_t c0 = std::clock();
          const auto s = Clock::now();
          REQUIRE(builder.build(*d, Pose{}, box, grid) == Status::ok);
          best = std::min(best, ms(Clock::now() - s));
          bestCpu = std::min(bestCpu, 1000.0 * double(std::clock() - c0) / CLOCKS_PER_SEC);
        }
        CHECK(std::all_of(grid.values().begin(), grid.values().end(),
                          [](float v) { return std::isfinite(v); }));
        std::cout << "  " << n << "^3, " << threads << " thread(s): " << best << " ms wall, "
                  << bestCpu << " ms CPU (best of 3)\n";
      }
    }
  }
}
