#include "io/mesh_io.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <fstream>
#include <iterator>
#include <new>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <system_error>
#include <unordered_map>
#include <vector>

#include <assimp/scene.h>
#include <assimp/Importer.hpp>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

namespace sdfg {
namespace {

namespace fs = std::filesystem;

// A file as one indexed triangle list in world space, vertices not yet shared.
struct Flattened {
  std::vector<glm::vec3> positions;
  std::vector<uint32_t> indices;  // three per triangle
};

Error fileError(Status code, const fs::path& path, const std::string& what) {
  return makeError(code, "mesh file '" + path.string() + "': " + what);
}

std::string lowerExtension(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

bool isFinite(const glm::vec3& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

// ---------------------------------------------------------------------------------------------
// Polygons

// Appends the triangles of a polygon (vertex ids into `positions`, in its winding order) to
// `out`, keeping the winding. Triangles pass through; larger polygons are ear-clipped in the
// plane of their Newell normal, so concave ones are split correctly; a polygon with no ear left
// (self-intersecting or degenerate) has its remainder fanned. Fewer than 3 ids: nothing.
void appendPolygon(const std::vector<glm::vec3>& positions, std::span<const uint32_t> polygon,
                   std::vector<uint32_t>& out) {
  const size_t n = polygon.size();
  if (n < 3) return;
  if (n == 3) {
    out.insert(out.end(), polygon.begin(), polygon.end());
    return;
  }
  glm::dvec3 normal(0.0);
  for (size_t i = 0; i < n; ++i) {
    const glm::dvec3 a(positions[polygon[i]]), b(positions[polygon[(i + 1) % n]]);
    normal +=
        glm::dvec3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y));
  }
  // Project by dropping the dominant axis, ordered so the polygon stays counter-clockwise.
  int axis = 0;
  for (int k = 1; k < 3; ++k) {
    if (std::abs(normal[k]) > std::abs(normal[axis])) axis = k;
  }
  int u = (axis + 1) % 3, v = (axis + 2) % 3;
  if (normal[axis] < 0.0) std::swap(u, v);
  std::vector<glm::dvec2> p(n);
  for (size_t i = 0; i < n; ++i) {
    p[i] = glm::dvec2(positions[polygon[i]][u], positions[polygon[i]][v]);
  }
  auto cross = [](const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
  };

  std::vector<size_t> left(n);
  for (size_t i = 0; i < n; ++i) left[i] = i;
  while (left.size() > 3) {
    bool clipped = false;
    for (size_t k = 0; k < left.size() && !clipped; ++k) {
      const size_t a = left[(k + left.size() - 1) % left.size()], b = left[k],
                   c = left[(k + 1) % left.size()];
      if (cross(p[a], p[b], p[c]) <= 0.0) continue;  // reflex or flat corner: not an ear
      bool blocked = false;
      for (size_t other : left) {
        if (other == a || other == b || other == c) continue;
        if (cross(p[a], p[b], p[other]) >= 0.0 && cross(p[b], p[c], p[other]) >= 0.0 &&
            cross(p[c], p[a], p[other]) >= 0.0) {
          blocked = true;
          break;
        }
      }
      if (blocked) continue;
      out.insert(out.end(), {polygon[a], polygon[b], polygon[c]});
      left.erase(left.begin() + static_cast<std::ptrdiff_t>(k));
      clipped = true;
    }
    if (!clipped) break;
  }
  for (size_t k = 1; k + 1 < left.size(); ++k) {
    out.insert(out.end(), {polygon[left[0]], polygon[left[k]], polygon[left[k + 1]]});
  }
}

// ---------------------------------------------------------------------------------------------
// PLY. Read here rather than by Assimp: Assimp 5.2.5's PLY importer loops forever on a header
// without end_header, and fills a truncated ASCII body with made-up faces (then aborts in its
// triangulation step). This reader checks every count against the bytes present.

enum class PlyFormat { ascii, binaryLittleEndian, binaryBigEndian };
enum class PlyType { int8, uint8, int16, uint16, int32, uint32, float32, float64 };

std::optional<PlyType> parsePlyType(std::string_view name) {
  if (name == "char" || name == "int8") return PlyType::int8;
  if (name == "uchar" || name == "uint8") return PlyType::uint8;
  if (name == "short" || name == "int16") return PlyType::int16;
  if (name == "ushort" || name == "uint16") return PlyType::uint16;
  if (name == "int" || name == "int32") return PlyType::int32;
  if (name == "uint" || name == "uint32") return PlyType::uint32;
  if (name == "float" || name == "float32") return PlyType::float32;
  if (name == "double" || name == "float64") return PlyType::float64;
  return std::nullopt;
}

size_t sizeOf(PlyType type) {
  switch (type) {
    case PlyType::int8:
    case PlyType::uint8:
      return 1;
    case PlyType::int16:
    case PlyType::uint16:
      return 2;
    case PlyType::int32:
    case PlyType::uint32:
    case PlyType::float32:
      return 4;
    case PlyType::float64:
      return 8;
  }
  return 1;
}

bool isInteger(PlyType type) {
  return type != PlyType::float32 && type != PlyType::float64;
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::float32;  // of the items, for a list
  bool isList = false;
  PlyType countType = PlyType::uint8;
};

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

std::vector<std::string_view> splitWords(std::string_view line) {
  std::vector<std::string_view> words;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    const size_t start = i;
    while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

// Reads the values of a PLY body one at a time, never past its end. Every value is returned as a
// double, which holds every PLY integer type exactly.
class PlyBodyReader {
 public:
  PlyBodyReader(std::string_view body, PlyFormat format) : body_(body), format_(format) {}

  // False at the end of the data or on text that is not a number of the type.
  bool read(PlyType type, double& value) {
    return format_ == PlyFormat::ascii ? readText(type, value) : readBinary(type, value);
  }
  size_t bytesLeft() const { return body_.size() - offset_; }

 private:
  bool readText(PlyType type, double& value) {
    while (offset_ < body_.size() && std::isspace(static_cast<unsigned char>(body_[offset_]))) {
      ++offset_;
    }
    size_t end = offset_;
    while (end < body_.size() && !std::isspace(static_cast<unsigned char>(body_[end]))) ++end;
    if (end == offset_) return false;
    const char* first = body_.data() + offset_;
    const char* last = body_.data() + end;
    offset_ = end;
    const auto [ptr, ec] = std::from_chars(first, last, value);
    if (ec != std::errc() || ptr != last) return false;
    return !isInteger(type) || (std::isfinite(value) && value == std::floor(value));
  }

  template <class T>
  T take() {
    unsigned char bytes[sizeof(T)];
    std::memcpy(bytes, body_.data() + offset_, sizeof(T));
    offset_ += sizeof(T);
    const bool fileIsLittle = format_ == PlyFormat::binaryLittleEndian;
    if (fileIsLittle != (std::endian::native == std::endian::little)) {
      std::reverse(std::begin(bytes), std::end(bytes));
    }
    T out;
    std::memcpy(&out, bytes, sizeof(T));
    return out;
  }

  bool readBinary(PlyType type, double& value) {
    if (bytesLeft() < sizeOf(type)) return false;
    switch (type) {
      case PlyType::int8:
        value = take<int8_t>();
        break;
      case PlyType::uint8:
        value = take<uint8_t>();
        break;
      case PlyType::int16:
        value = take<int16_t>();
        break;
      case PlyType::uint16:
        value = take<uint16_t>();
        break;
      case PlyType::int32:
        value = take<int32_t>();
        break;
      case PlyType::uint32:
        value = take<uint32_t>();
        break;
      case PlyType::float32:
        value = take<float>();
        break;
      case PlyType::float64:
        value = take<double>();
        break;
    }
    return true;
  }

  std::string_view body_;
  PlyFormat format_;
  size_t offset_ = 0;
};

Result<Flattened> readPly(std::string_view bytes) {
  auto bad = [](std::string what) { return makeError(Status::io_error, "PLY: " + what); };

  // Header: lines up to end_header.
  PlyFormat format = PlyFormat::ascii;
  bool haveFormat = false, haveEnd = false;
  std::vector<PlyElement> elements;
  size_t offset = 0;
  for (size_t lineNo = 0; !haveEnd; ++lineNo) {
    const size_t eol = bytes.find('\n', offset);
    if (eol == std::string_view::npos) return bad("header has no end_header line");
    std::string_view line = bytes.substr(offset, eol - offset);
    offset = eol + 1;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    const auto words = splitWords(line);
    if (lineNo == 0) {
      if (words.size() != 1 || words[0] != "ply") return bad("no 'ply' magic line");
      continue;
    }
    const std::string at = " (header line " + std::to_string(lineNo + 1) + ")";
    if (words.empty() || words[0] == "comment" || words[0] == "obj_info") continue;
    if (words[0] == "end_header") {
      haveEnd = true;
    } else if (words[0] == "format") {
      if (words.size() != 3 || words[2] != "1.0") return bad("bad format line" + at);
      if (words[1] == "ascii") {
        format = PlyFormat::ascii;
      } else if (words[1] == "binary_little_endian") {
        format = PlyFormat::binaryLittleEndian;
      } else if (words[1] == "binary_big_endian") {
        format = PlyFormat::binaryBigEndian;
      } else {
        return bad("unknown format '" + std::string(words[1]) + "'" + at);
      }
      haveFormat = true;
    } else if (words[0] == "element") {
      PlyElement element;
      if (words.size() != 3) return bad("bad element line" + at);
      element.name = words[1];
      const auto [ptr, ec] =
          std::from_chars(words[2].data(), words[2].data() + words[2].size(), element.count);
      if (ec != std::errc() || ptr != words[2].data() + words[2].size()) {
        return bad("bad element count" + at);
      }
      elements.push_back(std::move(element));
    } else if (words[0] == "property") {
      if (elements.empty()) return bad("property before any element" + at);
      PlyProperty property;
      std::optional<PlyType> type, countType;
      if (words.size() == 5 && words[1] == "list") {
        countType = parsePlyType(words[2]);
        type = parsePlyType(words[3]);
        property.isList = true;
        if (countType && !isInteger(*countType)) return bad("list count is not an integer" + at);
      } else if (words.size() == 3) {
        type = parsePlyType(words[1]);
        countType = PlyType::uint8;
      }
      if (!type || !countType) return bad("bad property line" + at);
      property.type = *type;
      property.countType = *countType;
      property.name = words.back();
      elements.back().properties.push_back(std::move(property));
    } else {
      return bad("unknown header keyword '" + std::string(words[0]) + "'" + at);
    }
  }
  if (!haveFormat) return bad("header has no format line");

  // Body: every element in header order; only vertex x, y, z and face vertex indices are kept.
  PlyBodyReader reader(bytes.substr(offset), format);
  Flattened out;
  std::vector<uint32_t> polygonIds;   // all face lists, back to back
  std::vector<size_t> polygonStarts;  // where each face begins in polygonIds
  bool haveVertices = false, haveFaces = false;
  for (const PlyElement& element : elements) {
    const bool isVertex = element.name == "vertex" && !haveVertices;
    const bool isFace = element.name == "face" && !haveFaces;
    int xyz[3] = {-1, -1, -1};
    int faceList = -1;
    for (size_t i = 0; i < element.properties.size(); ++i) {
      const PlyProperty& property = element.properties[i];
      if (isVertex && !property.isList) {
        for (int k = 0; k < 3; ++k) {
          if (property.name == std::string(1, char('x' + k))) xyz[k] = static_cast<int>(i);
        }
      }
      if (isFace && property.isList &&
          (property.name == "vertex_indices" || property.name == "vertex_index")) {
        faceList = static_cast<int>(i);
      }
    }
    if (isVertex && (xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0)) {
      return bad("vertex element lacks an x, y or z property");
    }
    if (isFace && faceList < 0) return bad("face element has no vertex_indices list");
    haveVertices |= isVertex;
    haveFaces |= isFace;

    // Each instance takes at least one byte (binary) or character (ASCII), so a count beyond the
    // bytes left is truncation; checking here keeps a lying header from reserving gigabytes.
    if (!element.properties.empty() && element.count > reader.bytesLeft()) {
      return bad("file ends before its " + std::to_string(element.count) + " '" + element.name +
                 "' elements");
    }
    if (isVertex) out.positions.reserve(element.count);
    if (isFace) polygonStarts.reserve(element.count);
    for (uint64_t n = 0; n < element.count; ++n) {
      const std::string which = "'" + element.name + "' element " + std::to_string(n);
      glm::vec3 position(0.0f);
      for (size_t i = 0; i < element.properties.size(); ++i) {
        const PlyProperty& property = element.properties[i];
        double value = 0.0;
        if (!property.isList) {
          if (!reader.read(property.type, value)) return bad("truncated or bad value in " + which);
          for (int k = 0; k < 3; ++k) {
            if (xyz[k] == static_cast<int>(i)) position[k] = static_cast<float>(value);
          }
          continue;
        }
        double length = 0.0;
        if (!reader.read(property.countType, length) || length < 0.0) {
          return bad("truncated or bad list length in " + which);
        }
        const bool keep = isFace && faceList == static_cast<int>(i);
        if (keep) polygonStarts.push_back(polygonIds.size());
        for (double item = 0; item < length; ++item) {
          if (!reader.read(property.type, value)) return bad("truncated or bad list in " + which);
          if (!keep) continue;
          if (value < 0.0 || value > double(UINT32_MAX)) {
            return makeError(Status::invalid_argument,
                             "PLY: " + which + " has vertex index " + std::to_string(value));
          }
          polygonIds.push_back(static_cast<uint32_t>(value));
        }
      }
      if (isVertex) {
        if (!isFinite(position)) {
          return makeError(Status::invalid_argument, "PLY: vertex " + std::to_string(n) +
                                                         " has a NaN or infinite coordinate");
        }
        out.positions.push_back(position);
      }
    }
  }

  for (size_t f = 0; f < polygonStarts.size(); ++f) {
    const size_t end = f + 1 < polygonStarts.size() ? polygonStarts[f + 1] : polygonIds.size();
    const std::span<const uint32_t> polygon(polygonIds.data() + polygonStarts[f],
                                            end - polygonStarts[f]);
    for (uint32_t id : polygon) {
      if (id >= out.positions.size()) {
        return makeError(Status::invalid_argument,
                         "PLY: face " + std::to_string(f) + " refers to vertex " +
                             std::to_string(id) + ", but there are " +
                             std::to_string(out.positions.size()) + " vertices");
      }
    }
    appendPolygon(out.positions, polygon, out.indices);
  }
  return out;
}

Result<Flattened> readPlyFile(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return makeError(Status::io_error, "cannot open for reading");
  std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  if (file.bad()) return makeError(Status::io_error, "read error");
  return readPly(bytes);
}

// ---------------------------------------------------------------------------------------------
// OBJ, through Assimp. No post-processing step is asked for: Debian's Assimp keeps its internal
// asserts on and aborts the process when a step meets a malformed mesh, so the scene is checked
// and triangulated here instead.

// Checks what would otherwise be read blindly: face indices in range and finite coordinates.
std::optional<Error> checkScene(const aiScene& scene) {
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh& mesh = *scene.mMeshes[m];
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      const aiVector3D& p = mesh.mVertices[v];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        return makeError(Status::invalid_argument,
                         "a vertex has a NaN or infinite coordinate (vertex " + std::to_string(v) +
                             " of imported mesh " + std::to_string(m) + ")");
      }
    }
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices > 0 && face.mIndices == nullptr) {
        return makeError(Status::io_error, "face " + std::to_string(f) + " has no indices");
      }
      for (unsigned i = 0; i < face.mNumIndices; ++i) {
        if (face.mIndices[i] >= mesh.mNumVertices) {
          return makeError(Status::invalid_argument,
                           "face " + std::to_string(f) + " refers to vertex " +
                               std::to_string(face.mIndices[i]) + ", but there are " +
                               std::to_string(mesh.mNumVertices) + " vertices");
        }
      }
    }
  }
  return std::nullopt;
}

