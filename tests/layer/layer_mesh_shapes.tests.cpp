// Meshes as games ship them, through the loader (issue 41): the same surface as an indexed mesh,
// as a triangle soup and with hard-edge splits grasps the same; a sphere subdivided with each
// face's own midpoints is grasped; meshes that are not watertight (a cup without its bottom, a box
// with a face missing, intersecting closed boxes, duplicated or double-sided triangles,
// T-junctions, a crack between two halves) are closed on from outside, never through what a person
// calls solid, and a hand that starts inside them is moved out. The set-up's log line says what
// the weld did, and new vertices for a split mesh (skinning) still move its surface.
//
// Every mesh is built here, in code. The references the hand is checked against never come from
// the layer: the exact distance to the indexed (bit-exactly welded) mesh where one exists, else the
// solid a person would name, as an analytic signed distance.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <iterator>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "grasp_v2.h"

namespace {

using namespace sdfg;
using namespace sdfg::test;

const XrPosef kGrip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};

// The bounds of every check below: "on the surface" and "not inside" both mean within 0.5 mm.
constexpr float kSurface = 5e-4f;

// ---------------------------------------------------------------------------------------------
// Meshes built in code.

using Triangles = std::vector<std::array<glm::vec3, 3>>;

XrVector3f xr(const glm::vec3& p) {
  return {p.x, p.y, p.z};
}
glm::vec3 vec(const XrVector3f& p) {
  return {p.x, p.y, p.z};
}

// A triangle soup: every triangle its own three vertices, positions copied bit for bit.
TestMesh soupOf(const Triangles& tris) {
  TestMesh m;
  for (const auto& t : tris) {
    for (const glm::vec3& p : t) {
      m.indices.push_back(uint32_t(m.vertices.size()));
      m.vertices.push_back(xr(p));
    }
  }
  return m;
}

Triangles trianglesOf(const TestMesh& m) {
  Triangles out;
  for (size_t i = 0; i + 2 < m.indices.size(); i += 3)
    out.push_back({vec(m.vertices[m.indices[i]]), vec(m.vertices[m.indices[i + 1]]),
                   vec(m.vertices[m.indices[i + 2]])});
  return out;
}

TestMesh soupOf(const TestMesh& m) {
  return soupOf(trianglesOf(m));
}

// Vertices at bit-identical positions made one (the first one's index): the indexed mesh a soup
// or a split mesh came from, the reference its grasps are compared with. No tolerance, so a test
// mesh only becomes closed here when its builder made the shared corners bit-identical.
TestMesh weldExact(const TestMesh& m) {
  std::map<std::array<uint32_t, 3>, uint32_t> seen;
  TestMesh out;
  for (uint32_t i : m.indices) {
    const XrVector3f& p = m.vertices[i];
    std::array<uint32_t, 3> key;
    std::memcpy(key.data(), &p, sizeof key);
    const auto [it, inserted] = seen.try_emplace(key, uint32_t(out.vertices.size()));
    if (inserted) out.vertices.push_back(p);
    out.indices.push_back(it->second);
  }
  return out;
}

// Hard-edge (flat-shading) split as exporters make it: at each vertex, the triangles around it
// are grouped by normal (a triangle joins the first group whose first normal is within 30
// degrees), and each group gets its own copy of the vertex, at the same position.
TestMesh hardEdgeSplit(const TestMesh& m) {
  const float cosLimit = std::cos(glm::radians(30.0f));
  std::vector<std::vector<std::pair<glm::vec3, uint32_t>>> groups(m.vertices.size());
  TestMesh out;
  for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    const glm::vec3 a = vec(m.vertices[m.indices[t]]), b = vec(m.vertices[m.indices[t + 1]]),
                    c = vec(m.vertices[m.indices[t + 2]]);
    const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
    for (size_t k = 0; k < 3; ++k) {
      const uint32_t v = m.indices[t + k];
      uint32_t copy = UINT32_MAX;
      for (const auto& [normal, index] : groups[v])
        if (glm::dot(normal, n) >= cosLimit) {
          copy = index;
          break;
        }
      if (copy == UINT32_MAX) {
        copy = uint32_t(out.vertices.size());
        out.vertices.push_back(m.vertices[v]);
        groups[v].push_back({n, copy});
      }
      out.indices.push_back(copy);
    }
  }
  return out;
}

// Corner i of n along one axis between lo and hi: the end corners are lo and hi themselves, so
// faces that meet there share bit-identical positions whatever their subdivision.
float along(float lo, float hi, int i, int n) {
  if (i == 0) return lo;
  if (i == n) return hi;
  return lo + (hi - lo) * float(i) / float(n);
}

// One face of the box [lo, hi]: the face normal to `axis` on its `positive` side, as an n x n
// grid of quads, wound counter-clockwise seen from outside.
void addBoxFace(Triangles& tris, const glm::vec3& lo, const glm::vec3& hi, int axis, bool positive,
                int n) {
  const int a = (axis + 1) % 3, b = (axis + 2) % 3;  // e_a x e_b = e_axis
  auto at = [&](int i, int j) {
    glm::vec3 p;
    p[axis] = positive ? hi[axis] : lo[axis];
    p[a] = along(lo[a], hi[a], i, n);
    p[b] = along(lo[b], hi[b], j, n);
    return p;
  };
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const glm::vec3 p00 = at(i, j), p10 = at(i + 1, j), p11 = at(i + 1, j + 1),
                      p01 = at(i, j + 1);
      if (positive) {
        tris.push_back({p00, p10, p11});
        tris.push_back({p00, p11, p01});
      } else {
        tris.push_back({p00, p11, p10});
        tris.push_back({p00, p01, p11});
      }
    }
  }
}

// Faces of a box in the order -X, +X, -Y, +Y, -Z, +Z.
enum BoxFace { kMinusX, kPlusX, kMinusY, kPlusY, kMinusZ, kPlusZ };

