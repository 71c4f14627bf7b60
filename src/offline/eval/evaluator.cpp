#include "eval/evaluator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

namespace sdfg {

namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Point3 = Kernel::Point_3;
using Vector3 = Kernel::Vector_3;
using Ray3 = Kernel::Ray_3;
using Triangle3 = Kernel::Triangle_3;
using Triangles = std::vector<Triangle3>;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, Triangles::const_iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

Point3 toPoint(const glm::vec3& p) {
  return Point3(p.x, p.y, p.z);
}

// Directions spread over the sphere (a Fibonacci spiral) and turned off the coordinate axes and
// planes, so no ray runs along the axis-aligned faces and edges that procedural meshes are full of.
std::array<Vector3, ExactMeshQuery::kInsideRays> rayDirections() {
  std::array<Vector3, ExactMeshQuery::kInsideRays> dirs;
  const double golden = 2.399963229728653;  // pi * (3 - sqrt(5))
  for (int i = 0; i < ExactMeshQuery::kInsideRays; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / ExactMeshQuery::kInsideRays;
    const double r = std::sqrt(1.0 - z * z);
    const double phi = golden * i + 0.3183098861837907;  // 1/pi: an irrational offset
    double x = r * std::cos(phi), y = r * std::sin(phi), zz = z;
    // A fixed tilt about an oblique axis keeps z off the exact values the spiral gives.
    const double c = std::cos(0.2718281828), s = std::sin(0.2718281828);
    const double y2 = c * y - s * zz, z2 = s * y + c * zz;
    dirs[i] = Vector3(x + 1e-3 * 0.577, y2 + 1e-3 * 0.433, z2 + 1e-3 * 0.271);
  }
  return dirs;
}

}  // namespace

struct ExactMeshQuery::Impl {
  Triangles triangles;  // the tree keeps iterators into this: never resized after build
  Tree tree;
  std::array<Vector3, kInsideRays> directions = rayDirections();
};

