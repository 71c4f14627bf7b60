#include "eval/solver_physics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <btBulletCollisionCommon.h>

namespace sdfg {

namespace {

// One query holds one algorithm and one manifold at a time: Bullet's default pools (4096 of
// each, megabytes zeroed per world) are far more than a single-object world needs.
btDefaultCollisionConstructionInfo smallPools() {
  btDefaultCollisionConstructionInfo info;
  info.m_defaultMaxPersistentManifoldPoolSize = 64;
  info.m_defaultMaxCollisionAlgorithmPoolSize = 64;
  return info;
}

}  // namespace

struct PhysicsCollider::Impl {
  // One static object per part, each with the arrays its triangle-mesh shape references
  // (btTriangleIndexVertexArray does not copy).
  struct Part {
    std::vector<btScalar> vertices;  // xyz per vertex
    std::vector<int> indices;        // three per triangle
    std::unique_ptr<btTriangleIndexVertexArray> meshInterface;
    std::unique_ptr<btCollisionShape> shape;
    btCollisionObject object;
  };
  std::vector<std::unique_ptr<Part>> parts;
  // Declared in construction order; destroyed in reverse, the world before what it uses.
  btDefaultCollisionConfiguration configuration{smallPools()};
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btCollisionWorld world{&dispatcher, &broadphase, &configuration};
};

PhysicsCollider::PhysicsCollider(Kind kind) : kind_(kind), impl_(std::make_unique<Impl>()) {}

PhysicsCollider::~PhysicsCollider() {
  if (!impl_) return;
  for (auto& part : impl_->parts) impl_->world.removeCollisionObject(&part->object);
}

size_t PhysicsCollider::shapeVertexCount() const {
  size_t count = 0;
  for (const auto& part : impl_->parts) {
    count += kind_ == Kind::convexHull
                 ? size_t(static_cast<const btConvexHullShape*>(part->shape.get())->getNumPoints())
                 : part->vertices.size() / 3;
  }
  return count;
}

Result<std::unique_ptr<PhysicsCollider>> PhysicsCollider::create(const TriangleMesh& mesh,
                                                                 Kind kind) {
  return create(std::span<const TriangleMesh>(&mesh, 1), kind);
}

Result<std::unique_ptr<PhysicsCollider>> PhysicsCollider::create(
    std::span<const TriangleMesh> meshes, Kind kind) {
  if (meshes.empty()) {
    return makeError(Status::invalid_argument, "physics collider: no mesh");
  }
  for (const TriangleMesh& mesh : meshes) {
    if (auto error = validateMesh(mesh.positions, mesh.indices)) {
      return makeError(error->code, "physics collider: " + error->message);
    }
  }
  std::unique_ptr<PhysicsCollider> collider(new PhysicsCollider(kind));
  Impl& impl = *collider->impl_;
  for (const TriangleMesh& mesh : meshes) {
    auto part = std::make_unique<Impl::Part>();
    if (kind == Kind::convexHull) {
      auto hull = std::make_unique<btConvexHullShape>();
      for (const glm::vec3& p : mesh.positions) hull->addPoint(btVector3(p.x, p.y, p.z), false);
      hull->optimizeConvexHull();  // keeps the exact hull's vertices only: cheaper support queries
      hull->setMargin(0);
      hull->recalcLocalAabb();
      part->shape = std::move(hull);
    } else {
      part->vertices.reserve(mesh.positions.size() * 3);
      for (const glm::vec3& p : mesh.positions) {
        part->vertices.insert(part->vertices.end(), {btScalar(p.x), btScalar(p.y), btScalar(p.z)});
      }
      part->indices.assign(mesh.indices.begin(), mesh.indices.end());
      part->meshInterface = std::make_unique<btTriangleIndexVertexArray>(
          int(mesh.triangleCount()), part->indices.data(), int(3 * sizeof(int)),
          int(mesh.vertexCount()), part->vertices.data(), int(3 * sizeof(btScalar)));
      auto shape = std::make_unique<btBvhTriangleMeshShape>(part->meshInterface.get(), true);
      shape->setMargin(0);
      part->shape = std::move(shape);
    }
    part->object.setCollisionShape(part->shape.get());
    part->object.setWorldTransform(btTransform::getIdentity());
    impl.world.addCollisionObject(&part->object);
    impl.parts.push_back(std::move(part));
  }
  impl.world.updateAabbs();
  return collider;
}

namespace {

// Records the deepest contact; positive distances (Bullet reports pairs within its contact
// breaking threshold) are not overlaps.
struct DeepestContact : btCollisionWorld::ContactResultCallback {
  btScalar deepest = std::numeric_limits<btScalar>::infinity();
  btScalar addSingleResult(btManifoldPoint& cp, const btCollisionObjectWrapper*, int, int,
                           const btCollisionObjectWrapper*, int, int) override {
    deepest = std::min(deepest, cp.getDistance());
    return 0;
  }
};

}  // namespace

bool PhysicsCollider::sphereOverlaps(glm::vec3 centre, float radius, float& centreDistance) const {
  btSphereShape sphere(std::max(radius, 0.0f));
  btCollisionObject probe;
  probe.setCollisionShape(&sphere);
  probe.setWorldTransform(
      btTransform(btQuaternion::getIdentity(), btVector3(centre.x, centre.y, centre.z)));
  DeepestContact result;
  impl_->world.contactTest(&probe, result);
  if (!(result.deepest <= 0)) return false;
  centreDistance = float(radius + result.deepest);
  return true;
}

bool PhysicsCollider::sphereOverlaps(glm::vec3 centre, float radius) const {
  float unused = 0.0f;
  return sphereOverlaps(centre, radius, unused);
}

std::string_view PhysicsSolver::name() const {
  return kind_ == PhysicsCollider::Kind::convexHull ? "physics-convex" : "physics-mesh";
}

Status PhysicsSolver::prepare(const HandModel& hand, const GridBox&, const SolverOptions& options) {
  prepared_ = false;
  error_.clear();
  if (auto error = validateSolverOptions(options)) {
    error_ = std::string(name()) + ": " + error->message;
    return error->code;
  }
  hand_ = hand;
  coarse_ = options.da;
  fine_ = options.refineStep;
  for (int f = 0; f < kFingerCount; ++f) {
    radius_[f] = options.threshold >= 0.0f ? options.threshold : hand.tipRadius(Finger(f));
  }
  prepared_ = true;
  return Status::ok;
}

namespace {

bool finitePose(const Pose& pose) {
  const glm::quat& q = pose.orientation;
  const glm::vec3& p = pose.position;
  return std::isfinite(q.w) && std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) &&
         std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

}  // namespace

Status PhysicsSolver::solve(const GraspScene& scene, GraspResult& out) const {
  if (!prepared_ || scene.collider == nullptr || scene.collider->kind() != kind_ ||
      !finitePose(scene.objectFromHand)) {
    return Status::invalid_argument;
  }
  const PhysicsCollider& collider = *scene.collider;
  for (int f = 0; f < kFingerCount; ++f) {
    const Finger finger = Finger(f);
    const float radius = radius_[f];
    float distance = 0.0f;
    auto overlapsAt = [&](float a) {
      const glm::vec3 tip = scene.objectFromHand.transformPoint(hand_.tipPosition(finger, a));
      return collider.sphereOverlaps(tip, radius, distance);
    };
    FingerState& state = out.fingers[f];
    state.curl = 1.0f;
    state.contact = false;
    state.distance = std::numeric_limits<float>::infinity();
    float previous = 0.0f;
    for (int k = 0;; ++k) {
      const float a = std::min(float(k) * coarse_, 1.0f);
      if (overlapsAt(a)) {
        float stop = a;
        // Back to the last free coarse step, then forward by the fine step.
        for (int j = 1; k > 0; ++j) {
          const float b = previous + float(j) * fine_;
          if (b >= a) break;
          if (overlapsAt(b)) {
            stop = b;
            break;
          }
        }
        state.curl = stop;
        state.contact = true;
        state.distance = distance;
        break;
      }
      if (a >= 1.0f) break;
      previous = a;
    }
    state.jointCurls.fill(state.curl);
    state.contactPoint = hand_.tipPosition(finger, state.curl);
  }
  return Status::ok;
}

}  // namespace sdfg