// The box [lo, hi], face f split into divisions[f] x divisions[f] quads (0: the face is left out).
Triangles boxTriangles(const glm::vec3& lo, const glm::vec3& hi,
                       const std::array<int, 6>& divisions = {1, 1, 1, 1, 1, 1}) {
  Triangles tris;
  for (int f = 0; f < 6; ++f)
    if (divisions[size_t(f)] > 0) addBoxFace(tris, lo, hi, f / 2, f % 2 == 1, divisions[size_t(f)]);
  return tris;
}

Triangles boxTriangles(const glm::vec3& half) {
  return boxTriangles(-half, half);
}

// A sphere of `radius` subdivided `levels` times from an octahedron or an icosahedron the way a
// simple exporter or procedural generator does it: every face computes its own edge midpoints
// (normalize(a + b), which is bit-identical for the face on the other side of the edge, since a
// float sum does not depend on the order of its terms) and appends them as new vertices. Only the
// base solid's corners share indices: after two levels every original face is 4 separate pieces,
// no edge is shared by index, and the pieces meet only at positions.
TestMesh unsharedSphere(bool icosahedron, int levels, float radius) {
  std::vector<glm::vec3> p;
  std::vector<std::array<uint32_t, 3>> faces;
  if (icosahedron) {
    const float g = 0.5f * (1.0f + std::sqrt(5.0f));
    p = {{-1, g, 0},  {1, g, 0},  {-1, -g, 0}, {1, -g, 0}, {0, -1, g},  {0, 1, g},
         {0, -1, -g}, {0, 1, -g}, {g, 0, -1},  {g, 0, 1},  {-g, 0, -1}, {-g, 0, 1}};
    const uint32_t idx[60] = {0, 11, 5,  0, 5,  1, 0, 1, 7, 0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11,
                              4, 11, 10, 2, 10, 7, 6, 7, 1, 8, 3,  9,  4, 3,  4,  2, 3, 2, 6, 3,
                              6, 8,  3,  8, 9,  4, 9, 5, 2, 4, 11, 6,  2, 10, 8,  6, 7, 9, 8, 1};
    for (glm::vec3& v : p) v = glm::normalize(v);
    for (int t = 0; t < 20; ++t) faces.push_back({idx[3 * t], idx[3 * t + 1], idx[3 * t + 2]});
  } else {
    p = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (uint32_t x : {0u, 1u})
      for (uint32_t y : {2u, 3u})
        for (uint32_t z : {4u, 5u}) faces.push_back({x, y, z});
  }
  for (int level = 0; level < levels; ++level) {
    std::vector<std::array<uint32_t, 3>> finer;
    for (const auto& [a, b, c] : faces) {
      const uint32_t ab = uint32_t(p.size());
      p.push_back(glm::normalize(p[a] + p[b]));
      const uint32_t bc = uint32_t(p.size());
      p.push_back(glm::normalize(p[b] + p[c]));
      const uint32_t ca = uint32_t(p.size());
      p.push_back(glm::normalize(p[c] + p[a]));
      finer.insert(finer.end(), {{a, ab, ca}, {ab, b, bc}, {ca, bc, c}, {ab, bc, ca}});
    }
    faces = std::move(finer);
  }
  TestMesh m;
  for (const glm::vec3& v : p) m.vertices.push_back(xr(v * radius));
  for (auto [a, b, c] : faces) {
    // Outward for a convex solid around the origin.
    if (glm::dot(glm::cross(p[b] - p[a], p[c] - p[a]), p[a] + p[b] + p[c]) < 0.0f) std::swap(b, c);
    m.indices.insert(m.indices.end(), {a, b, c});
  }
  return m;
}

// A mug-like cup lying along X: outer wall (radius R) from x0 to x1, the rim at x1, the inner
// wall (radius r) down to a floor at xf; the outer bottom disc at x0 only when `bottom`. Each
// triangle is turned to face the side `outward` says; ring corners are computed by one formula,
// so the surfaces meet at bit-identical positions.
struct Cup {
  float R = 0.04f, r = 0.032f, x0 = -0.06f, x1 = 0.06f, xf = -0.052f;
  int segments = 64;
  glm::vec3 ring(float x, float radius, int i) const {
    const float a = 2.0f * float(M_PI) * float(i % segments) / float(segments);
    return {x, radius * std::cos(a), radius * std::sin(a)};
  }
  Triangles triangles(bool bottom) const {
    Triangles tris;
    auto add = [&](glm::vec3 a, glm::vec3 b, glm::vec3 c, const glm::vec3& outward) {
      if (glm::dot(glm::cross(b - a, c - a), outward) < 0.0f) std::swap(b, c);
      tris.push_back({a, b, c});
    };
    auto radial = [](const glm::vec3& p) { return glm::vec3(0.0f, p.y, p.z); };
    for (int i = 0; i < segments; ++i) {
      const glm::vec3 o0 = ring(x0, R, i), o1 = ring(x0, R, i + 1), o2 = ring(x1, R, i + 1),
                      o3 = ring(x1, R, i);
      add(o0, o1, o2, radial(o0 + o2));  // outer wall, facing away from the axis
      add(o0, o2, o3, radial(o0 + o2));
      const glm::vec3 i0 = ring(xf, r, i), i1 = ring(xf, r, i + 1), i2 = ring(x1, r, i + 1),
                      i3 = ring(x1, r, i);
      add(i0, i1, i2, -radial(i0 + i2));  // inner wall, facing the axis (into the cavity)
      add(i0, i2, i3, -radial(i0 + i2));
      add(o3, o2, i2, {1, 0, 0});  // rim
      add(o3, i2, i3, {1, 0, 0});
      add(glm::vec3(xf, 0, 0), i0, i1, {1, 0, 0});  // floor, facing into the cavity
      if (bottom) add(glm::vec3(x0, 0, 0), o0, o1, {-1, 0, 0});
    }
    return tris;
  }
  // What a person calls the cup's material: the wall and the floor (an L in the (x, radius)
  // half-plane); exact outside, a bound inside.
  float solid(const glm::vec3& p) const {
    const glm::vec2 q(p.x, std::hypot(p.y, p.z));
    auto rect = [&](const glm::vec2& lo, const glm::vec2& hi) {
      const glm::vec2 c = 0.5f * (lo + hi), h = 0.5f * (hi - lo);
      const glm::vec2 d = glm::abs(q - c) - h;
      return glm::length(glm::max(d, glm::vec2(0.0f))) + std::min(std::max(d.x, d.y), 0.0f);
    };
    return std::min(rect({x0, r}, {x1, R}), rect({x0, 0.0f}, {xf, R}));
  }
};