// Appends every polygon of every mesh reachable from `node`, in world space. Points and lines
// are not surface and are skipped.
void flatten(const aiScene& scene, const aiNode& node, const aiMatrix4x4& parent, Flattened& out,
             int depth) {
  // A corrupt file could describe an absurdly deep hierarchy; stop rather than overflow.
  if (depth > 256) return;
  const aiMatrix4x4 world = parent * node.mTransformation;
  const bool identity = world.IsIdentity();
  for (unsigned n = 0; n < node.mNumMeshes; ++n) {
    if (node.mMeshes[n] >= scene.mNumMeshes) continue;
    const aiMesh& mesh = *scene.mMeshes[node.mMeshes[n]];
    const auto base = static_cast<uint32_t>(out.positions.size());
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      // Identity is skipped so the file's float values reach the mesh bit for bit.
      const aiVector3D p = identity ? mesh.mVertices[v] : world * mesh.mVertices[v];
      out.positions.emplace_back(p.x, p.y, p.z);
    }
    std::vector<uint32_t> polygon;
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      polygon.assign(face.mIndices, face.mIndices + face.mNumIndices);
      for (uint32_t& id : polygon) id += base;
      appendPolygon(out.positions, polygon, out.indices);
    }
  }
  for (unsigned c = 0; c < node.mNumChildren; ++c) {
    if (node.mChildren[c] != nullptr) flatten(scene, *node.mChildren[c], world, out, depth + 1);
  }
}

