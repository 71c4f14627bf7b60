// Welding by position (mesh/mesh_weld.h) and what it gives MeshDistance: a mesh whose vertices
// are split (a triangle soup, seams) is signed exactly as the same surface indexed; near-equal
// positions weld, distinct ones never do; repeated triangles go; closed parts that overlap are
// signed by the winding number.
#include <catch2/catch.hpp>

#include <random>
#include <vector>

#include "io/shapes.h"
#include "mesh/mesh_distance.h"
#include "mesh/mesh_weld.h"

namespace {

using namespace sdfg;

// Every triangle its own three vertices, positions bit-identical.
TriangleMesh soup(const TriangleMesh& m) {
  TriangleMesh out;
  for (uint32_t i : m.indices) {
    out.indices.push_back(uint32_t(out.positions.size()));
    out.positions.push_back(m.positions[i]);
  }
  return out;
}

TriangleMesh translated(TriangleMesh m, const glm::vec3& by) {
  for (glm::vec3& p : m.positions) p += by;
  return m;
}

TriangleMesh joined(const TriangleMesh& a, const TriangleMesh& b) {
  TriangleMesh out = a;
  const uint32_t base = uint32_t(a.positions.size());
  out.positions.insert(out.positions.end(), b.positions.begin(), b.positions.end());
  for (uint32_t i : b.indices) out.indices.push_back(base + i);
  return out;
}

std::unique_ptr<MeshDistance> distanceOf(const TriangleMesh& m) {
  auto made = MeshDistance::create(m);
  REQUIRE(made.ok());
  return std::move(*made);
}

}  // namespace

TEST_CASE("A triangle soup welds back into the indexed mesh's topology", "[core][mesh]") {
  const TriangleMesh mug = makeMug();
  TriangleMesh s = soup(mug);
  const size_t soupVertices = s.positions.size();
  const WeldReport r = weldByPosition(s.positions, s.indices);
  CHECK_FALSE(r.stopped);
  CHECK(r.vertices == soupVertices);
  CHECK(r.weldedVertices == mug.vertexCount());
  CHECK(r.nearWelded == 0);
  CHECK(r.duplicateTriangles == 0);
  CHECK(r.collapsedTriangles == 0);
  CHECK(s.positions.size() == soupVertices);  // the app's array is untouched
  CHECK(s.triangleCount() == mug.triangleCount());
  CHECK(r.describe() == std::to_string(soupVertices) + " split vertices welded into " +
                            std::to_string(mug.vertexCount()));

  // Welding a welded mesh changes nothing.
  const std::vector<uint32_t> once = s.indices;
  const WeldReport again = weldByPosition(s.positions, s.indices);
  CHECK_FALSE(again.changed());
  CHECK(s.indices == once);
  CHECK(again.describe() == "no split vertices");
}

TEST_CASE("A soup is closed and signed exactly as the indexed mesh", "[core][mesh]") {
  for (const TriangleMesh& m : {makeMug(), makeTorus(), makeThinPlate(), makeSphere(0.02f, 2)}) {
    const auto indexed = distanceOf(m);
    const auto split = distanceOf(soup(m));
    REQUIRE(indexed->isClosed());
    CHECK(split->isClosed());
    CHECK(split->signsByWinding() == indexed->signsByWinding());
    const Aabb b = computeBounds(m.positions);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    int inside = 0;
    for (int i = 0; i < 2000; ++i) {
      const glm::vec3 p = b.min - 0.01f + (b.extent() + 0.02f) * glm::vec3(u(rng), u(rng), u(rng));
      const float d = indexed->signedDistance(p);
      inside += d < 0.0f ? 1 : 0;
      REQUIRE(split->signedDistance(p) == d);
      REQUIRE(split->localSignedDistanceWithin(p, 0.01f) ==
              indexed->localSignedDistanceWithin(p, 0.01f));
    }
    CHECK(inside > 20);  // the points do test the inside
  }
}

TEST_CASE("Near-equal positions weld, positions a tolerance apart never do", "[core][mesh]") {
  const TriangleMesh box = makeBox(glm::vec3(0.1f));
  const float diagonal = glm::length(computeBounds(box.positions).extent());
  TriangleMesh s = soup(box);
  // Every copy of a corner after the first nudged by a tenth of the tolerance: welded.
  std::vector<int> seen(box.vertexCount(), 0);
  for (size_t i = 0; i < box.indices.size(); ++i)
    if (seen[box.indices[i]]++ > 0) s.positions[i].x += 0.1f * kWeldRelativeTolerance * diagonal;
  WeldReport r = weldByPosition(s.positions, s.indices);
  CHECK(r.weldedVertices == box.vertexCount());
  CHECK(r.nearWelded == s.positions.size() - box.vertexCount());
  CHECK(distanceOf(s)->isClosed());

  // Nudged by ten tolerances (18 um at this size): a crack, not float noise; nothing welds.
  TriangleMesh cracked = soup(box);
  std::fill(seen.begin(), seen.end(), 0);
  for (size_t i = 0; i < box.indices.size(); ++i)
    if (seen[box.indices[i]]++ > 0)
      cracked.positions[i].x += 10.0f * kWeldRelativeTolerance * diagonal;
  r = weldByPosition(cracked.positions, cracked.indices);
  CHECK(r.weldedVertices > box.vertexCount());
  CHECK(r.nearWelded == 0);
}

