// autograsp-demo: the whole system at work with no headset and no GPU. An OpenXR app (this
// program) goes through the real Khronos loader, the SDF Autograsp layer and the mock runtime,
// registers objects with XR_SDFG_auto_grasp, scripts the right controller onto each, squeezes,
// reads the auto-grasped hand back with xrLocateHandJointsEXT and the grasp state, and renders
// the result with Vulkan (lavapipe on a machine without a GPU) into PNG files and a report. Then,
// in this process on the engine the layer runs, a table scene grasped object by object
// (table_scene.h) and the outer hand keeping a hand out of a table it is pushed into
// (outer_sequence.h).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "build_info.h"
#include "cli_options.h"
#include "demo_config.h"
#include "eval/solver_physics.h"
#include "eval/strategies.h"
#include "grasp/solver.h"
#include "hand/hand_synthesis.h"
#include "io/mesh_io.h"
#include "io/shapes.h"
#include "outer_sequence.h"
#include "png_io.h"
#include "renderer.h"
#include "report.h"
#include "scene.h"
#include "sdf/sdf_cpu.h"
#include "table_scene.h"
#include "xr_app.h"

namespace fs = std::filesystem;
using namespace sdfg;
using namespace sdfg::demo;

namespace {

constexpr uint32_t kSupersample = 2;         // renders at 2x and filters down: smooth edges
constexpr float kHandSizedDiagonal = 0.18f;  // metres: files are scaled to hand size
constexpr uint32_t kSliceResolution = 64;    // nodes per axis of the SDF in the slice picture

struct Options {
  std::string out = "out/demo";
  std::vector<std::string> meshes;
  bool embeddedOnly = false;
  uint32_t width = 640;
  uint32_t resolution = 0;  // 0: the layer's default
};

void usage(FILE* f) {
  std::fprintf(
      f,
      "usage: autograsp-demo [--out DIR] [--mesh FILE]... [--embedded-only] [--width N]\n"
      "                      [--resolution N] [--help]\n\n"
      "Grasps objects through OpenXR (Khronos loader, SDF Autograsp layer, mock runtime)\n"
      "with the physics-convex, paper and ours strategies from the same hand placement,\n"
      "renders them with Vulkan and writes PNG pictures and a report. Then, with the\n"
      "engine in this process: a table scene (a mug, a block and a comb on a table top)\n"
      "grasped, and the outer hand (a hand pushed into a table, tracked and shown).\n\n"
      "  --out DIR         output folder (default out/demo)\n"
      "  --mesh FILE       also grasp this OBJ or PLY file (repeatable); scaled to hand size\n"
      "  --embedded-only   only the built-in mug, torus and thin plate (not %s)\n"
      "  --width N         width of each picture panel in pixels, 256..2048 (default 640)\n"
      "  --resolution N    grab-box SDF nodes per axis, 2..128 (default: the layer's, 16)\n\n"
      "Without XR_RUNTIME_JSON the demo uses this build's mock runtime; without\n"
      "XR_ENABLE_API_LAYERS / XR_API_LAYER_PATH it enables this build's layer.\n"
      "Exit status: 0 all grasped, 1 some mesh or grasp failed (the rest still ran), 2 setup\n"
      "failed.\n",
      SDFG_DEMO_SHARED_MESHES);
}

// Fills `o`; false after printing why (exit 2). --help prints the usage and exits 0.
bool parse(int argc, char** argv, Options& o) {
  namespace cli = tools::cli;
  CLI::App app{"", "autograsp-demo"};
  bool help = false;
  cli::addHelpFlag(app, help);
  cli::addName(app, "--out", o.out, "folder name");
  cli::addRepeatable(app, "--mesh", o.meshes);
  app.add_flag("--embedded-only", o.embeddedOnly);
  cli::addInteger(app, "--width", o.width, 256, 2048);
  cli::addInteger(app, "--resolution", o.resolution, kMinGridResolution, kMaxGridResolution);
  if (auto error = cli::parse(app, argc, argv)) {
    std::fprintf(stderr, "autograsp-demo: %s (see --help)\n", error->c_str());
    return false;
  }
  if (help) {
    usage(stdout);
    std::exit(0);
  }
  return true;
}

// One line that rewrites itself on a terminal; plain lines otherwise (logs, CI).
class Progress {
 public:
  Progress() : tty_(isatty(STDERR_FILENO) != 0) {}
  void step(size_t index, size_t count, const std::string& object, const std::string& what) {
    if (tty_)
      std::fprintf(stderr, "\r\033[K[%zu/%zu] %s: %s", index, count, object.c_str(), what.c_str());
    else
      std::fprintf(stderr, "[%zu/%zu] %s: %s\n", index, count, object.c_str(), what.c_str());
    std::fflush(stderr);
  }
  // A message that must stay on screen.
  void note(const std::string& text) {
    if (tty_) std::fprintf(stderr, "\r\033[K");
    std::fprintf(stderr, "autograsp-demo: %s\n", text.c_str());
  }
  void done() {
    if (tty_) std::fprintf(stderr, "\r\033[K");
  }