ExactMeshQuery::ExactMeshQuery(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ExactMeshQuery::~ExactMeshQuery() = default;

Result<std::unique_ptr<ExactMeshQuery>> ExactMeshQuery::create(const TriangleMesh& mesh) {
  if (auto error = validateMesh(mesh.positions, mesh.indices)) {
    return makeError(error->code, "exact mesh query: " + error->message);
  }
  auto impl = std::make_unique<Impl>();
  impl->triangles.reserve(mesh.triangleCount());
  for (size_t t = 0; t < mesh.triangleCount(); ++t) {
    impl->triangles.emplace_back(toPoint(mesh.positions[mesh.indices[3 * t]]),
                                 toPoint(mesh.positions[mesh.indices[3 * t + 1]]),
                                 toPoint(mesh.positions[mesh.indices[3 * t + 2]]));
  }
  impl->tree.insert(impl->triangles.cbegin(), impl->triangles.cend());
  // Both are lazy in CGAL; building them now makes later const queries free of hidden writes.
  impl->tree.build();
  impl->tree.accelerate_distance_queries();
  return std::unique_ptr<ExactMeshQuery>(new ExactMeshQuery(std::move(impl)));
}

namespace {
bool allFinite(const glm::vec3& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}
}  // namespace

double ExactMeshQuery::unsignedDistance(const glm::vec3& p) const {
  if (!allFinite(p)) return std::numeric_limits<double>::quiet_NaN();
  return std::sqrt(impl_->tree.squared_distance(toPoint(p)));
}

bool ExactMeshQuery::inside(const glm::vec3& p) const {
  if (!allFinite(p)) return false;
  const Point3 origin = toPoint(p);
  constexpr int kMajority = kInsideRays / 2 + 1;
  int in = 0, out = 0;
  for (const Vector3& d : impl_->directions) {
    const size_t hits = impl_->tree.number_of_intersected_primitives(Ray3(origin, d));
    ((hits % 2 == 1) ? in : out)++;
    if (in >= kMajority) return true;
    if (out >= kMajority) return false;
  }
  return in > out;
}

double ExactMeshQuery::signedDistance(const glm::vec3& p) const {
  const double d = unsignedDistance(p);
  if (d == 0.0) return 0.0;
  return inside(p) ? -d : d;
}

// The chain walk behind signedDistances() and anyWithin(): writes each point's signed distance
// to `out` (when not empty) and stops early once `stop(i, distance)` says so. Returns the number
// of points walked.
template <class Stop>
size_t ExactMeshQuery::walkChain(std::span<const glm::vec3> points, std::span<double> out,
                                 Stop stop) const {
  bool previousInside = false;
  double previousDistance = 0.0;
  Point3 hint;
  bool haveHint = false;
  for (size_t i = 0; i < points.size(); ++i) {
    if (!allFinite(points[i])) {
      if (i < out.size()) out[i] = std::numeric_limits<double>::quiet_NaN();
      previousDistance = 0.0;  // the next point casts its own rays
      continue;
    }
    const Point3 p = toPoint(points[i]);
    // The previous point's closest point starts the search with a sphere barely larger than the
    // answer, instead of the tree's own nearest-vertex guess.
    hint = !haveHint ? impl_->tree.closest_point(p) : impl_->tree.closest_point(p, hint);
    haveHint = true;
    const double d = std::sqrt(CGAL::squared_distance(p, hint));
    bool isInside;
    // No surface lies within previousDistance of the previous point, so a step shorter than
    // that cannot have crossed it.
    if (i > 0 && double(glm::length(points[i] - points[i - 1])) < previousDistance) {
      isInside = previousInside;
    } else {
      isInside = d > 0.0 && inside(points[i]);
    }
    const double signedDistance = isInside ? -d : d;
    if (i < out.size()) out[i] = signedDistance;
    previousInside = isInside;
    previousDistance = d;
    if (stop(i, signedDistance)) return i + 1;
  }
  return points.size();
}

void ExactMeshQuery::signedDistances(std::span<const glm::vec3> points,
                                     std::span<double> out) const {
  walkChain(points.first(std::min(points.size(), out.size())), out,
            [](size_t, double) { return false; });
}

bool ExactMeshQuery::anyWithin(std::span<const glm::vec3> points,
                               std::span<const float> radii) const {
  bool found = false;
  walkChain(points.first(std::min(points.size(), radii.size())), {}, [&](size_t i, double d) {
    found = d < double(radii[i]);
    return found;
  });
  return found;
}

namespace {

struct FingerChain {
  std::vector<glm::vec3> points;  // object space, proximal joint first, tip centre last
  std::vector<float> radii;
};

// The first bone of the finger that moves as it curls: the metacarpal where it turns (the
// thumb's, at its carpometacarpal joint), else the proximal phalanx. A moving metacarpal is a
// part the finger can stop on or push into the object, so it is graded with the phalanges.
size_t firstMovingBone(const HandModel& hand, Finger finger) {
  const std::span<const Joint> joints = fingerJoints(finger);
  std::array<Pose, 5> open{}, closed{};
  hand.fingerPose(finger, 0.0f, std::span<Pose>(open.data(), joints.size()));
  hand.fingerPose(finger, 1.0f, std::span<Pose>(closed.data(), joints.size()));
  return glm::length(open[1].position - closed[1].position) > 1e-6f ? 0 : 1;
}

// Samples the finger's capsules (from its first moving bone to the tip) at the given joint curls.
void sampleFinger(const HandModel& hand, Finger finger, size_t firstBone, const JointCurls& curls,
                  const Pose& objectFromHand, FingerChain& chain) {
  const std::span<const Joint> joints = fingerJoints(finger);
  std::array<Pose, 5> poses{};
  hand.fingerPose(finger, curls, std::span<Pose>(poses.data(), joints.size()));
  chain.points.clear();
  chain.radii.clear();
  for (size_t j = firstBone; j + 1 < joints.size(); ++j) {
    const glm::vec3 a = objectFromHand.transformPoint(poses[j].position);
    const glm::vec3 b = objectFromHand.transformPoint(poses[j + 1].position);
    const float ra = hand.jointRadius(joints[j]);
    const float rb = hand.jointRadius(joints[j + 1]);
    const int n = std::max(1, int(std::ceil(glm::length(b - a) / kCapsuleSampleSpacing)));
    for (int k = 0; k < n; ++k) {
      const float t = float(k) / float(n);
      chain.points.push_back(a + (b - a) * t);
      chain.radii.push_back(ra + (rb - ra) * t);
    }
  }
  const Joint tip = joints.back();
  chain.points.push_back(objectFromHand.transformPoint(poses[joints.size() - 1].position));
  chain.radii.push_back(hand.jointRadius(tip));
}

struct ChainMeasure {
  double penetration = 0.0;  // metres, >= 0
  double clearance = 0.0;    // min (d - r), metres
  double tipDistance = 0.0;  // signed, metres
};

ChainMeasure measureChain(const ExactMeshQuery& mesh, const FingerChain& chain,
                          std::vector<double>& scratch) {
  scratch.resize(chain.points.size());
  mesh.signedDistances(chain.points, scratch);
  ChainMeasure m;
  m.clearance = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < chain.points.size(); ++i) {
    const double gap = scratch[i] - double(chain.radii[i]);
    m.penetration = std::max(m.penetration, -gap);
    m.clearance = std::min(m.clearance, gap);
  }
  m.tipDistance = scratch.back();
  return m;
}

// Whether some capsule sphere centre of the finger is inside the mesh at any step of the closing
// sweep (evaluator.h). Distance to the surface is 1-Lipschitz: a centre found outside at distance
// u cannot reach the inside before it has moved u, and the straight-line distance between sweep
// samples is at most the sum of the chords, so querying a centre again only once its chord sum
// exceeds u misses nothing that querying every step would find.
bool sweepPassesThrough(const ExactMeshQuery& mesh, const HandModel& hand, Finger finger,
                        size_t firstBone, const JointCurls& finalCurls, const Pose& objectFromHand,
                        FingerChain& chain) {
  float top = 0.0f;
  for (float c : finalCurls) top = std::max(top, c);
  const int steps = int(std::ceil(top / kPassThroughSweepStep - 1e-4f));
  std::vector<glm::vec3> previous;
  std::vector<double> budget;  // metres each centre may still move unseen
  for (int k = 0; k <= steps; ++k) {
    const float s = std::min(top, kPassThroughSweepStep * float(k));
    JointCurls curls{};
    for (size_t j = 0; j < curls.size(); ++j) curls[j] = std::min(s, finalCurls[j]);
    sampleFinger(hand, finger, firstBone, curls, objectFromHand, chain);
    if (budget.empty()) budget.assign(chain.points.size(), -1.0);
    for (size_t i = 0; i < chain.points.size() && i < budget.size(); ++i) {
      if (!previous.empty()) budget[i] -= double(glm::length(chain.points[i] - previous[i]));
      if (budget[i] >= 0.0) continue;
      const double u = mesh.unsignedDistance(chain.points[i]);
      if (!std::isfinite(u)) return false;
      if (u > 0.0 && mesh.inside(chain.points[i])) return true;
      budget[i] = u;
    }
    previous = chain.points;
  }
  return false;
}

}  // namespace

