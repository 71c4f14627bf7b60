#include "eval/approaching.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>
#include <glm/vector_relational.hpp>

namespace sdfg {
namespace {

// A unit vector perpendicular to n, the same way as placements.cpp.
glm::vec3 perpendicular(const glm::vec3& n) {
  const glm::vec3 axis = std::abs(n.x) < 0.6f   ? glm::vec3(1, 0, 0)
                         : std::abs(n.y) < 0.6f ? glm::vec3(0, 1, 0)
                                                : glm::vec3(0, 0, 1);
  return glm::normalize(glm::cross(n, axis));
}

}  // namespace

float handPenetrationMm(const ExactMeshQuery& query, const HandModel& hand,
                        const Pose& objectFromHand,
                        const std::array<JointCurls, kFingerCount>& curls,
                        const Pose& handCorrection) {
  const Pose objectFromShown = objectFromHand * handCorrection;
  std::vector<glm::vec3> points;
  std::vector<float> radii;
  JointPoses open;
  hand.pose(FingerCurls{}, open);
  points.push_back(objectFromShown.transformPoint(open[size_t(Joint::palm)].position));
  radii.push_back(hand.jointRadius(Joint::palm));
  std::array<Pose, 5> poses{};
  for (int f = 0; f < kFingerCount; ++f) {
    const std::span<const Joint> chain = fingerJoints(Finger(f));
    hand.fingerPose(Finger(f), curls[f], std::span(poses.data(), chain.size()));
    for (size_t j = 0; j + 1 < chain.size(); ++j) {
      const glm::vec3 a = objectFromShown.transformPoint(poses[j].position);
      const glm::vec3 b = objectFromShown.transformPoint(poses[j + 1].position);
      const float ra = hand.jointRadius(chain[j]), rb = hand.jointRadius(chain[j + 1]);
      const int n = std::max(1, int(std::ceil(glm::length(b - a) / kCapsuleSampleSpacing)));
      for (int k = j == 0 ? 0 : 1; k <= n; ++k) {
        const float t = float(k) / float(n);
        points.push_back(a + (b - a) * t);
        radii.push_back(ra + (rb - ra) * t);
      }
    }
  }
  std::vector<double> d(points.size());
  query.signedDistances(points, d);
  double deepest = 0.0;
  for (size_t i = 0; i < points.size(); ++i) deepest = std::max(deepest, double(radii[i]) - d[i]);
  return float(deepest * 1000.0);
}

float graspPenetrationMm(const ExactMeshQuery& query, const HandModel& hand,
                         const Pose& objectFromHand, const GraspResult& grasp) {
  std::array<JointCurls, kFingerCount> curls{};
  for (int f = 0; f < kFingerCount; ++f) curls[f] = grasp.fingers[f].jointCurls;
  return handPenetrationMm(query, hand, objectFromHand, curls, grasp.handCorrection);
}

std::vector<ApproachPlacement> generateApproachingPlacements(const TriangleMesh& normalizedMesh,
                                                             const ExactMeshQuery& query,
                                                             const HandModel& hand,
                                                             const GridBox& box, int count,
                                                             uint64_t seed) {
  std::vector<ApproachPlacement> out;
  const size_t triangles = normalizedMesh.triangleCount();
  if (count <= 0 || triangles == 0) return out;
  std::vector<double> cumulative(triangles);
  double total = 0.0;
  for (size_t t = 0; t < triangles; ++t) {
    const glm::dvec3 a(normalizedMesh.positions[normalizedMesh.indices[3 * t]]);
    const glm::dvec3 b(normalizedMesh.positions[normalizedMesh.indices[3 * t + 1]]);
    const glm::dvec3 c(normalizedMesh.positions[normalizedMesh.indices[3 * t + 2]]);
    total += 0.5 * glm::length(glm::cross(b - a, c - a));
    cumulative[t] = total;
  }
  if (!(total > 0.0)) return out;
  JointPoses openPose;
  hand.pose(FingerCurls{}, openPose);
  const Pose palmFromHand = openPose[size_t(Joint::palm)].inverse();
  const std::array<JointCurls, kFingerCount> openCurls{};

  std::mt19937_64 rng(seed);
  const long long maxAttempts = (long long)kPlacementAttemptsPerPlacement * count;
  for (long long attempt = 0; attempt < maxAttempts && int(out.size()) < count; ++attempt) {
    const double uTriangle = uniform01(rng());
    const double u1 = uniform01(rng());
    const double u2 = uniform01(rng());
    const double uDistance = uniform01(rng());
    const double uRoll = uniform01(rng());
    const size_t t = std::min<size_t>(
        size_t(std::upper_bound(cumulative.begin(), cumulative.end(), uTriangle * total) -
               cumulative.begin()),
        triangles - 1);
    const glm::vec3 a = normalizedMesh.positions[normalizedMesh.indices[3 * t]];
    const glm::vec3 b = normalizedMesh.positions[normalizedMesh.indices[3 * t + 1]];
    const glm::vec3 c = normalizedMesh.positions[normalizedMesh.indices[3 * t + 2]];
    const double s = std::sqrt(u1);
    const float wa = float(1.0 - s), wb = float(s * (1.0 - u2)), wc = float(s * u2);
    const glm::vec3 point = a * wa + b * wb + c * wc;
    const glm::vec3 cross = glm::cross(b - a, c - a);
    const float crossLength = glm::length(cross);
    if (!(crossLength > 0.0f)) continue;
    const glm::vec3 n = cross / crossLength;
    const float distance = float(kApproachMinPalmDistance +
                                 (kApproachMaxPalmDistance - kApproachMinPalmDistance) * uDistance);
    const double roll = 2.0 * std::numbers::pi * uRoll;
    const glm::vec3 t0 = perpendicular(n);
    const glm::vec3 t1 = glm::cross(n, t0);
    const glm::vec3 forward = float(std::cos(roll)) * t0 + float(std::sin(roll)) * t1;
    const glm::mat3 rotation(glm::cross(n, forward), n, forward);
    const Pose objectFromPalm{glm::normalize(glm::quat_cast(rotation)), point + n * distance};
    const Pose objectFromHand = objectFromPalm * palmFromHand;
    const glm::vec3 uvw = box.handToNormalized(objectFromHand.inverse().transformPoint(point));
    if (glm::any(glm::lessThan(uvw, glm::vec3(0.0f))) ||
        glm::any(glm::greaterThan(uvw, glm::vec3(1.0f))))
      continue;
    ApproachPlacement p;
    p.placement = Placement{objectFromHand, point, n, distance};
    p.openPenetrationMm = handPenetrationMm(query, hand, objectFromHand, openCurls);
    p.openInside = p.openPenetrationMm > 0.0f;
    out.push_back(p);
  }
  return out;
}

}  // namespace sdfg