 private:
  bool tty_;
};

struct Candidate {
  std::string name;
  std::string origin;  // "embedded" or the path
  std::string path;    // empty for embedded objects
  TriangleMesh mesh;
};

std::string fileStem(const std::string& name) {
  std::string s;
  for (char c : name) s += (std::isalnum(static_cast<unsigned char>(c)) || c == '-') ? c : '_';
  return s;
}

XrPosef toXr(const Pose& p) {
  return {{p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w},
          {p.position.x, p.position.y, p.position.z}};
}
Pose fromXr(const XrPosef& p) {
  return {glm::quat(p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z),
          glm::vec3(p.position.x, p.position.y, p.position.z)};
}

// The hand placement on an object, as objectFromGrip: around a handle-like part for the
// embedded objects (a grip closes round its handle), seeded on the surface for any other.
Pose placementFor(const Candidate& c, const HandModel& model, const MeshDistance& distance,
                  uint32_t seed) {
  if (c.path.empty() && c.name == "mug")  // the handle's outer bar (shapes.h: tube on +X)
    return gripAround(model, {0.066f, 0.0f, 0.0f}, {0, 1, 0}, {1, 0, 0});
  if (c.path.empty() && c.name == "torus")  // the ring's tube at +X, running along Z
    return gripAround(model, {0.05f, 0.0f, 0.0f}, {0, 0, 1}, {1, 0, 0});
  if (c.path.empty() && c.name == "thin-plate")  // the plate's edge at +X, 1.5 cm into the hand
    return gripAround(model, {0.055f, 0.0f, 0.0f}, {0, 0, 1}, {1, 0, 0});
  return seededGrip(model, distance, seed);
}

// Exact quality of one finger: the tip sphere's gap, and the least clearance of the finger's
// capsules (joint radii) sampled along its bones, both against the real mesh.
void exactFinger(const HandPose& hand, int f, const MeshDistance& distance,
                 const Pose& objectFromWorld, FingerRow& row) {
  const auto joints = fingerJoints(Finger(f));
  auto d = [&](const glm::vec3& p) {
    return distance.signedDistance(objectFromWorld.transformPoint(p));
  };
  const size_t tip = size_t(joints.back());
  row.tipGapMm = (d(hand.positions[tip]) - hand.radii[tip]) * 1000.0f;
  float least = 1e9f;
  // From the first bone that moves out of the palm (the thumb's metacarpal moves; the others'
  // sit inside the palm).
  for (size_t j = (f == 0 ? 0 : 1); j + 1 < joints.size(); ++j) {
    const size_t a = size_t(joints[j]), b = size_t(joints[j + 1]);
    for (int s = 0; s <= 4; ++s) {
      const float t = float(s) / 4.0f;
      const glm::vec3 p = glm::mix(hand.positions[a], hand.positions[b], t);
      const float r = glm::mix(hand.radii[a], hand.radii[b], t);
      least = std::min(least, d(p) - r);
    }
  }
  row.clearanceMm = least * 1000.0f;
}

// Least exact clearance of the whole hand, mm (negative: inside): the palm's sphere and every
// bone's capsule from the metacarpal joint to the tip, radii interpolated between the joints.
float wholeHandClearanceMm(const HandPose& hand, const MeshDistance& distance,
                           const Pose& objectFromWorld) {
  auto d = [&](const glm::vec3& p) {
    return distance.signedDistance(objectFromWorld.transformPoint(p));
  };
  const size_t palm = size_t(Joint::palm);
  float least = d(hand.positions[palm]) - hand.radii[palm];
  for (int f = 0; f < kFingerCount; ++f) {
    const auto joints = fingerJoints(Finger(f));
    for (size_t j = 0; j + 1 < joints.size(); ++j) {
      const size_t a = size_t(joints[j]), b = size_t(joints[j + 1]);
      for (int s = 0; s <= 8; ++s) {
        const float t = float(s) / 8.0f;
        least = std::min(least, d(glm::mix(hand.positions[a], hand.positions[b], t)) -
                                    glm::mix(hand.radii[a], hand.radii[b], t));
      }
    }
  }
  return least * 1000.0f;
}

HandPose handFromJoints(const HandJoints& j) {
  HandPose h;
  for (int k = 0; k < kJointCount; ++k) {
    h.positions[k] = fromXr(j.poses[k]).position;
    h.radii[k] = j.radii[k];
  }
  h.worldFromWrist = fromXr(j.poses[XR_HAND_JOINT_WRIST_EXT]);
  return h;
}

struct Panel {
  HandPose hand;
  std::vector<glm::vec3> contacts;  // world
};

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  if (!parse(argc, argv, opt)) return 2;
  const auto started = std::chrono::steady_clock::now();
  Progress progress;