Result<Flattened> readObjFile(const fs::path& path) {
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(path.string(), 0);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    return makeError(Status::io_error, std::string("parse failed: ") + importer.GetErrorString());
  }
  if (auto error = checkScene(*scene)) return *error;
  Flattened out;
  flatten(*scene, *scene->mRootNode, aiMatrix4x4(), out, 0);
  return out;
}

// ---------------------------------------------------------------------------------------------
// Welding

// Key for vertices with bit-identical positions. -0 and +0 are the same point, so they are
// folded together before the bits are taken.
struct PositionKey {
  uint32_t bits[3];
  bool operator==(const PositionKey& o) const {
    return bits[0] == o.bits[0] && bits[1] == o.bits[1] && bits[2] == o.bits[2];
  }
};

PositionKey keyOf(const glm::vec3& p) {
  PositionKey key{};
  for (int i = 0; i < 3; ++i) {
    const float v = p[i] == 0.0f ? 0.0f : p[i];
    std::memcpy(&key.bits[i], &v, sizeof(float));
  }
  return key;
}

struct PositionKeyHash {
  size_t operator()(const PositionKey& k) const {
    uint64_t h = 0x9E3779B97F4A7C15ull;
    for (uint32_t b : k.bits) h = (h ^ b) * 0xBF58476D1CE4E5B9ull;
    return static_cast<size_t>(h ^ (h >> 31));
  }
};