float boxSdf(const glm::vec3& p, const glm::vec3& lo, const glm::vec3& hi) {
  const glm::vec3 d = glm::abs(p - 0.5f * (lo + hi)) - 0.5f * (hi - lo);
  return glm::length(glm::max(d, glm::vec3(0.0f))) +
         std::min(std::max(d.x, std::max(d.y, d.z)), 0.0f);
}

// ---------------------------------------------------------------------------------------------
// Placement, references and checks.

using Solid = std::function<float(const glm::vec3&)>;      // object frame, negative inside
using Distance = std::function<float(const XrVector3f&)>;  // LOCAL space, negative inside

// `solid` placed at `pose`, read at LOCAL points.
Distance placed(Solid solid, const XrPosef& pose) {
  const Pose objectFromLocal = toPose(pose).inverse();
  return [solid = std::move(solid), objectFromLocal](const XrVector3f& p) {
    return solid(objectFromLocal.transformPoint(vec(p)));
  };
}

// The exact signed distance to an (indexed, closed) mesh as a Solid in its own frame.
Solid exactSolid(const TestMesh& indexed) {
  auto exact = std::make_shared<ExactDistance>(indexed, XrPosef{{0, 0, 0, 1}, {0, 0, 0}});
  return [exact](const glm::vec3& p) { return (*exact)(xr(p)); };
}

// The open right hand at kGrip: its joint spheres (hand space) and where it is in LOCAL space.
struct OpenHand {
  Pose localFromWrist;
  std::vector<BodySphere> spheres;
  OpenRightHand axes;
  float palmRadius = 0.0f;
};

OpenHand openHand(const XrPosef& grip) {
  const HandModel model = HandModel::defaultAdult(Hand::right);
  OpenHand h;
  h.localFromWrist = toPose(grip) * wristFromGrip(model).inverse();
  for (int f = 0; f < kFingerCount; ++f) model.phalanxSpheres(Finger(f), 0.0f, h.spheres);
  JointPoses open;
  model.pose(FingerCurls{}, open);
  h.palmRadius = model.jointRadius(Joint::palm);
  h.spheres.push_back({open[int(Joint::palm)].position, h.palmRadius, 0});
  h.axes = openRightHand(grip);
  return h;
}

// `solid` turned by facingPalm() (object +Y toward the palm, +X across the fingers) and moved
// along the palm's normal until every sphere of the open hand is 3 mm clear of it: the grab starts
// from a hand that touches nothing (belowOpenRightPalm() with a person's solid instead of a mesh,
// so an open mesh's own sign cannot choose where the test puts it).
XrPosef clearBelowPalm(const Solid& solid) {
  const OpenHand hand = openHand(kGrip);
  const XrQuaternionf q = facingPalm(kGrip);
  const glm::quat turn(q.w, q.x, q.y, q.z);
  for (float s = 0.0f; s < 0.4f; s += 0.001f) {
    const glm::vec3 t = hand.axes.palm + hand.axes.down * s;
    bool clear = true;
    for (const BodySphere& b : hand.spheres) {
      const glm::vec3 p = glm::inverse(turn) * (hand.localFromWrist.transformPoint(b.center) - t);
      if (solid(p) < b.radius + 0.003f) {
        clear = false;
        break;
      }
    }
    if (clear) return {q, xr(t)};
  }
  FAIL("no placement under the open palm keeps the hand clear of the object");
  return {};
}

// `solid` turned by facingPalm() with the open palm's sphere `depth` inside it (the palm's lowest
// point `depth` under the surface it faces): the solid is brought up along the palm's normal from
// far below in 1 mm steps until the palm is that deep (the first surface it meets, not a hollow's
// inside), then the depth is bisected within the last step.
XrPosef palmInside(const Solid& solid, float depth) {
  const OpenHand hand = openHand(kGrip);
  const XrQuaternionf q = facingPalm(kGrip);
  const glm::quat turn(q.w, q.x, q.y, q.z);
  auto palmClearance = [&](float s) {
    const glm::vec3 t = hand.axes.palm + hand.axes.down * s;
    return solid(glm::inverse(turn) * (hand.axes.palm - t)) - hand.palmRadius;
  };
  float hi = 0.4f;  // far clear
  REQUIRE(palmClearance(hi) > 0.0f);
  while (hi > 0.0f && palmClearance(hi - 0.001f) >= -depth) hi -= 0.001f;
  REQUIRE(hi > 0.0f);
  float lo = hi - 0.001f;  // the palm deeper than `depth` at lo, not at hi
  for (int i = 0; i < 40; ++i) {
    const float mid = 0.5f * (lo + hi);
    (palmClearance(mid) < -depth ? lo : hi) = mid;
  }
  const glm::vec3 t = hand.axes.palm + hand.axes.down * hi;
  return {q, xr(t)};
}

// Clearance of a located finger's capsules (proximal joint to tip, radii interpolated). Negative
// inside.
float fingerGap(const Joints& j, int finger, const Distance& distance) {
  // The thumb from its metacarpal: whole-finger strategies stop it wherever it touches, and
  // its metacarpal bone (the ball of the thumb) is where it often does on a small object.
  const int first = finger == 0 ? XR_HAND_JOINT_THUMB_METACARPAL_EXT : kTips[finger] - 3;
  float best = std::numeric_limits<float>::infinity();
  for (int k = first; k < kTips[finger]; ++k)
    best = std::min(best, capsuleClearance(j.joints[k], j.joints[k + 1], 16, distance));
  return best;
}

