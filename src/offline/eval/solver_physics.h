// The physics baseline (paper Algorithm 1), strategies "physics-convex" and "physics-mesh", and
// the Bullet collider they query.
//
// Each finger bends by coarse steps; at each step a sphere at the fingertip is tested for
// overlap with the object's collider. On the first overlap the finger goes back one coarse step
// and advances by the fine step until the sphere overlaps again; it stops there, like Algorithm 1
// stops on the step that overlaps. Two colliders, as in the benchmark:
// - convex hull: what commercial auto-grasp toolkits give the object (the paper's Figure 4).
//   Fingers stop on the hull, so early on concave objects, and a tip inside it counts as overlap.
// - exact triangle mesh: fingers stop on the real surface, but a mesh collider is only its
//   triangles: a sphere entirely inside the object touches none and does not count. That is how
//   mesh colliders behave in Bullet (and PhysX); it is kept visible, not worked around.
// Bullet stays behind this header: callers never include it.
#pragma once

#include <array>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include <glm/vec3.hpp>

#include "base/status.h"
#include "grasp/solver.h"
#include "mesh/mesh.h"

namespace sdfg {

// A Bullet collision world holding static objects (usually one), in the object's own space.
// Not thread-safe: queries reuse Bullet's dispatcher, so use one collider per thread.
class PhysicsCollider {
 public:
  enum class Kind {
    // btConvexHullShape over the mesh vertices, reduced to the exact hull's vertices
    // (btConvexHullShape::optimizeConvexHull, i.e. btConvexHullComputer): no approximation, no
    // polygon limit (PhysX cooking caps hulls at 255 polygons; Bullet's btShapeHull would
    // approximate). Zero collision margin, so the hull is not inflated.
    convexHull,
    // btBvhTriangleMeshShape over a btTriangleIndexVertexArray that references arrays this
    // collider owns. Zero margin.
    triangleMesh,
  };

  // Builds a collider from a mesh (copied). invalid_argument on a mesh validateMesh() rejects
  // (empty, bad indices, NaN...).
  static Result<std::unique_ptr<PhysicsCollider>> create(const TriangleMesh& mesh, Kind kind);
  // A collider of several objects (a scene, every part in the same space), each its own shape of
  // `kind`: one convex hull per object, not the hull of them all. invalid_argument on an empty
  // span or any mesh validateMesh() rejects.
  static Result<std::unique_ptr<PhysicsCollider>> create(std::span<const TriangleMesh> meshes,
                                                         Kind kind);

  ~PhysicsCollider();
  PhysicsCollider(const PhysicsCollider&) = delete;
  PhysicsCollider& operator=(const PhysicsCollider&) = delete;

  Kind kind() const { return kind_; }
  // Vertices the Bullet shape holds: the hull's vertices, or all mesh vertices.
  size_t shapeVertexCount() const;

  // True when a sphere (object space) overlaps the collider: Bullet's contactTest reports a
  // contact at distance <= 0. Contacts Bullet reports inside its breaking threshold but with a
  // positive distance (a sphere just outside) do not count. `radius` >= 0.
  bool sphereOverlaps(glm::vec3 centreObjectSpace, float radius) const;
  // Same; on overlap `centreDistance` receives the distance from the sphere's centre to the
  // surface as Bullet saw it (radius + deepest contact distance, negative when the centre is
  // past the surface). Unchanged when there is no overlap.
  bool sphereOverlaps(glm::vec3 centreObjectSpace, float radius, float& centreDistance) const;

 private:
  struct Impl;
  explicit PhysicsCollider(Kind kind);
  Kind kind_;
  std::unique_ptr<Impl> impl_;
};

// Algorithm 1 with a coarse and a fine step. The coarse step is options.da (default 0.1, the
// paper's "typically 0.1"), the fine step options.refineStep (default 0.01); samples are
// a = min(k * da, 1), so a = 1 is tested. Sphere radius: options.threshold when >= 0, else the
// finger's tip radius. Results: touching in the open pose -> curl 0; first overlap at a_k ->
// the first fine step in (a_{k-1}, a_k] that overlaps (a_k when none of the fine steps before it
// does), contact true, distance = Bullet's centre distance; no overlap up to a = 1 -> curl 1,
// contact false, distance +infinity (the strategy only knows nothing was within the radius).
// Tip positions come from HandModel::tipPosition at each tested curl, as Algorithm 1 blends
// the pose per step. Like Algorithm 1 it tests only tips at coarse steps, so a thin part can be
// skipped between two steps, and with a mesh collider a step that lands the whole sphere inside
// the object is not an overlap (the finger passes through).
class PhysicsSolver final : public GraspSolver {
 public:
  explicit PhysicsSolver(PhysicsCollider::Kind kind) : kind_(kind) {}

  std::string_view name() const override;
  bool needsField() const override { return false; }
  bool needsCollider() const override { return true; }

  // Keeps a copy of the hand; the box is not used. invalid_argument on invalid options.
  Status prepare(const HandModel& hand, const GridBox& box, const SolverOptions& options) override;
  // invalid_argument when unprepared, without a collider, with a collider of the other kind,
  // or with a non-finite objectFromHand.
  Status solve(const GraspScene& scene, GraspResult& out) const override;
  std::string_view prepareError() const override { return error_; }

 private:
  PhysicsCollider::Kind kind_;
  bool prepared_ = false;
  HandModel hand_;
  float coarse_ = 0.1f;
  float fine_ = 0.01f;
  std::array<float, kFingerCount> radius_{};
  std::string error_;
};

}  // namespace sdfg
