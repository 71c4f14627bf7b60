#include <catch2/catch.hpp>

#include <unistd.h>
#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "io/mesh_io.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace {

// A folder of its own under the system temp folder, removed with everything in it at the end.
struct TempDir {
  fs::path path;
  TempDir() {
    path = fs::temp_directory_path() / ("sdfg-mesh-io-" + std::to_string(::getpid()));
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  fs::path write(const std::string& name, const std::string& bytes) const {
    const fs::path file = path / name;
    std::ofstream(file, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
    return file;
  }
};

// Golden tetrahedron: dyadic coordinates (exact in decimal text and in float), outward
// counter-clockwise faces.
const std::array<glm::vec3, 4> kTetraPositions = {
    glm::vec3(0.125f, -0.25f, 0.5f), glm::vec3(1.125f, -0.25f, 0.5f),
    glm::vec3(0.125f, 0.75f, 0.5f), glm::vec3(0.125f, -0.25f, 1.5f)};
const std::array<std::array<uint32_t, 3>, 4> kTetraFaces = {
    {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}};

const char* kTetraPlyHeader =
    "element vertex 4\n"
    "property float x\n"
    "property float y\n"
    "property float z\n"
    "element face 4\n"
    "property list uchar int vertex_indices\n"
    "end_header\n";

std::string tetraAsciiPly() {
  return std::string("ply\nformat ascii 1.0\n") + kTetraPlyHeader +
         "0.125 -0.25 0.5\n1.125 -0.25 0.5\n0.125 0.75 0.5\n0.125 -0.25 1.5\n"
         "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
}

std::string tetraBinaryPly(bool bigEndian = false) {
  std::string bytes = std::string("ply\nformat ") +
                      (bigEndian ? "binary_big_endian" : "binary_little_endian") + " 1.0\n" +
                      kTetraPlyHeader;
  // Writes the value's bytes in the file's byte order.
  auto append = [&bytes, bigEndian](auto value) {
    char raw[sizeof(value)];
    std::memcpy(raw, &value, sizeof(value));
    if (bigEndian != (std::endian::native == std::endian::big))
      std::reverse(raw, raw + sizeof(raw));
    bytes.append(raw, sizeof(raw));
  };
  for (const glm::vec3& p : kTetraPositions) {
    for (int k = 0; k < 3; ++k) append(p[k]);
  }
  for (const auto& face : kTetraFaces) {
    append(uint8_t{3});
    for (uint32_t i : face) append(static_cast<int32_t>(i));
  }
  return bytes;
}

// OBJ is 1-based; texture coordinates and normals must not split vertices.
std::string tetraObj() {
  return "# tetrahedron\n"
         "v 0.125 -0.25 0.5\nv 1.125 -0.25 0.5\nv 0.125 0.75 0.5\nv 0.125 -0.25 1.5\n"
         "vt 0 0\nvt 1 0\nvt 0 1\n"
         "vn 0 0 1\n"
         "f 1/1/1 3/3/1 2/2/1\nf 1 2 4\nf 1/1 4/2 3/3\nf 2//1 3//1 4//1\n";
}

// The loaded mesh is the golden tetrahedron: four shared vertices and the same triangles in the
// same order with the same first corner (vertex numbering itself is not part of the contract).
void checkIsTetrahedron(const sdfg::LoadedMesh& loaded) {
  const sdfg::TriangleMesh& mesh = loaded.mesh;
  CHECK(loaded.droppedDegenerate == 0);
  CHECK(mesh.vertexCount() == 4);
  REQUIRE(mesh.triangleCount() == 4);
  for (size_t t = 0; t < 4; ++t) {
    for (size_t c = 0; c < 3; ++c) {
      CAPTURE(t, c);
      CHECK(mesh.positions[mesh.indices[3 * t + c]] == kTetraPositions[kTetraFaces[t][c]]);
    }
  }
}

// Number of triangles using each undirected edge, and whether any directed edge repeats.
struct EdgeUse {
  std::map<size_t, size_t> histogram;  // uses -> number of edges
  bool directedRepeats = false;
};

EdgeUse countEdges(const sdfg::TriangleMesh& mesh) {
  // Sorted lists rather than maps: the shared meshes have up to 1.2 million edge uses.
  std::vector<std::pair<uint32_t, uint32_t>> directed;
  directed.reserve(mesh.indices.size());
  for (size_t t = 0; t < mesh.triangleCount(); ++t) {
    for (int k = 0; k < 3; ++k) {
      directed.emplace_back(mesh.indices[3 * t + k], mesh.indices[3 * t + (k + 1) % 3]);
    }
  }
  std::vector<std::pair<uint32_t, uint32_t>> undirected = directed;
  for (auto& [a, b] : undirected) {
    if (a > b) std::swap(a, b);
  }
  std::sort(directed.begin(), directed.end());
  std::sort(undirected.begin(), undirected.end());
  EdgeUse use;
  use.directedRepeats = std::adjacent_find(directed.begin(), directed.end()) != directed.end();
  for (size_t i = 0; i < undirected.size();) {
    size_t j = i;
    while (j < undirected.size() && undirected[j] == undirected[i]) ++j;
    ++use.histogram[j - i];
    i = j;
  }
  return use;
}

bool messageNames(const sdfg::Error& error, const fs::path& file) {
  return error.message.find(file.filename().string()) != std::string::npos;
}

}  // namespace

TEST_CASE("Small OBJ and PLY files load exactly", "[core][mesh_io]") {
  const TempDir dir;

  SECTION("ASCII PLY") {
    const auto loaded = sdfg::loadMesh(dir.write("tetra-ascii.ply", tetraAsciiPly()));
    REQUIRE(loaded.ok());
    CHECK(loaded->name == "tetra-ascii.ply");
    checkIsTetrahedron(*loaded);
  }
  SECTION("Binary little-endian PLY") {
    const auto loaded = sdfg::loadMesh(dir.write("tetra-binary.PLY", tetraBinaryPly()));
    REQUIRE(loaded.ok());
    checkIsTetrahedron(*loaded);
  }
  SECTION("Binary big-endian PLY") {
    const auto loaded = sdfg::loadMesh(dir.write("tetra-big.ply", tetraBinaryPly(true)));
    REQUIRE(loaded.ok());
    checkIsTetrahedron(*loaded);
  }
  SECTION("PLY with properties and elements that are not positions or faces") {
    const auto loaded = sdfg::loadMesh(dir.write(
        "tetra-extra.ply",
        "ply\r\nformat ascii 1.0\r\ncomment made by hand\r\n"
        "element vertex 4\r\nproperty double x\r\nproperty float nx\r\nproperty double y\r\n"
        "property list uchar float weights\r\nproperty double z\r\n"
        "element face 4\r\nproperty uchar flags\r\nproperty list uint8 uint vertex_index\r\n"
        "element edge 1\r\nproperty int vertex1\r\nproperty int vertex2\r\nend_header\r\n"
        "0.125 7 -0.25 0 0.5\r\n1.125 7 -0.25 2 1 1 0.5\r\n0.125 7 0.75 0 0.5\r\n"
        "0.125 7 -0.25 0 1.5\r\n"
        "0 3 0 2 1\r\n0 3 0 1 3\r\n0 3 0 3 2\r\n0 3 1 2 3\r\n0 1\r\n"));
    REQUIRE(loaded.ok());
    checkIsTetrahedron(*loaded);
  }
  SECTION("A concave polygon is split into triangles inside it") {
    // A hexagon, reflex at its fourth corner, counter-clockwise seen from +z.
    const std::vector<glm::vec2> polygon = {{0, 0}, {4, 0}, {4, 1}, {2, 1.5f}, {2, 3}, {0, 1}};
    std::string obj;
    for (const glm::vec2& p : polygon) {
      obj += "v " + std::to_string(p.x) + " " + std::to_string(p.y) + " 0\n";
    }
    const auto loaded = sdfg::loadMesh(dir.write("concave.obj", obj + "f 1 2 3 4 5 6\n"));
    REQUIRE(loaded.ok());
    const sdfg::TriangleMesh& mesh = loaded->mesh;
    REQUIRE(mesh.triangleCount() == polygon.size() - 2);
    float area = 0.0f;
    for (size_t t = 0; t < mesh.triangleCount(); ++t) {
      const glm::vec3 a = mesh.positions[mesh.indices[3 * t]];
      const glm::vec3 n = glm::cross(mesh.positions[mesh.indices[3 * t + 1]] - a,
                                     mesh.positions[mesh.indices[3 * t + 2]] - a);
      CHECK(n.z > 0.0f);  // none folded over
      area += 0.5f * n.z;
    }
    // Triangles that all keep the winding and add up to the polygon's (shoelace) area cover it.
    float shoelace = 0.0f;
    for (size_t i = 0; i < polygon.size(); ++i) {
      const glm::vec2 p = polygon[i], q = polygon[(i + 1) % polygon.size()];
      shoelace += 0.5f * (p.x * q.y - q.x * p.y);
    }
    CHECK(area == Approx(shoelace).margin(1e-5));
  }
  SECTION("OBJ with texture coordinates and normals") {
    const auto loaded = sdfg::loadMesh(dir.write("tetra.obj", tetraObj()));
    REQUIRE(loaded.ok());
    checkIsTetrahedron(*loaded);
  }
  SECTION("OBJ split into groups is joined into one closed mesh") {
    const auto loaded = sdfg::loadMesh(
        dir.write("groups.obj",
                  "v 0.125 -0.25 0.5\nv 1.125 -0.25 0.5\nv 0.125 0.75 0.5\nv 0.125 -0.25 1.5\n"
                  "o first\ng a\nf 1 3 2\nf 1 2 4\no second\ng b\nf 1 4 3\nf 2 3 4\n"));
    REQUIRE(loaded.ok());
    CHECK(loaded->mesh.vertexCount() == 4);
    CHECK(loaded->mesh.triangleCount() == 4);
    const EdgeUse use = countEdges(loaded->mesh);
    CHECK(use.histogram == std::map<size_t, size_t>{{2, 6}});
    CHECK_FALSE(use.directedRepeats);
  }
  SECTION("A quad is split into two triangles covering it, wound the same way") {
    const auto loaded =
        sdfg::loadMesh(dir.write("quad.obj", "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 0\nf 1 2 3 4\n"));
    REQUIRE(loaded.ok());
    const sdfg::TriangleMesh& mesh = loaded->mesh;
    REQUIRE(mesh.triangleCount() == 2);
    CHECK(mesh.vertexCount() == 4);
    float area = 0.0f;
    for (size_t t = 0; t < 2; ++t) {
      const glm::vec3 a = mesh.positions[mesh.indices[3 * t]];
      const glm::vec3 n = glm::cross(mesh.positions[mesh.indices[3 * t + 1]] - a,
                                     mesh.positions[mesh.indices[3 * t + 2]] - a);
      CHECK(n.z > 0.0f);
      area += 0.5f * n.z;
    }
    CHECK(area == Approx(2.0f).margin(1e-6));
  }
  SECTION("Degenerate triangles and unused vertices are dropped and counted") {
    const auto loaded = sdfg::loadMesh(dir.write(
        "degenerate.obj", tetraObj() +
                              "v 9 9 9\n"            // 5: used by nothing
                              "v 2.125 -0.25 0.5\n"  // 6: on the line through vertices 1 and 2
                              "f 1 2 6\n"            // zero area
                              "f 1 1 2\n"            // repeated index
                              "v 0.125 0.75 0.5\n"   // 7: same position as vertex 3
                              "f 3 7 4\n"));         // repeated after welding
    REQUIRE(loaded.ok());
    CHECK(loaded->droppedDegenerate == 3);
    CHECK(loaded->mesh.vertexCount() == 4);
    CHECK(loaded->mesh.triangleCount() == 4);
  }
}

TEST_CASE("Bad mesh files give an error naming the file, never a crash", "[core][mesh_io]") {
  const TempDir dir;

  SECTION("Missing file") {
    const fs::path file = dir.path / "no-such-mesh.obj";
    const auto loaded = sdfg::loadMesh(file);
    REQUIRE_FALSE(loaded.ok());
    CHECK(loaded.error().code == sdfg::Status::io_error);
    CHECK(messageNames(loaded.error(), file));
  }
  SECTION("A folder is not a mesh file") {
    const auto loaded = sdfg::loadMesh(dir.path);
    REQUIRE_FALSE(loaded.ok());
    CHECK(loaded.error().code == sdfg::Status::io_error);
  }
  SECTION("Unknown extension") {
    const fs::path file = dir.write("tetra.stl", tetraObj());
    const auto loaded = sdfg::loadMesh(file);
    REQUIRE_FALSE(loaded.ok());
    CHECK(loaded.error().code == sdfg::Status::io_error);
    CHECK(messageNames(loaded.error(), file));
    CHECK(loaded.error().message.find(".stl") != std::string::npos);
  }
  SECTION("Empty file") {
    for (const char* name : {"empty.obj", "empty.ply"}) {
      const fs::path file = dir.write(name, "");
      const auto loaded = sdfg::loadMesh(file);
      REQUIRE_FALSE(loaded.ok());
      CHECK(loaded.error().code == sdfg::Status::io_error);
      CHECK(messageNames(loaded.error(), file));
    }
  }
  SECTION("Garbage bytes") {
    std::string garbage;
    uint32_t state = 12345;
    for (int i = 0; i < 4096; ++i) {
      state = state * 1664525u + 1013904223u;  // fixed LCG: the same bytes every run
      garbage.push_back(static_cast<char>(state >> 24));
    }
    for (const char* name : {"garbage.obj", "garbage.ply"}) {
      const fs::path file = dir.write(name, garbage);
      const auto loaded = sdfg::loadMesh(file);
      REQUIRE_FALSE(loaded.ok());
      CHECK(messageNames(loaded.error(), file));
    }
  }
  SECTION("Text without faces") {
    const fs::path file = dir.write("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    const auto loaded = sdfg::loadMesh(file);
    REQUIRE_FALSE(loaded.ok());
    CHECK(loaded.error().code == sdfg::Status::io_error);
    CHECK(loaded.error().message.find("no triangles") != std::string::npos);
  }
  SECTION("Only degenerate triangles") {
    const fs::path file = dir.write("flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
    const auto loaded = sdfg::loadMesh(file);
    REQUIRE_FALSE(loaded.ok());
    CHECK(messageNames(loaded.error(), file));
  }
  SECTION("NaN or infinite vertex") {
    for (const char* value : {"nan", "inf"}) {
      const fs::path file = dir.write(std::string(value) + ".obj", std::string("v ") + value +
                                                                       " 0 0\nv 1 0 0\nv 0 1 0\n"
                                                                       "f 1 2 3\n");
      const auto loaded = sdfg::loadMesh(file);
      REQUIRE_FALSE(loaded.ok());
      CHECK(loaded.error().code == sdfg::Status::invalid_argument);
      CHECK(messageNames(loaded.error(), file));
    }
  }
  SECTION("Face index out of range in a PLY file") {
    std::string ply = tetraAsciiPly();
    ply.replace(ply.rfind("3 1 2 3"), 7, "3 1 2 9");
    const fs::path file = dir.write("out-of-range.ply", ply);
    const auto loaded = sdfg::loadMesh(file);
    REQUIRE_FALSE(loaded.ok());
    CHECK(loaded.error().code == sdfg::Status::invalid_argument);
    CHECK(messageNames(loaded.error(), file));
  }
  SECTION("Face index out of range in an OBJ file") {
    // Assimp's OBJ importer rejects these itself, so they read as parse failures.
    for (const char* face : {"f 1 2 9\n", "f 1 2 -9\n", "f 0 1 2\n"}) {
      const fs::path file = dir.write("out-of-range.obj", std::string("v 0 0 0\nv 1 0 0\n"
                                                                      "v 0 1 0\n") +
                                                              face);
      const auto loaded = sdfg::loadMesh(file);
      CAPTURE(face);
      REQUIRE_FALSE(loaded.ok());
      CHECK(messageNames(loaded.error(), file));
    }
  }
}

TEST_CASE("Truncated files give an error or a valid mesh, never a crash", "[core][mesh_io]") {
  const TempDir dir;
  auto tryEveryLength = [&dir](const std::string& name, const std::string& full) {
    size_t loadedCount = 0;
    for (size_t length = 0; length <= full.size(); ++length) {
      const auto loaded = sdfg::loadMesh(dir.write(name, full.substr(0, length)));
      CAPTURE(length);
      if (loaded.ok()) {
        ++loadedCount;
        CHECK_FALSE(sdfg::validateMesh(loaded->mesh.positions, loaded->mesh.indices));
      } else {
        CHECK_FALSE(loaded.error().message.empty());
      }
    }
    return loadedCount;
  };

  SECTION("Binary PLY") {
    // The whole file must load; the truncations may or may not.
    CHECK(tryEveryLength("truncated.ply", tetraBinaryPly()) >= 1);
  }
  SECTION("OBJ") {
    CHECK(tryEveryLength("truncated.obj", tetraObj()) >= 1);
  }
}

namespace {

// What /work/shared/meshes/README.md documents of one shared mesh.
struct ExpectedCounts {
  const char* file;
  size_t vertices;  // vertices used by triangles, identical positions counted once
  size_t triangles;
  bool watertight;  // every undirected edge used by exactly two triangles
};

// One test case per mesh, skipped (before any assertion) when its file is absent: a case that
// skipped after checking other meshes would report their failures as a skip.
void loadsWithCounts(const ExpectedCounts& expected) {
  const auto path = sdfg::test::sharedMesh(expected.file);
  if (!path) SDFG_SKIP(std::string("shared mesh absent: ") + expected.file);
  const auto loaded = sdfg::loadMesh(*path);
  REQUIRE(loaded.ok());
  CHECK(loaded->name == expected.file);
  CHECK(loaded->mesh.vertexCount() == expected.vertices);
  CHECK(loaded->mesh.triangleCount() == expected.triangles);
  CHECK(loaded->droppedDegenerate == 0);
  CHECK_FALSE(sdfg::validateMesh(loaded->mesh.positions, loaded->mesh.indices));
  if (expected.watertight) {
    const EdgeUse use = countEdges(loaded->mesh);
    CHECK(use.histogram.size() == 1);
    CHECK(use.histogram.count(2) == 1);
    CHECK_FALSE(use.directedRepeats);
  }
}

}  // namespace

// The bunny has 1,113 vertices no face uses (35,947 in the file); the teapot has 403 vertices
// repeating another's position (3,644 in the file).
TEST_CASE("The bunny loads with the documented counts", "[core][mesh_io]") {
  loadsWithCounts({"stanford-bunny.obj", 34834, 69451, false});
}
TEST_CASE("The 100k armadillo loads with the documented counts", "[core][mesh_io]") {
  loadsWithCounts({"stanford-armadillo-100k.obj", 49990, 99976, true});
}
TEST_CASE("The dragon (PLY) loads with the documented counts", "[core][mesh_io]") {
  loadsWithCounts({"stanford-dragon-100k.ply", 50002, 100000, false});
}
TEST_CASE("The dragon (OBJ) loads with the documented counts", "[core][mesh_io]") {
  loadsWithCounts({"stanford-dragon-100k.obj", 50002, 100000, false});
}
TEST_CASE("The 400k armadillo loads with the documented counts", "[core][mesh_io]") {
  loadsWithCounts({"stanford-armadillo-400k-subdiv.obj", 199954, 399904, true});
}
TEST_CASE("Igea loads with the documented counts", "[core][mesh_io]") {
  loadsWithCounts({"igea-268k.obj", 134345, 268686, true});
}
TEST_CASE("The torus loads with the documented counts", "[core][mesh_io]") {
  loadsWithCounts({"torus.obj", 2304, 4608, true});
}
TEST_CASE("The teapot loads with the documented counts", "[core][mesh_io]") {
  loadsWithCounts({"newell-teapot.obj", 3241, 6320, false});
}

TEST_CASE("The PLY and OBJ dragon give the same triangles", "[core][mesh_io]") {
  const auto plyPath = sdfg::test::sharedMesh("stanford-dragon-100k.ply");
  const auto objPath = sdfg::test::sharedMesh("stanford-dragon-100k.obj");
  if (!plyPath || !objPath) SDFG_SKIP("shared dragon meshes absent");

  const auto ply = sdfg::loadMesh(*plyPath);
  const auto obj = sdfg::loadMesh(*objPath);
  REQUIRE(ply.ok());
  REQUIRE(obj.ok());
  REQUIRE(ply->mesh.indices.size() == obj->mesh.indices.size());
  size_t mismatches = 0;
  for (size_t i = 0; i < ply->mesh.indices.size(); ++i) {
    mismatches +=
        ply->mesh.positions[ply->mesh.indices[i]] != obj->mesh.positions[obj->mesh.indices[i]];
  }
  CHECK(mismatches == 0);
  CHECK(ply->mesh.vertexCount() == obj->mesh.vertexCount());
}