// What one grab ended with.
struct Grab {
  bool grasped = false;  // isGrasping with the hand's offset blended in fully, within the bound
  XrGraspTargetsSetupInfoSDFG setup{XR_TYPE_GRASP_TARGETS_SETUP_INFO_SDFG};
  Joints open;    // the located hand two frames in, before the squeeze
  Joints joints;  // the located hand once grasped
  XrGraspStateSDFG state{XR_TYPE_GRASP_STATE_SDFG};
  XrGraspHandOffsetSDFG offset{XR_TYPE_GRASP_HAND_OFFSET_SDFG};
  XrGraspBuildInfoSDFG build{XR_TYPE_GRASP_BUILD_INFO_SDFG};  // where the grab's SDF was built
};

void readHand(App& app, const Ext& ext, XrHandTrackerEXT tracker, Grab& g) {
  REQUIRE(locateJoints(app, tracker, g.joints) == XR_SUCCESS);
  g.offset = XrGraspHandOffsetSDFG{XR_TYPE_GRASP_HAND_OFFSET_SDFG};
  g.build = XrGraspBuildInfoSDFG{XR_TYPE_GRASP_BUILD_INFO_SDFG};
  g.offset = XrGraspHandOffsetSDFG{XR_TYPE_GRASP_HAND_OFFSET_SDFG, &g.build};
  g.state = XrGraspStateSDFG{XR_TYPE_GRASP_STATE_SDFG, &g.offset};
  XrGraspStateGetInfoSDFG gi{XR_TYPE_GRASP_STATE_GET_INFO_SDFG, nullptr, XR_HAND_RIGHT_EXT};
  REQUIRE(ext.state(app.session, &gi, &g.state) == XR_SUCCESS);
  // The structs are copied out: no pointers between them.
  g.state.next = nullptr;
  g.offset.next = nullptr;
}

// The right hand at kGrip squeezes (from frame 6) on `mesh` at `pose`; frames run until it
// grasps with its offset fully blended in, for at most `limit` of wall time (a bound, not a frame
// count: the layer sets up and solves on its session's worker, as fast as the machine allows). The
// set-up is waited for first without frames, so the scripted squeeze waits for it too. The outer
// hand is off: these cases measure the grasp's own clearance of a hand placed inside the mesh (the
// outer hand would show that hand at the nearest clear pose before the squeeze).
Grab grab(const TestMesh& mesh, const XrPosef& pose,
          std::chrono::milliseconds limit = std::chrono::seconds(45)) {
  XrEnv env;
  env.handTracking = "absent";
  env.extra = {{"SDFG_AUTOGRASP_OUTER_HAND", "false"}};
  env.script =
      gripLine(0, "right", kGrip) + squeezeLine(0, "right", 0.0f) + squeezeLine(6, "right", 1.0f);
  applyEnv(env);
  App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
  REQUIRE(app.ok());
  Ext ext(app);
  XrHandTrackerEXT tracker = makeTracker(app, ext, XR_HAND_RIGHT_EXT);
  makeTarget(app, ext, mesh, pose);
  Grab g;
  CHECK(untilSetUp(app, ext, [](const auto& s) { return s.pendingCount == 0; }));
  g.setup = setupInfo(app, ext);
  g.setup.next = nullptr;
  app.frames(2);
  REQUIRE(locateJoints(app, tracker, g.open) == XR_SUCCESS);
  g.grasped = app.framesUntil(
      [&] {
        readHand(app, ext, tracker, g);
        return g.state.isGrasping && g.offset.blend >= 1.0f;
      },
      limit);
  CHECK(validationLog().empty());
  return g;
}

// grab() on a Vulkan session (XR_KHR_vulkan_enable2, the app's device on lavapipe with the Vulkan
// validation layer), the layer's gpu key "on": the grab's SDF is built on the GPU, whose
// sign comes from its own preparation of the mesh (pseudo-normals where the mesh is closed, else
// a flood), not the CPU's. The squeeze waits until the session's GPU path is ready (pipelines
// warmed up in the first frames: seconds on lavapipe with a cold cache), else the grab would be
// built on the CPU. Every Vulkan validation message fails the test.
Grab grabOnGpu(const TestMesh& mesh, const XrPosef& pose) {
  XrEnv env;
  env.handTracking = "absent";
  env.extra = {{"SDFG_AUTOGRASP_GPU", "on"}};
  env.script = gripLine(0, "right", kGrip) + squeezeLine(0, "right", 0.0f);
  applyEnv(env);
  const size_t messagesBefore = vulkanMessages().size();
  Grab g;
  {
    App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME},
             true,
             Graphics::vulkan2});
    REQUIRE(app.ok());
    Ext ext(app);
    XrHandTrackerEXT tracker = makeTracker(app, ext, XR_HAND_RIGHT_EXT);
    makeTarget(app, ext, mesh, pose);
    CHECK(untilSetUp(app, ext, [](const auto& s) { return s.pendingCount == 0; }));
    g.setup = setupInfo(app, ext);
    g.setup.next = nullptr;
    app.frames(2);  // the hand is located at a frame's time: there is one from here on
    REQUIRE(app.framesUntil([&] {
      readHand(app, ext, tracker, g);
      return g.build.sessionBackend == XR_GRASP_SDF_BACKEND_VULKAN_SDFG;
    }));
    g.open = g.joints;
    const uint64_t next = app.framesEnded + 1;
    REQUIRE(app.setScript(gripLine(0, "right", kGrip) + squeezeLine(0, "right", 0.0f) +
                          squeezeLine(next - 1, "right", 0.0f) +
                          squeezeLine(next, "right", 1.0f)) == XR_SUCCESS);
    g.grasped = app.framesUntil(
        [&] {
          readHand(app, ext, tracker, g);
          return g.state.isGrasping && g.offset.blend >= 1.0f;
        },
        std::chrono::seconds(120));
    CHECK(g.build.graspBackend == XR_GRASP_SDF_BACKEND_VULKAN_SDFG);
    CHECK_FALSE(g.build.gpuFailed);
  }
  CHECK(validationLog().empty());
  CHECK(vulkanMessages().size() == messagesBefore);
  return g;
}

