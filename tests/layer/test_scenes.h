// Scenes of the grasp tests: meshes in OpenXR types, where the grab box of a controller-driven
// hand lies (from the core's hand model, the same one the layer uses), and exact distances.
#pragma once

#include <openxr/openxr.h>

#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "hand/hand_model.h"
#include "hand/hand_synthesis.h"
#include "io/mesh_io.h"
#include "io/shapes.h"
#include "mesh/mesh.h"
#include "mesh/mesh_distance.h"
#include "sdf/sdf_grid.h"
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

// A core mesh in OpenXR types.
inline TestMesh toTestMesh(const TriangleMesh& m) {
  TestMesh out;
  for (const glm::vec3& p : m.positions) out.vertices.push_back({p.x, p.y, p.z});
  out.indices = m.indices;
  return out;
}

// A sphere (the core's subdivided icosahedron) of `radius`.
inline TestMesh makeIcosphere(float radius, int levels) {
  return toTestMesh(makeSphere(radius, levels));
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

// Loads a mesh under ../shared/meshes with the core's loader; false when it is absent.
inline bool loadSharedObj(const char* name, TestMesh& out) {
  const auto path = sharedMesh(name);
  if (!path) return false;
  auto loaded = loadMesh(*path);
  if (!loaded) return false;
  out = toTestMesh(loaded->mesh);
  return true;
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
