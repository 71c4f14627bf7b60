#include "outer_scene.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "hand/hand_model.h"
#include "hand/hand_synthesis.h"
#include "io/shapes.h"

namespace sdfg::frame_cost {

Object meshObject(const std::string& name, const TriangleMesh& m) {
  Object o;
  o.name = name;
  for (const glm::vec3& p : m.positions) o.vertices.push_back({p.x, p.y, p.z});
  o.indices = m.indices;
  return o;
}

Pose toPose(const XrPosef& p) {
  return Pose{glm::quat(p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z),
              glm::vec3(p.position.x, p.position.y, p.position.z)};
}

OuterScene outerScene(int room) {
  OuterScene s;
  const HandModel model = HandModel::defaultAdult(Hand::right);
  const Pose grip = toPose(s.grip);
  JointPoses joints;
  JointRadii radii;
  placeJoints(model, curlsFromSqueeze(0.0f, MotionRange::unobstructed),
              grip * wristFromGrip(model).inverse(), joints, radii);
  float lowest = 1e30f;
  for (int j = 0; j < kJointCount; ++j)
    lowest = std::min(lowest, joints[size_t(j)].position.y - radii[size_t(j)]);
  const glm::vec3 palm = joints[size_t(Joint::palm)].position;
  const float top = lowest - s.gap;
  auto place = [&](Object o, const glm::vec3& c) {
    s.objects.push_back(std::move(o));
    s.poses.push_back({{0, 0, 0, 1}, {c.x, c.y, c.z}});
  };
  place(meshObject("table", makeBox(glm::vec3(0.4f, 0.04f, 0.4f))),
        glm::vec3(palm.x, top - 0.02f, palm.z));
  const TriangleMesh small = makeBox(glm::vec3(0.04f));
  for (const glm::vec2 d : {glm::vec2(0.14f, 0.0f), glm::vec2(-0.14f, 0.0f), glm::vec2(0.0f, 0.14f),
                            glm::vec2(0.0f, -0.14f)})
    place(meshObject("block", small), glm::vec3(palm.x + d.x, top + 0.0201f, palm.z + d.y));
  s.inHandBox = int(s.objects.size());
  const TriangleMesh box = makeBox(glm::vec3(0.05f));
  const TriangleMesh ball = makeSphere(0.03f, 1);
  // A grid fine enough for `room` places outside the hand's metre, three shelves high.
  auto places = [&](int n) {
    std::vector<glm::vec3> out;
    for (int y = 0; y < 3; ++y)
      for (int i = 0; i < n; ++i)
        for (int k = 0; k < n; ++k) {
          const glm::vec3 c(-5.0f + 10.0f * (float(i) + 0.5f) / float(n), 0.5f + float(y),
                            -5.0f + 10.0f * (float(k) + 0.5f) / float(n));
          if (glm::length(c - palm) >= 1.0f) out.push_back(c);
        }
    return out;
  };
  const size_t rest = size_t(std::max(0, room - s.inHandBox));
  int side = 2;
  std::vector<glm::vec3> centres = places(side);
  while (centres.size() < rest) centres = places(++side);
  for (size_t added = 0; added < rest; ++added)
    place(meshObject(added % 2 == 0 ? "box" : "ball", added % 2 == 0 ? box : ball), centres[added]);
  return s;
}

XrPosef touchingGrip(const OuterScene& s, int i, int frames) {
  XrPosef g = s.grip;
  const float down = (s.gap + 0.02f) * std::min(1.0f, float(i + 1) / 10.0f);
  g.position.y -= down;
  g.position.x += 0.08f * std::sin(6.2831853f * float(i) / float(frames));
  return g;
}

}  // namespace sdfg::frame_cost