// Every finger that stopped is on the surface `distance` (its closest part within 0.5 mm, on
// either side, and the centre of the sphere the layer says touches is outside), no part of the
// hand is more than 0.5 mm inside, and at least `minContacts` fingers touch.
void checkOnSurface(const Grab& g, const Distance& distance, const XrPosef& pose,
                    int minContacts = 3) {
  CAPTURE(g.setup.readyCount, g.setup.failedCount);
  REQUIRE(g.grasped);
  int contacts = 0;
  for (int f = 0; f < 5; ++f) {
    const XrGraspFingerStateSDFG& s = g.state.fingers[f];
    const float gap = fingerGap(g.joints, f, distance);
    CAPTURE(f, s.curl, s.inContact, gap);
    if (!s.inContact) continue;
    ++contacts;
    CHECK(std::abs(gap) <= kSurface);
    const glm::vec3 contact = toPose(pose).transformPoint(vec(s.contactPoint));
    CAPTURE(s.distance, distance(xr(contact)));
    CHECK(distance(xr(contact)) > 0.0f);
  }
  CHECK(contacts >= minContacts);
  CHECK(wholeHandClearance(g.joints, distance) > -kSurface);
}

// The open hand started partly inside (more than 3 mm) and the grab moved it out whole: clear
// within 0.5 mm, by the offset the layer reports, with at least two fingers on the surface.
void checkMovedOut(const Grab& g, const Distance& distance) {
  CAPTURE(g.setup.readyCount, g.setup.failedCount);
  REQUIRE(wholeHandClearance(g.open, distance) < -0.003f);  // the scene is what it claims
  REQUIRE(g.grasped);
  CAPTURE(g.offset.openClearance, g.offset.displacement, wholeHandClearance(g.joints, distance));
  CHECK(g.offset.exceeded == XR_FALSE);
  CHECK(g.offset.openClearance < -0.003f);
  CHECK(g.offset.displacement > 0.003f);
  CHECK(wholeHandClearance(g.joints, distance) > -kSurface);
  int contacts = 0;
  for (const XrGraspFingerStateSDFG& f : g.state.fingers) contacts += f.inContact ? 1 : 0;
  CHECK(contacts >= 2);
}

// Two grabs of one surface ended alike: per finger, the same contact and the tip within 0.5 mm.
void checkSameAs(const Grab& g, const Grab& reference) {
  REQUIRE(g.grasped);
  REQUIRE(reference.grasped);
  for (int f = 0; f < 5; ++f) {
    const float moved = glm::length(vec(g.joints.joints[kTips[f]].pose.position) -
                                    vec(reference.joints.joints[kTips[f]].pose.position));
    CAPTURE(f, g.state.fingers[f].curl, reference.state.fingers[f].curl, moved);
    CHECK(g.state.fingers[f].inContact == reference.state.fingers[f].inContact);
    CHECK(moved <= kSurface);
  }
}

// A person's solid and a mesh of it that is not watertight; both checks of part c: grabbed from
// outside, the fingers stop on the solid's surface and nothing enters it; grabbed with the palm
// `depths` inside (5 mm unless a case probes deeper), the hand is moved out first.
void checkSolid(const TestMesh& mesh, const Solid& solid,
                std::initializer_list<float> depths = {0.005f}) {
  {
    INFO("grabbed from outside");
    const XrPosef pose = clearBelowPalm(solid);
    const Grab g = grab(mesh, pose);
    checkOnSurface(g, placed(solid, pose), pose);
  }
  for (float depth : depths) {
    INFO("grabbed with the palm " << depth * 1000.0f << " mm inside");
    const XrPosef pose = palmInside(solid, depth);
    const Grab g = grab(mesh, pose);
    checkMovedOut(g, placed(solid, pose));
  }
}

// Runs `body(path)` with everything written to stderr (the layer's log when no debug-utils
// messenger is set) going to the file `path`, which `body` may read as it goes; returns its text.
template <class F>
std::string withStderrCaptured(F body) {
  char path[] = "/tmp/sdfg_mesh_shapes_stderr_XXXXXX";
  const int fd = mkstemp(path);
  REQUIRE(fd >= 0);
  std::fflush(stderr);
  const int saved = dup(2);
  dup2(fd, 2);
  try {
    body(static_cast<const char*>(path));
  } catch (...) {
    std::fflush(stderr);
    dup2(saved, 2);
    close(saved);
    close(fd);
    std::remove(path);
    throw;
  }
  std::fflush(stderr);
  dup2(saved, 2);
  close(saved);
  close(fd);
  std::ifstream in(path);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::remove(path);
  return text;
}

