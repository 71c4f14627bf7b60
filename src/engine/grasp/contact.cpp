#include "grasp/contact.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>

#include <glm/geometric.hpp>

namespace sdfg {
namespace {

// A touching sphere this close to its bone's end is that joint's own sphere.
constexpr float kJointEnd = 1e-3f;
// Search bound of the mesh query: a touching sphere's centre is about its radius (under 2 cm)
// from the surface.
constexpr float kNearBound = 0.05f;  // metres

glm::vec3 faceNormal(const TriangleMesh& m, uint32_t triangle) {
  const glm::vec3& a = m.positions[m.indices[3 * size_t(triangle)]];
  const glm::vec3& b = m.positions[m.indices[3 * size_t(triangle) + 1]];
  const glm::vec3& c = m.positions[m.indices[3 * size_t(triangle) + 2]];
  const glm::vec3 n = glm::cross(b - a, c - a);
  const float l = glm::length(n);
  return l > 0.0f ? n / l : glm::vec3(0.0f, 0.0f, 1.0f);
}

}  // namespace

FingerContacts computeContacts(const HandModel& hand, const GraspResult& result,
                               const Pose& objectFromHand, const MeshDistance* mesh,
                               const SdfGrid* field) {
  FingerContacts out{};
  if (mesh == nullptr && field == nullptr) return out;
  const Pose sceneFromHand = result.handCorrection;
  for (int f = 0; f < kFingerCount; ++f) {
    const FingerState& fs = result.fingers[f];
    const std::span<const Joint> joints = fingerJoints(Finger(f));
    const int bones = int(joints.size()) - 1;
    if (!fs.contact || fs.contactBone < 0 || fs.contactBone >= bones) continue;
    FingerContact& c = out[f];
    const int b = fs.contactBone;
    const float t = std::clamp(fs.contactT, 0.0f, 1.0f);
    std::array<Pose, 5> poses{};
    hand.fingerPose(Finger(f), fs.jointCurls, std::span(poses.data(), joints.size()));
    const glm::vec3 centreHand =
        sceneFromHand.transformPoint(glm::mix(poses[b].position, poses[b + 1].position, t));
    c.valid = true;
    c.jointSphere = t >= 1.0f - kJointEnd;
    c.joint = c.jointSphere ? joints[b + 1] : joints[b];
    c.boneFraction = c.jointSphere ? 0.0f : t;
    c.radius = (1.0f - t) * hand.jointRadius(joints[b]) + t * hand.jointRadius(joints[b + 1]);
    c.center = objectFromHand.transformPoint(centreHand);
    if (mesh != nullptr) {
      c.exact = true;
      // A touching sphere is within a few millimetres of the surface: the bounded query with
      // the nearest sheet's sign is cheap (about 1 us, against up to 200 us for the winding
      // number of an open 100k-triangle mesh); beyond the bound, the full query.
      glm::vec3 closest(0.0f);
      uint32_t triangle = 0;
      float d = mesh->localSignedDistanceNear(
          c.center, kNearBound, std::numeric_limits<uint32_t>::max(), &closest, &triangle);
      if (!std::isfinite(d)) {
        const ClosestPoint cp = mesh->closest(c.center);
        d = mesh->signedDistance(c.center) < 0.0f ? -cp.distance : cp.distance;
        closest = cp.point;
        triangle = cp.triangle;
      }
      const float sign = d < 0.0f ? -1.0f : 1.0f;
      c.distance = d;
      c.surfacePoint = closest;
      // Outward: from the surface to an outside centre, from an inside centre to the surface.
      const glm::vec3 away = c.center - closest;
      const float l = glm::length(away);
      c.normal = l > 1e-7f ? sign * away / l : faceNormal(mesh->mesh(), triangle);
    } else {
      const float d = field->sample(centreHand);
      glm::vec3 g = field->gradient(centreHand);
      const float l = glm::length(g);
      g = l > 0.0f ? g / l : glm::vec3(0.0f, 0.0f, 1.0f);
      c.distance = d;
      c.surfacePoint = objectFromHand.transformPoint(centreHand - d * g);
      c.normal = objectFromHand.transformVector(g);
    }
  }
  return out;
}

}  // namespace sdfg