  std::error_code ec;
  fs::create_directories(opt.out, ec);
  if (ec || !fs::is_directory(opt.out)) {
    std::fprintf(stderr, "autograsp-demo: cannot create the output folder %s: %s\n",
                 opt.out.c_str(), ec.message().c_str());
    return 2;
  }

  // Objects: the embedded ones, the shared meshes when present, then the user's files.
  std::vector<Candidate> candidates;
  for (auto& e : embeddedObjects())
    candidates.push_back({e.name, "embedded", "", std::move(e.mesh)});
  std::vector<std::string> files;
  if (!opt.embeddedOnly && fs::is_directory(SDFG_DEMO_SHARED_MESHES, ec)) {
    for (const auto& entry : fs::directory_iterator(SDFG_DEMO_SHARED_MESHES, ec)) {
      const std::string ext = entry.path().extension().string();
      if (ext == ".obj" || ext == ".ply") files.push_back(entry.path().string());
    }
    std::sort(files.begin(), files.end());
  }
  files.insert(files.end(), opt.meshes.begin(), opt.meshes.end());
  for (const auto& f : files) candidates.push_back({fs::path(f).filename().string(), f, f, {}});

  ReportInfo info;
  info.width = int(opt.width);
  info.environment = prepareEnvironment();
  info.commit = tools::describeBuild();
  XrApp app;
  std::string error;
  if (!app.init(error)) {
    std::fprintf(stderr, "autograsp-demo: %s\n", error.c_str());
    return 2;
  }
  info.runtime = app.runtimeName();
  info.device = app.deviceName();
  Renderer renderer;
  if (!renderer.init(app.vkPhysicalDevice(), app.vkDevice(), app.queueFamily(), app.queue(),
                     error)) {
    std::fprintf(stderr, "autograsp-demo: Vulkan renderer: %s\n", error.c_str());
    return 2;
  }
  CpuSdfBuilder sdfBuilder(2);
  const HandModel model = HandModel::defaultAdult(Hand::right);
  const Pose worldFromObject{glm::quat(1, 0, 0, 0), glm::vec3(0.0f, -0.3f, -0.5f)};
  const Pose objectFromWorld = worldFromObject.inverse();

