// What the demo draws and where it puts the hand: geometry for the renderer (an object with flat
// normals, a hand as capsules of its joint radii, contact markers), the camera of a grasp
// picture, the hand placement on each object, and the picture of a slice of the grab-box SDF.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "base/pose.h"
#include "hand/hand_model.h"
#include "mesh/mesh.h"
#include "mesh/mesh_distance.h"
#include "renderer.h"
#include "sdf/sdf_grid.h"

namespace sdfg::demo {

inline constexpr glm::vec3 kObjectColour{0.62f, 0.70f, 0.82f};
inline constexpr glm::vec3 kHandColour{0.93f, 0.66f, 0.47f};
inline constexpr glm::vec3 kContactColour{1.0f, 0.0f, 1.0f};     // unlit: exact in the image
inline constexpr glm::vec3 kTableColour{0.50f, 0.62f, 0.45f};    // grey-green
inline constexpr glm::vec3 kTrackedColour{0.50f, 0.50f, 0.52f};  // the tracked hand: grey
inline constexpr glm::vec3 kBackground{0.12f, 0.13f, 0.16f};

struct HandPose {
  std::array<glm::vec3, kJointCount> positions{};  // world (LOCAL) space
  std::array<float, kJointCount> radii{};
  Pose worldFromWrist;
};

// Appends the mesh placed by `worldFromObject`, one flat normal per triangle.
void appendMesh(std::vector<Vertex>& out, const TriangleMesh& mesh, const Pose& worldFromObject,
                const glm::vec3& colour);
void appendSphere(std::vector<Vertex>& out, const glm::vec3& centre, float radius,
                  const glm::vec3& colour, bool unlit);
// Bones as tapered capsules from joint to joint with the joints' radii, and the palm.
void appendHand(std::vector<Vertex>& out, const HandPose& hand, const glm::vec3& colour);

// The box around the hand's joint spheres (world).
Aabb handBounds(const HandPose& hand);

// View-projection (Vulkan clip space) of a picture of `hand` holding an object with world
// bounds `objectBounds`: seen from in front of the fingers, on the thumb side.
glm::mat4 graspCamera(const HandPose& hand, const Aabb& objectBounds, float aspect,
                      glm::vec3& lightOut);

// View-projection of a sphere (`centre`, `radius`, world) seen from the direction `toCamera`
// (unit, from the centre toward the eye), `up` up in the picture; the light comes from over the
// camera's shoulder.
glm::mat4 lookCamera(const glm::vec3& centre, float radius, const glm::vec3& toCamera,
                     const glm::vec3& up, float aspect, glm::vec3& lightOut);

// Where the right controller goes so the hand closes around a handle-like part: `centre` is the
// part's centre, `along` its direction, `outward` the side the palm is on (object space).
// Returns objectFromGrip (the grip pose in the object's frame).
Pose gripAround(const HandModel& model, const glm::vec3& centre, const glm::vec3& along,
                const glm::vec3& outward);

// A seeded placement for any mesh (centred, hand-sized): a surface point picked by `seed`, the
// palm 1-3 cm above it facing it. Returns objectFromGrip.
Pose seededGrip(const HandModel& model, const MeshDistance& distance, uint32_t seed);

// Picture of the grab-box SDF on the plane of the middle finger (hand space x = that finger's),
// fingers to the right, the back of the hand up: blue inside, red outside, 1 cm isolines, the
// zero isoline black; the hand's bones in white and its contacts in magenta. width x width RGBA.
std::vector<uint8_t> sdfSlice(const SdfGrid& grid, const HandPose& handSpaceHand,
                              const std::vector<glm::vec3>& handSpaceContacts, uint32_t width);

// The hand with all 26 joints of `model` at per-joint `curls`, its wrist at `worldFromWrist`.
HandPose modelHand(const HandModel& model, const std::array<JointCurls, kFingerCount>& curls,
                   const Pose& worldFromWrist);

// Least clearance of the hand's surface (palm sphere and finger capsules from the metacarpal
// joint to the tip, grasp/hand_clearance.h's parts) from a solid whose signed distance (world,
// negative inside) is `distance`; negative: that deep inside. Metres.
float leastClearance(const HandPose& hand, const std::function<float(const glm::vec3&)>& distance);

// Renders `list` at `supersample` times width x height, filters it down and copies it into
// `picture` (pictureWidth pixels a row, RGBA) with its top left corner at (x0, y0).
bool renderPanel(Renderer& renderer, const DrawList& list, const glm::mat4& viewProjection,
                 const glm::vec3& light, uint32_t width, uint32_t height, uint32_t supersample,
                 std::vector<uint8_t>& picture, uint32_t pictureWidth, uint32_t x0, uint32_t y0,
                 std::string& error);

// Box-filters an image down by `factor` in each direction (supersampled renders).
std::vector<uint8_t> downsample(const std::vector<uint8_t>& rgba, uint32_t width, uint32_t height,
                                uint32_t factor);

}  // namespace sdfg::demo