std::string readFile(const char* path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// The lines of `log` that contain `needle`.
std::vector<std::string> linesWith(const std::string& log, const std::string& needle) {
  std::vector<std::string> out;
  std::istringstream in(log);
  for (std::string line; std::getline(in, line);)
    if (line.find(needle) != std::string::npos) out.push_back(line);
  return out;
}

// The indexed mesh grasped at `pose`, then its soup and its hard-edge split: each on the surface,
// each the same grasp as the indexed one.
void checkSplitsLikeIndexed(const TestMesh& indexed, const TestMesh& soup, const TestMesh& split,
                            const XrPosef& pose, const Distance& distance) {
  const Grab reference = grab(indexed, pose);
  checkOnSurface(reference, distance, pose);
  for (const auto& [name, mesh] : {std::pair{"soup", &soup}, std::pair{"hard edges", &split}}) {
    INFO(name);
    const Grab g = grab(*mesh, pose);
    checkOnSurface(g, distance, pose);
    checkSameAs(g, reference);
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// a. One surface, three ways of sharing its vertices.

TEST_CASE("A box as a triangle soup or with hard-edge splits is grasped as the indexed box",
          "[layer][mesh-shapes]") {
  const TestMesh indexed = weldExact(soupOf(boxTriangles({0.05f, 0.025f, 0.03f})));
  REQUIRE(indexed.vertices.size() == 8);
  const TestMesh soup = soupOf(indexed);
  const TestMesh split = hardEdgeSplit(indexed);
  REQUIRE(split.vertices.size() == 24);  // every face its own four corners
  const Solid exact = exactSolid(indexed);
  const XrPosef pose = clearBelowPalm(exact);
  const Distance distance = placed(exact, pose);

  checkSplitsLikeIndexed(indexed, soup, split, pose, distance);
}

TEST_CASE("The mug as a triangle soup or with hard-edge splits is grasped as the indexed mug",
          "[layer][mesh-shapes]") {
  const TestMesh indexed = toTestMesh(makeMug());
  const TestMesh soup = soupOf(indexed);
  const TestMesh split = hardEdgeSplit(indexed);
  REQUIRE(split.vertices.size() > indexed.vertices.size());  // the rims are hard edges
  const XrPosef pose = mugUnderRightPalm(indexed, kGrip);
  const Distance distance = placed(exactSolid(indexed), pose);

  checkSplitsLikeIndexed(indexed, soup, split, pose, distance);
}

TEST_CASE("An open hand 5 mm inside a soup box is moved out before closing, as for the indexed box",
          "[layer][mesh-shapes]") {
  const TestMesh indexed = weldExact(soupOf(boxTriangles({0.05f, 0.025f, 0.03f})));
  const TestMesh soup = soupOf(indexed);
  const Solid exact = exactSolid(indexed);
  const XrPosef pose = palmInside(exact, 0.005f);
  const Distance distance = placed(exact, pose);
  const Grab reference = grab(indexed, pose);
  checkMovedOut(reference, distance);
  const Grab g = grab(soup, pose);
  checkMovedOut(g, distance);
  // Moved out the same way: the reported move and where the hand ends.
  CHECK(std::abs(g.offset.displacement - reference.offset.displacement) <= kSurface);
  CHECK(glm::length(vec(g.joints.joints[XR_HAND_JOINT_PALM_EXT].pose.position) -
                    vec(reference.joints.joints[XR_HAND_JOINT_PALM_EXT].pose.position)) <=
        kSurface);
}

// ---------------------------------------------------------------------------------------------
// b. A sphere whose faces computed their own midpoints: without the weld the layer's set-up sees
// it as separate open pieces ("32 parts, 0 closed" for the octahedron), with it one closed part.

TEST_CASE("A 4 cm sphere subdivided with unshared midpoints is grasped under an open palm",
          "[layer][mesh-shapes]") {
  const auto [icosahedron, levels] = GENERATE(std::pair{false, 2}, std::pair{true, 2});
  CAPTURE(icosahedron, levels);
  const TestMesh sphere = unsharedSphere(icosahedron, levels, 0.02f);
  const TestMesh indexed = weldExact(sphere);
  // The positions do meet (the welded copy is a closed sphere: V - E + F = 2), only the indices
  // do not share them.
  const size_t faces = indexed.indices.size() / 3;
  REQUIRE(indexed.vertices.size() == faces / 2 + 2);
  REQUIRE(sphere.vertices.size() > indexed.vertices.size());
  const Solid exact = exactSolid(indexed);
  const XrPosef pose = clearBelowPalm(exact);
  const Grab reference = grab(indexed, pose);
  checkOnSurface(reference, placed(exact, pose), pose);
  const Grab g = grab(sphere, pose);
  checkOnSurface(g, placed(exact, pose), pose);
  checkSameAs(g, reference);
}

TEST_CASE("On a Vulkan session a soup box and an unshared-midpoint sphere are grasped as indexed",
          "[layer][mesh-shapes][vulkan]") {
  if (const std::string why = vulkanUnavailable(); !why.empty()) SDFG_SKIP(why);
  {
    INFO("the sphere, octahedron subdivided twice (32 separate pieces)");
    const TestMesh sphere = unsharedSphere(false, 2, 0.02f);
    const TestMesh indexed = weldExact(sphere);
    const Solid exact = exactSolid(indexed);
    const XrPosef pose = clearBelowPalm(exact);
    const Grab reference = grabOnGpu(indexed, pose);
    checkOnSurface(reference, placed(exact, pose), pose);
    const Grab g = grabOnGpu(sphere, pose);
    checkOnSurface(g, placed(exact, pose), pose);
    checkSameAs(g, reference);
  }
  {
    INFO("the box as a soup");
    const TestMesh indexed = weldExact(soupOf(boxTriangles({0.05f, 0.025f, 0.03f})));
    const Solid exact = exactSolid(indexed);
    const XrPosef pose = clearBelowPalm(exact);
    const Grab g = grabOnGpu(soupOf(indexed), pose);
    checkOnSurface(g, placed(exact, pose), pose);
  }
}

// ---------------------------------------------------------------------------------------------
// c. Not watertight. Each states what a person expects: the solid they would name is closed on
// from outside, never entered, and a palm put 5 mm into it is moved out.

TEST_CASE(
    "A cup without its bottom: the fingers stop on its wall, a palm inside the wall is moved "
    "out",
    "[layer][mesh-shapes]") {
  // The cup lies across the fingers (its axis along +X, the open bottom at the index side, 6 cm
  // from the palm's centre), its outer wall toward the palm. A person calls its 8 mm wall and
  // its floor solid, the missing bottom face notwithstanding.
  const Cup cup;
  const TestMesh mesh = weldExact(soupOf(cup.triangles(/*bottom=*/false)));
  checkSolid(mesh, [cup](const glm::vec3& p) { return cup.solid(p); });
}

TEST_CASE("A box with one face missing: closed on from outside, a palm inside it is moved out",
          "[layer][mesh-shapes]") {
  // The face away from the palm (-Y) is missing, as on props modelled never to be seen from
  // below; a person calls the whole box solid.
  const glm::vec3 half(0.05f, 0.025f, 0.03f);
  const TestMesh mesh =
      weldExact(soupOf(boxTriangles(-half, half, {1, 1, 0 /* -Y missing */, 1, 1, 1})));
  checkSolid(mesh, [half](const glm::vec3& p) { return boxSdf(p, -half, half); });
}

TEST_CASE(
    "Two closed boxes that cross: closed on from outside, a palm deep in their overlap is "
    "moved out",
    "[layer][mesh-shapes]") {
  // A plus sign under the palm: a 5 cm tall bar across the fingers and a 2 cm tall one along
  // them, each closed, crossing under the palm. A person calls their union solid, deep in the
  // overlap included: there the low bar's top face runs inside the tall one, 1.5 cm under its
  // top, so a palm 12 mm deep is nearer that inner face (from its outer side) than any face of
  // the outside, and the pseudo-normal of the nearest face alone would read it as outside.
  const glm::vec3 a(0.06f, 0.025f, 0.015f), b(0.015f, 0.01f, 0.06f);
  Triangles tris = boxTriangles(a);
  const Triangles other = boxTriangles(b);
  tris.insert(tris.end(), other.begin(), other.end());
  const TestMesh mesh = weldExact(soupOf(tris));
  checkSolid(mesh,
             [a, b](const glm::vec3& p) { return std::min(boxSdf(p, -a, a), boxSdf(p, -b, b)); },
             {0.005f, 0.012f});
}

TEST_CASE("A box with every triangle duplicated, same or reverse winding, is grasped as a box",
          "[layer][mesh-shapes]") {
  const glm::vec3 half(0.05f, 0.025f, 0.03f);
  const bool reversed = GENERATE(false, true);
  CAPTURE(reversed);  // reversed: double-sided, each face also wound the other way
  const TestMesh box = weldExact(soupOf(boxTriangles(half)));
  TestMesh mesh = box;
  for (size_t t = 0; t < box.indices.size(); t += 3) {
    if (reversed)
      mesh.indices.insert(mesh.indices.end(),
                          {box.indices[t], box.indices[t + 2], box.indices[t + 1]});
    else
      mesh.indices.insert(mesh.indices.end(),
                          {box.indices[t], box.indices[t + 1], box.indices[t + 2]});
  }
  checkSolid(mesh, [half](const glm::vec3& p) { return boxSdf(p, -half, half); });
}

TEST_CASE("A box with T-junctions (its top split 4 x 4, its sides not) is grasped as a box",
          "[layer][mesh-shapes]") {
  // The face toward the palm is split, the faces around it are not: its edge points lie on the
  // side faces' edges without being their vertices, so no edge of the rim is shared by index.
  const glm::vec3 half(0.05f, 0.025f, 0.03f);
  const TestMesh mesh = weldExact(soupOf(boxTriangles(-half, half, {1, 1, 1, 4, 1, 1})));
  checkSolid(mesh, [half](const glm::vec3& p) { return boxSdf(p, -half, half); });
}

TEST_CASE(
    "A box cut in two closed halves 1 mm apart: closed on from outside, a palm over the "
    "crack is moved out",
    "[layer][mesh-shapes]") {
  // Cut across the fingers (at x = 0), right under the palm; both halves solid, the 1 mm crack
  // far too narrow for any finger.
  const bool openHalves = GENERATE(false, true);
  CAPTURE(openHalves);  // true: each half lacks its face toward the crack (open toward the other)
  const glm::vec3 half(0.05f, 0.025f, 0.03f);
  const glm::vec3 loA(-half.x - 0.0005f, -half.y, -half.z), hiA(-0.0005f, half.y, half.z);
  const glm::vec3 loB(0.0005f, -half.y, -half.z), hiB(half.x + 0.0005f, half.y, half.z);
  Triangles tris = boxTriangles(loA, hiA, {1, openHalves ? 0 : 1, 1, 1, 1, 1});
  const Triangles b = boxTriangles(loB, hiB, {openHalves ? 0 : 1, 1, 1, 1, 1, 1});
  tris.insert(tris.end(), b.begin(), b.end());
  const TestMesh mesh = weldExact(soupOf(tris));
  checkSolid(
      mesh, [=](const glm::vec3& p) { return std::min(boxSdf(p, loA, hiA), boxSdf(p, loB, hiB)); });
}

// ---------------------------------------------------------------------------------------------
// d. The set-up's log line says what the weld did.

TEST_CASE("The set-up log line of a soup says its split vertices were welded",
          "[layer][mesh-shapes]") {
  const TestMesh indexed = weldExact(soupOf(boxTriangles({0.05f, 0.025f, 0.03f})));
  const TestMesh soup = soupOf(indexed);
  TestMesh doubled = indexed;  // every triangle twice
  doubled.indices.insert(doubled.indices.end(), indexed.indices.begin(), indexed.indices.end());
  std::map<std::string, XrGraspTargetSDFG> targets;
  const std::string log = withStderrCaptured([&](const char* path) {
    XrEnv env;
    env.handTracking = "absent";
    env.extra = {{"SDFG_AUTOGRASP_LOG_LEVEL", "info"}};
    applyEnv(env);
    App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME}});
    REQUIRE(app.ok());
    Ext ext(app);
    // Far apart and out of reach: only the set-ups matter.
    targets["indexed"] = makeTarget(app, ext, indexed, {{0, 0, 0, 1}, {0, 5, 0}});
    targets["soup"] = makeTarget(app, ext, soup, {{0, 0, 0, 1}, {1, 5, 0}});
    targets["doubled"] = makeTarget(app, ext, doubled, {{0, 0, 0, 1}, {2, 5, 0}});
    REQUIRE(untilSetUp(app, ext, [](const auto& s) { return s.readyCount == 3; }));
    // The lines are written from the next xrSyncActions after the set-ups: frames until they
    // are (a bound, not a count).
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (std::chrono::steady_clock::now() < until) {
      app.frame();
      std::fflush(stderr);
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      if (linesWith(readFile(path), "mesh wound").size() >= 3) break;
    }
    CHECK(validationLog().empty());
  });
  unsetenv("SDFG_AUTOGRASP_LOG_LEVEL");
  CAPTURE(log);
  auto lineOf = [&](const std::string& name) {
    char id[32];
    std::snprintf(id, sizeof id, "target %#llx:",
                  static_cast<unsigned long long>(reinterpret_cast<uintptr_t>(targets[name])));
    const auto lines = linesWith(log, id);
    CAPTURE(name, id);
    REQUIRE(lines.size() == 1);  // once per target
    return lines.front();
  };
  const std::string soupLine = lineOf("soup");
  CAPTURE(soupLine);
  // 12 triangles of 3 vertices each, 8 corners: all 36 welded into 8, one closed part.
  CHECK(soupLine.find("36 split vertices welded into 8") != std::string::npos);
  CHECK(soupLine.find("(1 parts, 1 closed)") != std::string::npos);
  const std::string indexedLine = lineOf("indexed");
  CAPTURE(indexedLine);
  CHECK(indexedLine.find("no split vertices") != std::string::npos);
  CHECK(indexedLine.find("(1 parts, 1 closed)") != std::string::npos);
  const std::string doubledLine = lineOf("doubled");
  CAPTURE(doubledLine);
  CHECK(doubledLine.find("12 duplicate triangles dropped") != std::string::npos);
  CHECK(doubledLine.find("(1 parts, 1 closed)") != std::string::npos);
}