TEST_CASE("Repeated and double-sided triangles are dropped", "[core][mesh]") {
  const TriangleMesh box = makeBox(glm::vec3(0.1f));
  TriangleMesh doubled = box;
  doubled.indices.insert(doubled.indices.end(), box.indices.begin(), box.indices.end());
  TriangleMesh twoSided = box;
  for (size_t t = 0; t < box.triangleCount(); ++t) {
    twoSided.indices.push_back(box.indices[3 * t]);
    twoSided.indices.push_back(box.indices[3 * t + 2]);
    twoSided.indices.push_back(box.indices[3 * t + 1]);
  }
  for (TriangleMesh* m : {&doubled, &twoSided}) {
    TriangleMesh w = *m;
    const WeldReport r = weldByPosition(w.positions, w.indices);
    CHECK(r.duplicateTriangles == box.triangleCount());
    CHECK(w.indices == box.indices);  // the first of each pair is kept
    const auto d = distanceOf(*m);
    CHECK(d->isClosed());
    CHECK(d->signedDistance(glm::vec3(0.0f)) == Approx(-0.05f).margin(1e-6));
    CHECK(d->signedDistance(glm::vec3(0.0f, 0.08f, 0.0f)) == Approx(0.03f).margin(1e-6));
  }
}

TEST_CASE("Closed parts that overlap are inside in their overlap", "[core][mesh]") {
  // A cross of two closed boxes: in the middle the nearest surface is the other box's inner
  // face, whose pseudo-normal says outside.
  const TriangleMesh a = makeBox(glm::vec3(0.12f, 0.02f, 0.02f));
  const TriangleMesh b = makeBox(glm::vec3(0.02f, 0.12f, 0.02f));
  const TriangleMesh cross = joined(a, b);
  CHECK(partsOverlap(cross.positions, cross.indices));
  const auto d = distanceOf(cross);
  CHECK(d->isClosed());
  CHECK(d->signsByWinding());
  for (const glm::vec3 p : {glm::vec3(0.0f), glm::vec3(0.009f, 0.0f, 0.0f),
                            glm::vec3(0.0f, 0.009f, 0.005f), glm::vec3(0.05f, 0.0f, 0.0f)})
    CHECK(d->signedDistance(p) < 0.0f);
  CHECK(d->signedDistance(glm::vec3(0.03f, 0.03f, 0.0f)) > 0.0f);

  // Two boxes apart stay signed by pseudo-normals (the fast path).
  const TriangleMesh apart = joined(a, translated(b, glm::vec3(0.2f, 0.0f, 0.0f)));
  CHECK_FALSE(partsOverlap(apart.positions, apart.indices));
  CHECK_FALSE(distanceOf(apart)->signsByWinding());
}

TEST_CASE("A welded soup takes the app's vertex updates one for one", "[core][mesh]") {
  const TriangleMesh sphere = makeSphere(0.02f, 2);
  const TriangleMesh s = soup(sphere);
  const auto d = distanceOf(s);
  REQUIRE(d->mesh().positions.size() == s.positions.size());
  std::vector<glm::vec3> bigger = s.positions;
  for (glm::vec3& p : bigger) p *= 1.5f;
  REQUIRE(d->updatePositions(bigger) == Status::ok);
  CHECK(d->isClosed());
  CHECK(d->signedDistance(glm::vec3(0.0f, 0.025f, 0.0f)) < 0.0f);
  CHECK(d->signedDistance(glm::vec3(0.0f, 0.035f, 0.0f)) > 0.0f);
  // A different count is refused, as for any mesh.
  bigger.pop_back();
  CHECK(d->updatePositions(bigger) == Status::invalid_argument);
}

TEST_CASE("A weld stopped by its limit leaves the indices as given", "[core][mesh]") {
  TriangleMesh s = soup(makeSphere(0.02f, 4));
  const std::vector<uint32_t> given = s.indices;
  std::atomic<bool> stop{true};
  const WeldReport r =
      weldByPosition(s.positions, s.indices, WorkLimit{WorkLimit::Clock::time_point::max(), &stop});
  CHECK(r.stopped);
  CHECK(s.indices == given);
}

TEST_CASE("A weld that would leave a triangle of zero area changes nothing", "[core][mesh]") {
  // Corner c of the sliver is within the tolerance of d, which a first triangle uses: welding c
  // into d would lay a, b and c on one line.
  TriangleMesh m;
  m.positions = {{0.05f, 0.0f, 0.0f}, {0.05f, 0.05f, 0.0f}, {0.0f, 0.05f, 0.0f},
                 {0.0f, 0.0f, 0.0f},  {0.1f, 0.0f, 0.0f},   {0.05f, 5e-7f, 0.0f}};
  m.indices = {0, 1, 2, 3, 4, 5};
  REQUIRE_FALSE(validateMesh(m.positions, m.indices).has_value());
  const std::vector<uint32_t> given = m.indices;
  const WeldReport r = weldByPosition(m.positions, m.indices);
  CHECK_FALSE(r.stopped);
  CHECK_FALSE(r.changed());
  CHECK(r.vertices == 6);
  CHECK(m.indices == given);
  CHECK(distanceOf(m)->mesh().indices == given);
}
