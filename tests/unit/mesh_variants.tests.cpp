// The split-vertex variants of a mesh (io/mesh_variants.h): the same triangles in the same order
// and winding, every corner at a bit-identical position, and as many vertices as an exporter
// would make: a cube has 8, its soup 36, its flat-shaded and box-mapped versions 24 each.
#include <catch2/catch.hpp>

#include <cstring>
#include <string>

#include "io/mesh_variants.h"
#include "io/shapes.h"

using namespace sdfg;

namespace {

// Every corner of `variant` at the bit-identical position of the same corner of `mesh`.
void checkSameSurface(const TriangleMesh& mesh, const TriangleMesh& variant) {
  REQUIRE(variant.triangleCount() == mesh.triangleCount());
  REQUIRE(variant.indices.size() == mesh.indices.size());
  CHECK_FALSE(validateMesh(variant.positions, variant.indices).has_value());
  size_t moved = 0;
  for (size_t c = 0; c < mesh.indices.size(); ++c) {
    const glm::vec3& a = mesh.positions[mesh.indices[c]];
    const glm::vec3& b = variant.positions[variant.indices[c]];
    if (std::memcmp(&a, &b, sizeof a) != 0) ++moved;
  }
  CHECK(moved == 0);
}

// Every vertex of `variant` is used, and they come in the order of first use.
void checkFirstUseOrder(const TriangleMesh& variant) {
  uint32_t next = 0;
  for (uint32_t i : variant.indices) {
    REQUIRE(i <= next);
    if (i == next) ++next;
  }
  CHECK(next == variant.vertexCount());
}

// Corners of one vertex in `mesh` never share an index in `variant` unless they shared one in
// `mesh` (a split only splits).
void checkOnlySplits(const TriangleMesh& mesh, const TriangleMesh& variant) {
  std::vector<uint32_t> original(variant.vertexCount(), UINT32_MAX);
  size_t merged = 0;
  for (size_t c = 0; c < mesh.indices.size(); ++c) {
    uint32_t& o = original[variant.indices[c]];
    if (o != UINT32_MAX && o != mesh.indices[c]) ++merged;
    o = mesh.indices[c];
  }
  CHECK(merged == 0);
}

void checkVariant(const TriangleMesh& mesh, const TriangleMesh& variant) {
  checkSameSurface(mesh, variant);
  checkFirstUseOrder(variant);
  checkOnlySplits(mesh, variant);
}

}  // namespace

TEST_CASE("the variants of a cube have the vertex counts an exporter gives", "[mesh_variants]") {
  const TriangleMesh cube = makeBox(glm::vec3(0.1f, 0.06f, 0.04f));
  REQUIRE(cube.vertexCount() == 8);
  REQUIRE(cube.triangleCount() == 12);

  const TriangleMesh soup = soupVariant(cube);
  checkVariant(cube, soup);
  CHECK(soup.vertexCount() == 36);

  // Each face is a smoothing region (its two triangles are coplanar), each corner in 3 faces.
  const TriangleMesh flat = flatVariant(cube);
  checkVariant(cube, flat);
  CHECK(flat.vertexCount() == 24);

  // Each face is a chart of its own.
  const TriangleMesh seams = seamsVariant(cube);
  checkVariant(cube, seams);
  CHECK(seams.vertexCount() == 24);
}

TEST_CASE("makeMeshVariant gives each named variant and rejects an unknown name",
          "[mesh_variants]") {
  const TriangleMesh mug = makeMug();
  REQUIRE(meshVariantNames().size() == 3);
  CHECK(meshVariantNames()[0] == "soup");
  CHECK(meshVariantNames()[1] == "flat");
  CHECK(meshVariantNames()[2] == "seams");
  for (std::string_view name : meshVariantNames()) {
    INFO(std::string(name));
    const Result<TriangleMesh> variant = makeMeshVariant(name, mug);
    REQUIRE(variant.ok());
    checkVariant(mug, *variant);
    CHECK(variant->vertexCount() > mug.vertexCount());
  }
  CHECK(makeMeshVariant("soup", mug)->vertexCount() == 3 * mug.triangleCount());

  const Result<TriangleMesh> unknown = makeMeshVariant("welded", mug);
  REQUIRE_FALSE(unknown.ok());
  CHECK(unknown.error().code == Status::invalid_argument);
  TriangleMesh broken = mug;
  broken.indices.back() = uint32_t(broken.vertexCount());
  CHECK_FALSE(makeMeshVariant("flat", broken).ok());
}

TEST_CASE("flat splits only hard edges: a fine sphere and torus stay whole", "[mesh_variants]") {
  // Neighbouring faces of a 3-times subdivided icosahedron differ by about 8 degrees, of the
  // 48 x 24 torus by at most 15: below the 30-degree split angle.
  const TriangleMesh sphere = makeSphere(0.05f, 3);
  const TriangleMesh flatSphere = flatVariant(sphere);
  checkVariant(sphere, flatSphere);
  CHECK(flatSphere.vertexCount() == sphere.vertexCount());
  const TriangleMesh torus = makeTorus();
  const TriangleMesh flatTorus = flatVariant(torus);
  checkVariant(torus, flatTorus);
  CHECK(flatTorus.vertexCount() == torus.vertexCount());

  // With a split angle below every dihedral angle each triangle is a region: a soup.
  const TriangleMesh faceted = flatVariant(sphere, 1.0f);
  checkVariant(sphere, faceted);
  CHECK(faceted.vertexCount() == 3 * sphere.triangleCount());
  // And the same soup as soupVariant(), corner for corner.
  CHECK(faceted.indices == soupVariant(sphere).indices);
}

TEST_CASE("seams splits a sphere along the six box-mapping charts", "[mesh_variants]") {
  const TriangleMesh sphere = makeSphere(0.05f, 3);
  const TriangleMesh seams = seamsVariant(sphere);
  checkVariant(sphere, seams);
  // Only vertices on a chart border are copied: more than before, far fewer than a soup.
  CHECK(seams.vertexCount() > sphere.vertexCount());
  CHECK(seams.vertexCount() < sphere.vertexCount() + sphere.vertexCount() / 2);
}

TEST_CASE("a variant is deterministic and keeps the triangle order", "[mesh_variants]") {
  const TriangleMesh torus = makeTorus();
  for (std::string_view name : meshVariantNames()) {
    INFO(std::string(name));
    const TriangleMesh a = *makeMeshVariant(name, torus);
    const TriangleMesh b = *makeMeshVariant(name, torus);
    CHECK(a.indices == b.indices);
    CHECK(std::memcmp(a.positions.data(), b.positions.data(),
                      a.positions.size() * sizeof(glm::vec3)) == 0);
  }
}