// Welds vertices with bit-identical positions into one (Assimp's OBJ importer gives every face
// corner its own vertex, and separate meshes of one file share none), drops triangles that
// repeat a vertex or have zero area, and drops vertices no triangle uses. Vertices keep the order
// of their first appearance, which for PLY is the file's order. Exact equality, not a tolerance:
// joining merely close vertices would change the surface.
LoadedMesh weld(const Flattened& flat) {
  std::unordered_map<PositionKey, uint32_t, PositionKeyHash> ids;
  ids.reserve(flat.positions.size());
  std::vector<uint32_t> weldedId(flat.positions.size());
  std::vector<glm::vec3> unique;
  for (size_t v = 0; v < flat.positions.size(); ++v) {
    const auto [it, inserted] =
        ids.try_emplace(keyOf(flat.positions[v]), static_cast<uint32_t>(unique.size()));
    if (inserted) unique.push_back(flat.positions[v]);
    weldedId[v] = it->second;
  }

  LoadedMesh out;
  std::vector<uint32_t> kept;
  kept.reserve(flat.indices.size());
  std::vector<char> used(unique.size(), 0);
  for (size_t t = 0; t < flat.indices.size() / 3; ++t) {
    const uint32_t a = weldedId[flat.indices[3 * t]];
    const uint32_t b = weldedId[flat.indices[3 * t + 1]];
    const uint32_t c = weldedId[flat.indices[3 * t + 2]];
    // Same zero-area test as validateMesh: an exactly zero cross product in double precision.
    const glm::dvec3 pa(unique[a]), pb(unique[b]), pc(unique[c]);
    const glm::dvec3 n = glm::cross(pb - pa, pc - pa);
    if (a == b || b == c || a == c || (n.x == 0.0 && n.y == 0.0 && n.z == 0.0)) {
      ++out.droppedDegenerate;
      continue;
    }
    kept.insert(kept.end(), {a, b, c});
    used[a] = used[b] = used[c] = 1;
  }

  std::vector<uint32_t> compact(unique.size(), 0);
  for (size_t v = 0; v < unique.size(); ++v) {
    if (!used[v]) continue;
    compact[v] = static_cast<uint32_t>(out.mesh.positions.size());
    out.mesh.positions.push_back(unique[v]);
  }
  out.mesh.indices.reserve(kept.size());
  for (uint32_t v : kept) out.mesh.indices.push_back(compact[v]);
  return out;
}

