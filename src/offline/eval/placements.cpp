#include "eval/placements.h"

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

constexpr float kOpenHandSampleSpacing = 0.002f;

void appendSegment(const glm::vec3& a, const glm::vec3& b, float ra, float rb,
                   std::vector<glm::vec3>& points, std::vector<float>& radii) {
  const int n = std::max(1, int(std::ceil(glm::length(b - a) / kOpenHandSampleSpacing)));
  for (int k = 0; k <= n; ++k) {
    const float t = float(k) / float(n);
    points.push_back(a + (b - a) * t);
    radii.push_back(ra + (rb - ra) * t);
  }
}

// A unit vector perpendicular to n, chosen the same way every time for the same n.
glm::vec3 perpendicular(const glm::vec3& n) {
  const glm::vec3 axis = std::abs(n.x) < 0.6f   ? glm::vec3(1, 0, 0)
                         : std::abs(n.y) < 0.6f ? glm::vec3(0, 1, 0)
                                                : glm::vec3(0, 0, 1);
  return glm::normalize(glm::cross(n, axis));
}

}  // namespace

bool openHandIntersects(const ExactMeshQuery& query, const HandModel& hand,
                        const Pose& objectFromHand) {
  JointPoses joints;
  hand.pose(FingerCurls{}, joints);
  std::vector<glm::vec3> points;
  std::vector<float> radii;
  auto at = [&](Joint j) { return objectFromHand.transformPoint(joints[size_t(j)].position); };
  for (Joint j : {Joint::palm, Joint::wrist}) {
    points.push_back(at(j));
    radii.push_back(hand.jointRadius(j));
  }
  for (int f = 0; f < kFingerCount; ++f) {
    const std::span<const Joint> chain = fingerJoints(Finger(f));
    // Wrist to metacarpal base, then along every bone to the tip: the palm and the whole finger.
    appendSegment(at(Joint::wrist), at(chain[0]), hand.jointRadius(Joint::wrist),
                  hand.jointRadius(chain[0]), points, radii);
    for (size_t j = 0; j + 1 < chain.size(); ++j) {
      appendSegment(at(chain[j]), at(chain[j + 1]), hand.jointRadius(chain[j]),
                    hand.jointRadius(chain[j + 1]), points, radii);
    }
  }
  return query.anyWithin(points, radii);
}

std::vector<Placement> generatePlacements(const TriangleMesh& normalizedMesh,
                                          const ExactMeshQuery& query, const HandModel& hand,
                                          const GridBox& box, int count, uint64_t seed,
                                          PlacementStats* stats) {
  return generatePlacements(normalizedMesh, query, hand, box, count, seed, nullptr, stats);
}

std::vector<Placement> generatePlacements(const TriangleMesh& normalizedMesh,
                                          const ExactMeshQuery& query, const HandModel& hand,
                                          const GridBox& box, int count, uint64_t seed,
                                          const std::function<bool(const Pose&)>& alsoRejects,
                                          PlacementStats* stats) {
  PlacementStats local;
  PlacementStats& st = stats ? *stats : local;
  st = PlacementStats{};
  std::vector<Placement> out;
  const size_t triangles = normalizedMesh.triangleCount();
  if (count <= 0 || triangles == 0) return out;

  // Cumulative areas in double: 400k small triangles summed in float would lose the tail.
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
  const Pose handFromPalm = openPose[size_t(Joint::palm)];
  const Pose palmFromHand = handFromPalm.inverse();

  std::mt19937_64 rng(seed);
  const long long maxAttempts = (long long)kPlacementAttemptsPerPlacement * count;
  for (long long attempt = 0; attempt < maxAttempts && int(out.size()) < count; ++attempt) {
    ++st.attempts;
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
    // Uniform over the triangle: the square root keeps the density even toward vertex a's side.
    const double s = std::sqrt(u1);
    const float wa = float(1.0 - s), wb = float(s * (1.0 - u2)), wc = float(s * u2);
    const glm::vec3 point = a * wa + b * wb + c * wc;
    const glm::vec3 cross = glm::cross(b - a, c - a);
    const float crossLength = glm::length(cross);
    if (!(crossLength > 0.0f)) continue;
    const glm::vec3 n = cross / crossLength;

    const float distance =
        float(kMinPalmDistance + (kMaxPalmDistance - kMinPalmDistance) * uDistance);
    const double roll = 2.0 * std::numbers::pi * uRoll;
    const glm::vec3 t0 = perpendicular(n);
    const glm::vec3 t1 = glm::cross(n, t0);
    const glm::vec3 forward = float(std::cos(roll)) * t0 + float(std::sin(roll)) * t1;
    // Palm +Y (back of the hand) along n, so its palm side (-Y) faces the surface; X = Y x Z.
    const glm::mat3 rotation(glm::cross(n, forward), n, forward);
    const Pose objectFromPalm{glm::normalize(glm::quat_cast(rotation)), point + n * distance};
    const Pose objectFromHand = objectFromPalm * palmFromHand;

    const glm::vec3 uvw = box.handToNormalized(objectFromHand.inverse().transformPoint(point));
    if (glm::any(glm::lessThan(uvw, glm::vec3(0.0f))) ||
        glm::any(glm::greaterThan(uvw, glm::vec3(1.0f)))) {
      ++st.outsideBox;
      continue;
    }
    if (openHandIntersects(query, hand, objectFromHand) ||
        (alsoRejects && alsoRejects(objectFromHand))) {
      ++st.handIntersecting;
      continue;
    }
    out.push_back(Placement{objectFromHand, point, n, distance});
  }
  return out;
}

}  // namespace sdfg
