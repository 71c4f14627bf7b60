#include "table_scene.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <numbers>
#include <optional>
#include <thread>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "grasp/grasp_session.h"
#include "hand/hand_synthesis.h"
#include "io/shapes.h"
#include "png_io.h"
#include "scene.h"
#include "sdf/sdf_backend.h"

namespace sdfg::demo {
namespace {

using Clock = std::chrono::steady_clock;

// Frames are paced as an app's would be (90 Hz); a grasp not shown within the bound failed.
constexpr auto kFrame = std::chrono::microseconds(11111);
constexpr auto kGraspBound = std::chrono::seconds(20);
constexpr auto kSetupBound = std::chrono::seconds(20);
constexpr uint64_t kSpace = 1;  // the one space everything is placed in (the world)

struct Object {
  uint64_t id = 0;
  std::string name;
  TriangleMesh mesh;  // drawn (the table's too, made from its box)
  std::optional<AnalyticShape> shape;
  std::unique_ptr<MeshDistance> distance;  // meshes: the exact distance for the report
  Pose worldFromObject;
  glm::vec3 colour;

  float signedDistance(const glm::vec3& world) const {
    const glm::vec3 p = worldFromObject.inverse().transformPoint(world);
    return shape ? shape->signedDistance(p) : distance->signedDistance(p);
  }
};

struct Placement {
  std::string aim;      // the object the hand is put on
  Pose worldFromWrist;  // the open hand
};

struct Grasp {
  SceneGraspRow row;
  HandPose hand;
  std::vector<glm::vec3> contacts;  // world
  Aabb focus;                       // the hand and what it holds: the close-up's framing
};

std::string nameOf(const std::vector<Object>& objects, uint64_t id) {
  for (const auto& o : objects)
    if (o.id == id) return o.name;
  return id == 0 ? "nothing" : "target " + std::to_string(id);
}

// One squeeze of the right hand at `worldFromWrist`, until the session shows a grasp (or the
// bound passes), then the release.
Grasp graspOnce(GraspSession& session, const std::vector<Object>& objects,
                const Pose& worldFromWrist, const std::string& aim) {
  Grasp g;
  g.row.aim = aim;
  const SpaceFrame world{kSpace, true, Pose{}};
  HandFrame frame;
  frame.valid = true;
  frame.worldFromWrist = worldFromWrist;
  auto step = [&](float squeeze) {
    frame.squeeze = squeeze;
    ++frame.time;
    const Status st = session.update(Hand::right, frame, std::span(&world, 1));
    std::this_thread::sleep_for(kFrame);
    return st;
  };
  step(0.0f);  // the open hand arrives
  const auto squeezed = Clock::now();
  while (!session.grasp(Hand::right).shown()) {
    if (const Status st = step(1.0f); st != Status::ok) {
      g.row.error = std::string("the session refused the grasp: ") + toString(st);
      break;
    }
    if (Clock::now() - squeezed > kGraspBound) {
      g.row.error = "no grasp shown within 20 s";
      break;
    }
  }
  const HandGrasp& held = session.grasp(Hand::right);
  g.row.ok = held.shown();
  g.row.milliseconds = std::chrono::duration<double, std::milli>(Clock::now() - squeezed).count();
  const GraspResult& r = held.result;
  const Pose shownWrist = worldFromWrist * (g.row.ok ? r.handCorrection : Pose{});
  std::array<JointCurls, kFingerCount> curls{};
  for (int f = 0; f < kFingerCount && g.row.ok; ++f) curls[size_t(f)] = r.fingers[f].jointCurls;
  g.hand = modelHand(session.model(Hand::right), curls, shownWrist);
  g.row.took = g.row.ok ? nameOf(objects, held.target) : "-";
  g.row.handMovedMm = g.row.ok ? r.handMoved * 1000.0f : 0.0f;
  for (int f = 0; f < kFingerCount; ++f) {
    g.row.curl[size_t(f)] = g.row.ok ? r.fingers[f].curl : 0.0f;
    const bool contact = g.row.ok && r.fingers[f].contact;
    g.row.touched[size_t(f)] =
        contact && held.touched[size_t(f)] != 0 ? nameOf(objects, held.touched[size_t(f)]) : "-";
    if (contact) {
      ++g.row.contacts;
      if (held.target != 0 && held.touched[size_t(f)] == held.target) ++g.row.fingersOnTaken;
      g.contacts.push_back(shownWrist.transformPoint(r.fingers[f].contactPoint));
    }
  }
  g.row.tableMm = g.row.objectsMm = std::numeric_limits<float>::infinity();
  for (const auto& o : objects) {
    const float c =
        1000.0f * leastClearance(g.hand, [&](const glm::vec3& p) { return o.signedDistance(p); });
    float& into = o.shape ? g.row.tableMm : g.row.objectsMm;
    into = std::min(into, c);
  }
  g.focus = handBounds(g.hand);
  for (const auto& o : objects) {
    if (o.name != g.row.took) continue;
    const Aabb b = computeBounds(o.mesh.positions);
    g.focus.min = glm::min(g.focus.min, b.min + o.worldFromObject.position);
    g.focus.max = glm::max(g.focus.max, b.max + o.worldFromObject.position);
  }
  // Let go, and wait for the hand to open before the next placement.
  const auto released = Clock::now();
  while (session.grasp(Hand::right).holding && Clock::now() - released < kGraspBound) step(0.0f);
  return g;
}

}  // namespace

bool runTableScene(Renderer& renderer, const TableSceneOptions& options, SceneReport& report,
                   std::string& error) {
  // World: y up, the table top at y = 0; the mug (handle to +X) and the block 21 cm apart, a
  // comb lying in front of the block.
  std::vector<Object> objects;
  {
    Object table;
    table.id = 1;
    table.name = "table";
    table.shape = AnalyticShape{ShapeKind::box, glm::vec3(0.25f, 0.02f, 0.2f)};
    table.mesh = makeBox(2.0f * table.shape->halfExtents);
    table.worldFromObject = Pose{glm::quat(1, 0, 0, 0), glm::vec3(0.0f, -0.02f, 0.03f)};
    table.colour = kTableColour;
    objects.push_back(std::move(table));
    Object mug;
    mug.id = 2;
    mug.name = "mug";
    mug.mesh = makeMug();  // 9.5 cm tall, centred on its origin
    mug.worldFromObject = Pose{glm::quat(1, 0, 0, 0), glm::vec3(-0.11f, 0.0475f, 0.0f)};
    mug.colour = kObjectColour;
    objects.push_back(std::move(mug));
    Object block;
    block.id = 3;
    block.name = "block";
    block.mesh = makeBox(glm::vec3(0.06f, 0.05f, 0.10f));
    block.worldFromObject = Pose{glm::quat(1, 0, 0, 0), glm::vec3(0.10f, 0.025f, 0.0f)};
    block.colour = kObjectColour;
    objects.push_back(std::move(block));
    Object comb;  // flat: no finger reaches under it, they close past it onto the table
    comb.id = 4;
    comb.name = "comb";
    comb.mesh = makeBox(glm::vec3(0.025f, 0.006f, 0.12f));
    comb.worldFromObject = Pose{glm::quat(1, 0, 0, 0), glm::vec3(0.10f, 0.003f, 0.13f)};
    comb.colour = kObjectColour;
    objects.push_back(std::move(comb));
  }
  // The right hand round the mug's body from its front left, upright (the thumb up, the little
  // finger down by the table), as a controller's handle 3.5 cm out of the mug's axis would sit;
  // then palm down over the block, the fingers across it toward +X; then the same over the
  // comb. The little finger and the fingertips end near the table, which they must stop on.
  GraspSession session(makeCpuSdfBackend(1));
  const HandModel& model = session.model(Hand::right);
  const glm::vec3 outward = glm::normalize(glm::vec3(-1.0f, 0.0f, 0.6f));
  const Pose aroundMug =
      gripAround(model, glm::vec3(-0.11f, 0.045f, 0.0f) + 0.035f * outward, {0, 1, 0}, outward) *
      wristFromGrip(model).inverse();
  JointPoses open;
  model.pose(FingerCurls{}, open);
  const glm::quat fingersToX =
      glm::angleAxis(-0.5f * std::numbers::pi_v<float>, glm::vec3(0, 1, 0));
  // The palm's surface 8 mm over the block's top, 1.5 cm toward the wrist from its middle.
  const glm::vec3 palm(0.085f, 0.05f + model.jointRadius(Joint::palm) + 0.008f, 0.0f);
  const Pose overBlock{fingersToX, palm - fingersToX * open[size_t(Joint::palm)].position};
  const glm::vec3 palmOverComb(0.10f, 0.006f + model.jointRadius(Joint::palm) + 0.008f, 0.13f);
  const Pose overComb{fingersToX, palmOverComb - fingersToX * open[size_t(Joint::palm)].position};
  const std::vector<Placement> placements = {
      {"mug", aroundMug}, {"block", overBlock}, {"comb", overComb}};
  report.description =
      "A table top (an analytic box, role scene: the hands stop on it and never take it) with "
      "a mug, a 6 x 5 x 10 cm block and a 12 cm comb 6 mm thick on it, registered in one "
      "`GraspSession` (the engine the layer runs) with the `ours` strategy. The right hand is "
      "placed round the mug (upright, the little finger by the table), then palm down over the "
      "block, then over the comb, and squeezes; the fingers close on everything in the grab "
      "box, and the session takes the graspable object the hand touches "
      "(grasp/target_choice.h: the one most fingers touch; the comb, which no finger reaches "
      "under, is taken because the palm touches it while the fingers rest on the table). "
      "Left: every grasp in the scene; then each close up. Table grey-green, objects "
      "blue-grey, contacts magenta. Clearances are the least exact distance of the hand's "
      "surface (palm sphere, finger capsules) from the table and from the objects; negative: "
      "that deep inside.";

  GraspSettings settings;
  settings.solver = "ours";
  if (session.configure(settings) != Status::ok) {
    error = "the grasp session refused the settings";
    return false;
  }
  for (auto& o : objects) {
    Status st = Status::ok;
    if (o.shape) {
      st = session.addShapeTarget(o.id, *o.shape);
      if (st == Status::ok) st = session.setTargetRole(o.id, TargetRole::scene);
    } else {
      auto d = MeshDistance::create(o.mesh);
      if (!d) {
        error = o.name + ": " + d.error().message;
        return false;
      }
      o.distance = std::move(*d);
      st = session.addTarget(o.id, o.mesh);
    }
    if (st == Status::ok) st = session.placeTarget(o.id, kSpace, o.worldFromObject);
    if (st != Status::ok) {
      error = "the grasp session refused the " + o.name + ": " + toString(st);
      return false;
    }
  }
  if (!session.waitWorkerIdle(kSetupBound)) {
    error = "the grasp session did not set the scene up within 20 s";
    return false;
  }
  for (const auto& [id, why] : session.takeSetupFailures()) {
    error = nameOf(objects, id) + ": " + why;
    return false;
  }

  std::vector<Grasp> grasps;
  for (const auto& p : placements) {
    grasps.push_back(graspOnce(session, objects, p.worldFromWrist, p.aim));
    report.grasps.push_back(grasps.back().row);
  }

  // The picture: the whole table with both hands, then each grasp close up.
  const uint32_t w = options.width, gap = 4;
  const uint32_t totalW = uint32_t(grasps.size() + 1) * w + uint32_t(grasps.size()) * gap;
  std::vector<uint8_t> picture(size_t(totalW) * w * 4, 255);
  const glm::vec3 toCamera = glm::normalize(glm::vec3(0.25f, 0.75f, 1.0f));
  for (size_t panel = 0; panel <= grasps.size(); ++panel) {
    DrawList list;
    for (const auto& o : objects) appendMesh(list.lit, o.mesh, o.worldFromObject, o.colour);
    for (size_t k = 0; k < grasps.size(); ++k) {
      if (panel != 0 && panel != k + 1) continue;
      appendHand(list.lit, grasps[k].hand, kHandColour);
      for (const auto& q : grasps[k].contacts)
        appendSphere(list.overlay, q, panel == 0 ? 0.005f : 0.004f, kContactColour, true);
    }
    glm::vec3 centre(0.02f, 0.04f, 0.05f);
    float radius = 0.3f;
    if (panel > 0) {
      const Aabb& b = grasps[panel - 1].focus;
      centre = 0.5f * (b.min + b.max);
      radius = 0.5f * glm::length(b.max - b.min);
    }
    glm::vec3 light;
    const glm::mat4 vp = lookCamera(centre, radius, toCamera, {0, 1, 0}, 1.0f, light);
    if (!renderPanel(renderer, list, vp, light, w, w, options.supersample, picture, totalW,
                     uint32_t(panel) * (w + gap), 0, error))
      return false;
  }
  const std::string path = (std::filesystem::path(options.outDir) / options.png).string();
  if (!writePng(path, totalW, w, picture, error)) return false;
  report.png = options.png;
  return true;
}

}  // namespace sdfg::demo