Result<LoadedMesh> load(const fs::path& path, bool isPly) {
  Result<Flattened> flat = isPly ? readPlyFile(path) : readObjFile(path);
  if (!flat.ok()) return fileError(flat.error().code, path, flat.error().message);
  if (flat->indices.empty()) return fileError(Status::io_error, path, "no triangles");

  LoadedMesh loaded = weld(*flat);
  if (loaded.mesh.indices.empty()) {
    return fileError(Status::io_error, path,
                     "no triangles with non-zero area (" +
                         std::to_string(loaded.droppedDegenerate) + " degenerate)");
  }
  if (auto error = validateMesh(loaded.mesh.positions, loaded.mesh.indices)) {
    return fileError(error->code, path, error->message);
  }
  loaded.name = path.filename().string();
  return loaded;
}

}  // namespace

Result<LoadedMesh> loadMesh(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return fileError(Status::io_error, path, "file not found");
  if (!fs::is_regular_file(path, ec)) {
    return fileError(Status::io_error, path, "not a regular file");
  }
  const std::string ext = lowerExtension(path);
  if (ext != ".obj" && ext != ".ply") {
    return fileError(Status::io_error, path,
                     "unknown format '" + ext + "' (supported: .obj, .ply)");
  }
  const auto size = fs::file_size(path, ec);
  if (ec) return fileError(Status::io_error, path, "cannot read its size: " + ec.message());
  if (size == 0) return fileError(Status::io_error, path, "empty file");

  // Assimp reports parse errors through a null scene, but nothing may escape this function
  // whatever the file holds.
  try {
    return load(path, ext == ".ply");
  } catch (const std::bad_alloc&) {
    return fileError(Status::out_of_memory, path, "out of memory while loading");
  } catch (const std::exception& e) {
    return fileError(Status::io_error, path, std::string("parse failed: ") + e.what());
  } catch (...) {
    return fileError(Status::io_error, path, "parse failed (unknown error)");
  }
}

}  // namespace sdfg
