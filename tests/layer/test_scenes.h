// Scenes of the grasp tests: meshes in OpenXR types, where the grab box of a controller-driven
// hand lies (from the core's hand model, the same one the layer uses), and exact distances.
#pragma once

#include <openxr/openxr.h>

#include <cmath>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "hand_model.h"
#include "hand_synthesis.h"
#include "mesh.h"
#include "mesh_distance.h"
#include "sdf_grid.h"
#include "test_support.h"

namespace sdfg::test {

struct TestMesh {
  std::vector<XrVector3f> vertices;
  std::vector<uint32_t> indices;
};

inline Pose toPose(const XrPosef& p) {
  return Pose{glm::quat(p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z),
              glm::vec3(p.position.x, p.position.y, p.position.z)};
}

// Centre of the default grab box of a controller-driven hand whose grip pose is `grip` (LOCAL).
inline XrVector3f boxCentreInLocal(const XrPosef& grip, bool right) {
  const HandModel model = HandModel::defaultAdult(right ? Hand::right : Hand::left);
  const Pose worldFromWrist = toPose(grip) * wristFromGrip(model).inverse();
  const glm::vec3 c =
      worldFromWrist.transformPoint(GridBox::referenceDefault().handFromBox.position);
  return {c.x, c.y, c.z};
}

// Octahedron subdivided `levels` times, projected onto the sphere.
inline TestMesh makeIcosphere(float radius, int levels) {
  std::vector<glm::vec3> v = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  std::vector<uint32_t> f = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4,
                             2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
  for (int l = 0; l < levels; ++l) {
    std::vector<uint32_t> next;
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
    auto midpoint = [&](uint32_t a, uint32_t b) {
      auto k = std::minmax(a, b);
      auto it = mid.find(k);
      if (it != mid.end()) return it->second;
      v.push_back(glm::normalize(v[a] + v[b]));
      return mid[k] = uint32_t(v.size() - 1);
    };
    for (size_t t = 0; t < f.size(); t += 3) {
      const uint32_t a = f[t], b = f[t + 1], c = f[t + 2];
      const uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      next.insert(next.end(), {a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca});
    }
    f = next;
  }
  TestMesh m;
  for (const auto& p : v) m.vertices.push_back({p.x * radius, p.y * radius, p.z * radius});
  m.indices = f;
  return m;
}

// Torus around the Z axis.
inline TestMesh makeTorus(float major, float minor, int ring, int tube) {
  TestMesh m;
  for (int i = 0; i < ring; ++i) {
    const float u = 2.0f * float(M_PI) * i / ring;
    for (int j = 0; j < tube; ++j) {
      const float w = 2.0f * float(M_PI) * j / tube;
      const float r = major + minor * std::cos(w);
      m.vertices.push_back({r * std::cos(u), r * std::sin(u), minor * std::sin(w)});
    }
  }
  for (int i = 0; i < ring; ++i) {
    for (int j = 0; j < tube; ++j) {
      const uint32_t a = i * tube + j, b = ((i + 1) % ring) * tube + j;
      const uint32_t c = ((i + 1) % ring) * tube + (j + 1) % tube, d = i * tube + (j + 1) % tube;
      m.indices.insert(m.indices.end(), {a, b, c, a, c, d});
    }
  }
  return m;
}

inline float torusDistance(const XrPosef& pose, float major, float minor, const XrVector3f& p) {
  const glm::vec3 q = toPose(pose).inverse().transformPoint(glm::vec3(p.x, p.y, p.z));
  const float rho = std::sqrt(q.x * q.x + q.y * q.y) - major;
  return std::sqrt(rho * rho + q.z * q.z) - minor;
}

// Reads "v" and "f" lines of an OBJ under ../shared/meshes; false when it is absent.
inline bool loadSharedObj(const char* name, TestMesh& out) {
  const auto path = sharedMesh(name);
  if (!path) return false;
  std::ifstream in(*path);
  if (!in) return false;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string tag;
    s >> tag;
    if (tag == "v") {
      XrVector3f v;
      s >> v.x >> v.y >> v.z;
      out.vertices.push_back(v);
    } else if (tag == "f") {
      std::vector<uint32_t> face;
      std::string w;
      while (s >> w) face.push_back(uint32_t(std::stoul(w.substr(0, w.find('/')))) - 1);
      for (size_t k = 1; k + 1 < face.size(); ++k)
        out.indices.insert(out.indices.end(), {face[0], face[k], face[k + 1]});
    }
  }
  return !out.indices.empty();
}

inline void centreMesh(TestMesh& m) {
  glm::vec3 lo(1e9f), hi(-1e9f);
  for (const auto& v : m.vertices) {
    lo = glm::min(lo, glm::vec3(v.x, v.y, v.z));
    hi = glm::max(hi, glm::vec3(v.x, v.y, v.z));
  }
  const glm::vec3 c = (lo + hi) * 0.5f;
  for (auto& v : m.vertices) v = {v.x - c.x, v.y - c.y, v.z - c.z};
}

// Exact signed distance of a placed mesh (the core's MeshDistance: exact closest point).
class ExactDistance {
 public:
  ExactDistance(const TestMesh& m, const XrPosef& pose) : objectFromLocal_(toPose(pose).inverse()) {
    TriangleMesh mesh;
    for (const auto& v : m.vertices) mesh.positions.emplace_back(v.x, v.y, v.z);
    mesh.indices = m.indices;
    auto made = MeshDistance::create(mesh);
    if (made) distance_ = std::move(*made);
  }
  float operator()(const XrVector3f& p) const {
    if (distance_ == nullptr) return -1.0f;
    return distance_->signedDistance(objectFromLocal_.transformPoint(glm::vec3(p.x, p.y, p.z)));
  }

 private:
  Pose objectFromLocal_;
  std::unique_ptr<MeshDistance> distance_;
};

}  // namespace sdfg::test