  std::vector<ObjectResult> results;
  std::vector<std::string> written;
  bool anyFailure = false;
  for (size_t i = 0; i < candidates.size(); ++i) {
    Candidate& c = candidates[i];
    const size_t index = i + 1, count = candidates.size();
    // `why` names the file itself when it comes from loadMesh (its messages start with it).
    auto fail = [&](const std::string& why, bool namesFile = false) {
      const std::string what = namesFile ? why : c.origin + ": " + why;
      progress.note("skipping " + what);
      info.failures.push_back(what);
      anyFailure = true;
    };
    if (!c.path.empty()) {
      progress.step(index, count, c.name, "loading");
      auto loaded = loadMesh(c.path);
      if (!loaded) {
        fail(loaded.error().message, /*namesFile=*/true);
        continue;
      }
      c.mesh = normalizedToDiagonal(loaded->mesh, kHandSizedDiagonal);
    }
    auto distance = MeshDistance::create(c.mesh);
    if (!distance) {
      fail(distance.error().message);
      continue;
    }
    std::vector<XrVector3f> vertices;
    vertices.reserve(c.mesh.positions.size());
    for (const auto& p : c.mesh.positions) vertices.push_back({p.x, p.y, p.z});
    XrGraspTargetSDFG target = XR_NULL_HANDLE;
    progress.step(index, count, c.name, "registering the grasp target");
    if (!app.createTarget(vertices, c.mesh.indices, toXr(worldFromObject), target, error)) {
      fail(error);
      continue;
    }
    const Pose objectFromGrip = placementFor(c, model, **distance, uint32_t(1000 + i));
    const XrPosef grip = toXr(worldFromObject * objectFromGrip);

    ObjectResult result;
    result.name = c.name;
    result.origin = c.path.empty()
                        ? "embedded object"
                        : c.path + " (scaled to a " +
                              std::to_string(int(kHandSizedDiagonal * 100)) + " cm diagonal)";
    result.triangles = c.mesh.triangleCount();
    std::array<Panel, 3> panels{};
    HandJoints openHand;
    bool haveOpen = false;
    const std::pair<const char*, XrGraspSolverSDFG> layerStrategies[2] = {
        {"paper", XR_GRASP_SOLVER_PAPER_SDFG}, {"ours", XR_GRASP_SOLVER_OURS_SDFG}};
    std::vector<StrategyResult> layerResults;
    for (int s = 0; s < 2; ++s) {
      progress.step(index, count, c.name,
                    std::string("grasping through OpenXR, ") + layerStrategies[s].first);
      GraspReading r = app.grasp(target, grip, layerStrategies[s].second, opt.resolution);
      StrategyResult sr;
      sr.name = layerStrategies[s].first;
      sr.source = "layer";
      sr.ok = r.grasped && r.error.empty();
      sr.error = r.error;
      sr.frames = r.frames;
      sr.milliseconds = r.milliseconds;
      if (!haveOpen && r.error.find("not active") == std::string::npos) {
        openHand = r.openJoints;
        haveOpen = true;
      }
      Panel& panel = panels[size_t(s) + 1];
      panel.hand = handFromJoints(r.grasped ? r.joints : r.openJoints);
      for (int f = 0; f < 5; ++f) {
        const XrGraspFingerStateSDFG& fs = r.state.fingers[f];
        FingerRow& row = sr.fingers[size_t(f)];
        row.curl = fs.curl;
        row.contact = r.grasped && fs.inContact;
        row.reportedMm = fs.distance * 1000.0f;
        exactFinger(panel.hand, f, **distance, objectFromWorld, row);
        if (row.contact) {
          ++sr.contacts;
          const XrVector3f& p = fs.contactPoint;
          panel.contacts.push_back(worldFromObject.transformPoint({p.x, p.y, p.z}));
        }
      }
      sr.wholeHandMm = wholeHandClearanceMm(panel.hand, **distance, objectFromWorld);
      sr.handMovedMm = r.grasped ? r.offset.displacement * 1000.0f : 0.0f;
      sr.openClearanceMm = r.grasped ? r.offset.openClearance * 1000.0f : 0.0f;
      if (!sr.ok) anyFailure = true;
      layerResults.push_back(sr);
    }
    app.destroyTarget(target);
    if (!haveOpen) {
      fail("the layer gave no hand: " + layerResults[0].error);
      continue;
    }

    // physics-convex is no SDF strategy, so the layer does not offer it: solved here by the core
    // for the hand pose the layer placed (the wrist it reported), on a Bullet convex hull.
    progress.step(index, count, c.name, "physics-convex (core, Bullet convex hull)");
    const Pose worldFromWrist = fromXr(openHand.poses[XR_HAND_JOINT_WRIST_EXT]);
    StrategyResult phys;
    phys.name = "physics-convex";
    phys.source = "core";
    {
      auto solver = createAnySolver("physics-convex");
      auto collider = PhysicsCollider::create(c.mesh, PhysicsCollider::Kind::convexHull);
      GraspResult gr;
      Status st = Status::ok;
      if (!solver || !collider) {
        phys.error = !solver ? solver.error().message : collider.error().message;
      } else if ((st = (*solver)->prepare(model, GridBox::referenceDefault(), SolverOptions{})) !=
                 Status::ok) {
        phys.error = std::string((*solver)->prepareError());
      } else {
        GraspScene scene;
        scene.collider = collider->get();
        scene.objectFromHand = objectFromWorld * worldFromWrist;
        const auto t0 = std::chrono::steady_clock::now();
        st = (*solver)->solve(scene, gr);
        phys.milliseconds =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                .count();
        phys.ok = st == Status::ok;
        if (!phys.ok) phys.error = std::string("solve failed: ") + toString(st);
      }
      Panel& panel = panels[0];
      FingerCurls curls{};
      for (int f = 0; f < 5; ++f) curls[f] = phys.ok ? gr.fingers[f].curl : 0.0f;
      JointPoses poses;
      JointRadii radii;
      placeJoints(model, curls, worldFromWrist, poses, radii);
      for (int k = 0; k < kJointCount; ++k) {
        panel.hand.positions[k] = poses[k].position;
        panel.hand.radii[k] = radii[k];
      }
      panel.hand.worldFromWrist = worldFromWrist;
      for (int f = 0; f < 5 && phys.ok; ++f) {
        FingerRow& row = phys.fingers[size_t(f)];
        row.curl = gr.fingers[f].curl;
        row.contact = gr.fingers[f].contact;
        row.reportedMm = gr.fingers[f].distance * 1000.0f;
        exactFinger(panel.hand, f, **distance, objectFromWorld, row);
        if (row.contact) {
          ++phys.contacts;
          panel.contacts.push_back(worldFromWrist.transformPoint(gr.fingers[f].contactPoint));
        }
      }
      phys.wholeHandMm = wholeHandClearanceMm(panel.hand, **distance, objectFromWorld);
      if (!phys.ok) anyFailure = true;
    }
    result.strategies = {phys, layerResults[0], layerResults[1]};

    // The three panels, one camera (framed on the open hand and the object).
    progress.step(index, count, c.name, "rendering with Vulkan");
    const uint32_t w = opt.width, h = opt.width;
    const HandPose open = handFromJoints(openHand);
    Aabb bounds = computeBounds(c.mesh.positions);
    bounds.min += worldFromObject.position;
    bounds.max += worldFromObject.position;
    glm::vec3 light;
    const glm::mat4 viewProjection = graspCamera(open, bounds, 1.0f, light);
    const uint32_t gap = 4;
    const uint32_t totalW = 3 * w + 2 * gap;
    std::vector<uint8_t> picture(size_t(totalW) * h * 4, 255);
    bool rendered = true;
    for (int p = 0; p < 3 && rendered; ++p) {
      DrawList list;
      appendMesh(list.lit, c.mesh, worldFromObject, kObjectColour);
      appendHand(list.lit, panels[size_t(p)].hand, kHandColour);
      for (const auto& q : panels[size_t(p)].contacts)
        appendSphere(list.overlay, q, 0.004f, kContactColour, true);
      rendered = renderPanel(renderer, list, viewProjection, light, w, h, kSupersample, picture,
                             totalW, uint32_t(p) * (w + gap), 0, error);
    }
    if (!rendered) {
      fail("rendering failed: " + error);
      continue;
    }
    const std::string stem = fileStem(c.name);
    result.graspPng = stem + "-grasp.png";
    result.slicePng = stem + "-sdf-slice.png";
    if (!writePng((fs::path(opt.out) / result.graspPng).string(), totalW, h, picture, error)) {
      fail(error);
      continue;
    }
    written.push_back(result.graspPng);

    // The grab-box SDF for the `ours` hand. Finer than the solvers' grid (16^3 by default,
    // 1.4 cm between nodes, too coarse to show a 5 mm wall) so the picture shows the field.
    progress.step(index, count, c.name, "grab-box SDF slice");
    GridBox box = GridBox::referenceDefault();
    box.resolution = glm::uvec3(std::max(opt.resolution, kSliceResolution));
    const HandPose& ours = panels[2].hand;
    SdfGrid grid;
    if (sdfBuilder.build(**distance, objectFromWorld * ours.worldFromWrist, box, grid) !=
        Status::ok) {
      fail("the SDF builder refused the grab box");
      continue;
    }
    HandPose local = ours;
    const Pose wristFromWorld = ours.worldFromWrist.inverse();
    for (auto& p : local.positions) p = wristFromWorld.transformPoint(p);
    std::vector<glm::vec3> localContacts;
    for (const auto& q : panels[2].contacts)
      localContacts.push_back(wristFromWorld.transformPoint(q));
    const std::vector<uint8_t> slice = sdfSlice(grid, local, localContacts, w);
    if (!writePng((fs::path(opt.out) / result.slicePng).string(), w, w, slice, error)) {
      fail(error);
      continue;
    }
    written.push_back(result.slicePng);
    results.push_back(std::move(result));
  }