// ---------------------------------------------------------------------------------------------
// e. New vertices for a split mesh (xrUpdateGraspTargetVerticesSDFG, skinned meshes).

TEST_CASE("New vertices for a soup sphere move the surface the hand closes on",
          "[layer][mesh-shapes]") {
  const float r0 = 0.025f, scale = 1.3f;
  const TestMesh small = soupOf(makeIcosphere(r0, 3));
  TestMesh large = small;
  for (XrVector3f& v : large.vertices) v = {v.x * scale, v.y * scale, v.z * scale};
  const Solid smallSolid = exactSolid(weldExact(small)), largeSolid = exactSolid(weldExact(large));
  // Placed for the larger sphere (same centre): both shapes start clear of the open hand.
  const XrPosef pose = clearBelowPalm(largeSolid);
  const Distance smallAt = placed(smallSolid, pose), largeAt = placed(largeSolid, pose);

  XrEnv env;
  env.handTracking = "absent";
  env.script = gripLine(0, "right", kGrip) + squeezeLine(0, "right", 0.0f);
  applyEnv(env);
  App app({{XR_SDFG_AUTO_GRASP_EXTENSION_NAME, XR_EXT_HAND_TRACKING_EXTENSION_NAME}});
  REQUIRE(app.ok());
  Ext ext(app);
  XrHandTrackerEXT tracker = makeTracker(app, ext, XR_HAND_RIGHT_EXT);
  const XrGraspTargetSDFG target = makeTarget(app, ext, small, pose);
  REQUIRE(untilSetUp(app, ext, [](const auto& s) { return s.readyCount == 1; }));
  app.frames(2);  // the hand is located at a frame's time: there is one from here on
  auto squeeze = [&](float value) {
    REQUIRE(app.setScript(gripLine(0, "right", kGrip) +
                          squeezeLine(app.framesEnded + 1, "right", value)) == XR_SUCCESS);
  };
  auto update = [&](const TestMesh& m) {
    XrGraspTargetVerticesSDFG v{XR_TYPE_GRASP_TARGET_VERTICES_SDFG};
    v.vertexCount = uint32_t(m.vertices.size());
    v.vertices = m.vertices.data();
    REQUIRE(ext.update(target, &v) == XR_SUCCESS);
  };
  Grab g;
  auto grasped = [&] {
    return app.framesUntil(
        [&] {
          readHand(app, ext, tracker, g);
          return g.state.isGrasping && g.offset.blend >= 1.0f;
        },
        std::chrono::seconds(45));
  };

  INFO("the soup as given");
  squeeze(1.0f);
  g.grasped = grasped();
  checkOnSurface(g, smallAt, pose);
  const float smallTip = glm::length(
      vec(g.joints.joints[XR_HAND_JOINT_MIDDLE_TIP_EXT].pose.position) - vec(pose.position));
  squeeze(0.0f);
  REQUIRE(app.framesUntil([&] {
    readHand(app, ext, tracker, g);
    return !g.state.isGrasping;
  }));

  INFO("grown by 30 % while released, then grabbed");
  update(large);
  squeeze(1.0f);
  g.grasped = grasped();
  checkOnSurface(g, largeAt, pose);
  const float largeTip = glm::length(
      vec(g.joints.joints[XR_HAND_JOINT_MIDDLE_TIP_EXT].pose.position) - vec(pose.position));
  CHECK(largeTip > smallTip + 0.005f);  // the fingers stopped on the new, larger surface

  INFO("shrunk back while held: the held grasp is solved again onto the new surface");
  update(small);
  const bool settled = app.framesUntil(
      [&] {
        readHand(app, ext, tracker, g);
        if (!g.state.isGrasping) return false;
        int on = 0;
        for (int f = 0; f < 5; ++f)
          if (g.state.fingers[f].inContact && std::abs(fingerGap(g.joints, f, smallAt)) <= kSurface)
            ++on;
        return on >= 3;
      },
      std::chrono::seconds(45));
  CHECK(settled);
  checkOnSurface(g, smallAt, pose);
  CHECK(validationLog().empty());
}
