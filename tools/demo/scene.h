// What the demo draws and where it puts the hand: geometry for the renderer (an object with flat
// normals, a hand as capsules of its joint radii, contact markers), the camera of a grasp
// picture, the hand placement on each object, and the picture of a slice of the grab-box SDF.
#pragma once

#include <array>
#include <cstdint>
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
inline constexpr glm::vec3 kContactColour{1.0f, 0.0f, 1.0f};  // unlit: exact in the image
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

// View-projection (Vulkan clip space) of a picture of `hand` holding an object with world
// bounds `objectBounds`: seen from in front of the fingers, on the thumb side.
glm::mat4 graspCamera(const HandPose& hand, const Aabb& objectBounds, float aspect,
                      glm::vec3& lightOut);

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

// Box-filters an image down by `factor` in each direction (supersampled renders).
std::vector<uint8_t> downsample(const std::vector<uint8_t>& rgba, uint32_t width, uint32_t height,
                                uint32_t factor);

}  // namespace sdfg::demo