  // The table scene and the outer hand: the engine in this process (no OpenXR).
  progress.step(1, 2, "table scene",
                "grasping the mug, the block and the comb (GraspSession, ours)");
  SceneReport sceneReport;
  TableSceneOptions sceneOptions;
  sceneOptions.width = opt.width;
  sceneOptions.supersample = kSupersample;
  sceneOptions.outDir = opt.out;
  if (!runTableScene(renderer, sceneOptions, sceneReport, error)) {
    progress.note("table scene: " + error);
    info.failures.push_back("table scene: " + error);
    anyFailure = true;
  } else {
    written.push_back(sceneReport.png);
    for (const auto& g : sceneReport.grasps) anyFailure = anyFailure || !g.ok;
  }
  progress.step(2, 2, "outer hand", "a hand pushed into the table (OuterHand)");
  OuterReport outerReport;
  OuterSequenceOptions outerOptions;
  outerOptions.width = opt.width;
  outerOptions.supersample = kSupersample;
  outerOptions.outDir = opt.out;
  if (!runOuterSequence(renderer, outerOptions, outerReport, error)) {
    progress.note("outer hand: " + error);
    info.failures.push_back("outer hand: " + error);
    anyFailure = true;
  } else {
    written.push_back(outerReport.png);
  }
  progress.done();