GraspMetrics evaluateGrasp(const ExactMeshQuery& mesh, const HandModel& hand,
                           const Pose& objectFromHand, const GraspResult& grasp) {
  GraspMetrics out;
  const glm::quat& q = objectFromHand.orientation;
  if (!allFinite(objectFromHand.position) || !std::isfinite(q.w) ||
      !allFinite(glm::vec3(q.x, q.y, q.z))) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (FingerMetrics& f : out.fingers) {
      f.tipDistanceMm = f.tipGapMm = f.tipResidualMm = f.penetrationMm = f.clearanceMm = nan;
      f.contactResidualMm = nan;
    }
    out.penetrationMm = nan;
    return out;
  }
  // The fingers closed in the hand frame the solver moved the hand to (GraspResult::
  // handCorrection: the clearance, the approach), which is where the app shows them.
  const Pose objectFromShown = objectFromHand * grasp.handCorrection;
  FingerChain chain;
  std::vector<double> scratch;
  for (int f = 0; f < kFingerCount; ++f) {
    const Finger finger = Finger(f);
    const size_t firstBone = firstMovingBone(hand, finger);
    const FingerState& state = grasp.fingers[f];
    const double tipRadius = hand.tipRadius(finger);
    FingerMetrics& m = out.fingers[f];

    // Curls outside [0, 1] or NaN (a broken solver) are graded as the pose they clamp to.
    JointCurls stopCurls = state.jointCurls;
    for (float& c : stopCurls) c = std::isfinite(c) ? std::clamp(c, 0.0f, 1.0f) : 0.0f;
    sampleFinger(hand, finger, firstBone, stopCurls, objectFromShown, chain);
    const ChainMeasure at = measureChain(mesh, chain, scratch);
    m.contact = state.contact;
    m.stopped = state.contact || state.curl < 1.0f - 1e-6f;
    m.tipDistanceMm = float(at.tipDistance * 1000.0);
    m.tipGapMm = float((at.tipDistance - tipRadius) * 1000.0);
    m.tipResidualMm = std::abs(m.tipGapMm);
    m.penetrationMm = float(at.penetration * 1000.0);
    m.clearanceMm = float(at.clearance * 1000.0);
    m.touching = m.clearanceMm <= kTouchingMm;
    m.contactResidualMm = std::abs(m.clearanceMm);
    m.tipIsContact = m.tipGapMm <= m.clearanceMm + kTipContactToleranceMm;
    m.passThrough =
        sweepPassesThrough(mesh, hand, finger, firstBone, stopCurls, objectFromShown, chain);

    if (m.stopped && m.tipGapMm > kEarlyStopGapMm) {
      JointCurls curls = stopCurls;
      for (int step = 1;; ++step) {
        bool allClosed = true;
        for (size_t j = 0; j < curls.size(); ++j) {
          curls[j] = std::min(1.0f, stopCurls[j] + kEarlyStopSweepStep * float(step));
          allClosed = allClosed && curls[j] >= 1.0f;
        }
        sampleFinger(hand, finger, firstBone, curls, objectFromShown, chain);
        const ChainMeasure next = measureChain(mesh, chain, scratch);
        if (next.penetration * 1000.0 > kSweepPenetrationToleranceMm) break;
        if ((next.tipDistance - tipRadius) * 1000.0 <= kEarlyStopGapMm) {
          m.earlyStop = true;
          break;
        }
        if (allClosed) break;
      }
    }
    out.penetrationMm = std::max(out.penetrationMm, m.penetrationMm);
    out.contacts += m.touching ? 1 : 0;
    out.earlyStops += m.earlyStop ? 1 : 0;
    out.passThroughs += m.passThrough ? 1 : 0;
  }
  return out;
}

}  // namespace sdfg