  if (!writeReports(opt.out, results, sceneReport, outerReport, info, error)) {
    std::fprintf(stderr, "autograsp-demo: %s\n", error.c_str());
    return 2;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  const fs::path dir = fs::absolute(opt.out).lexically_normal();
  int grasps = 0;
  for (const auto& r : results)
    for (const auto& s : r.strategies) grasps += s.ok ? 1 : 0;
  std::printf("autograsp-demo: %zu objects, %d grasps in %.1f s (runtime: %s, Vulkan: %s)\n",
              results.size(), grasps, seconds, info.runtime.c_str(), info.device.c_str());
  for (const auto& r : results) {
    std::printf("  %-28s", r.name.c_str());
    for (const auto& s : r.strategies)
      std::printf("  %s %d/5%s", s.name.c_str(), s.contacts, s.ok ? "" : " (failed)");
    std::printf("\n");
  }
  for (const auto& g : sceneReport.grasps) {
    if (g.ok)
      std::printf("  table scene: placed on the %s, took the %s, %d/5, %.2f mm into the table\n",
                  g.aim.c_str(), g.took.c_str(), g.contacts, double(std::max(0.0f, -g.tableMm)));
    else
      std::printf("  table scene: placed on the %s: failed: %s\n", g.aim.c_str(), g.error.c_str());
  }
  if (!outerReport.frames.empty()) {
    std::printf("  outer hand: %zu frames, deepest in the table: tracked %.1f mm, shown %.2f mm\n",
                outerReport.frames.size(), double(outerReport.deepestTrackedMm()),
                double(outerReport.deepestShownMm()));
  }
  for (const auto& f : info.failures) std::printf("  skipped: %s\n", f.c_str());
  std::printf("Pictures (%zu PNG) and the report are in %s/\n", written.size(), dir.c_str());
  std::printf("Open %s\n", (dir / "report.html").c_str());
  return anyFailure ? 1 : 0;
}
