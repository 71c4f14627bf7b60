// autograsp-frame-cost's target meshes as the app hands them to the layer, and the outer-hand
// scenario's scene (issue 27): where the right hand is held, and the targets near it and spread
// over a room (--room N). Geometry only; main.cpp's app registers and drives it.
#pragma once

#include <openxr/openxr.h>

#include <cstdint>
#include <string>
#include <vector>

#include "base/pose.h"
#include "mesh/mesh.h"

namespace sdfg::frame_cost {

// A target's mesh in the app's arrays.
struct Object {
  std::string name;
  std::vector<XrVector3f> vertices;
  std::vector<uint32_t> indices;
};

// The positions and indices of `m` as they are (no centring or scaling).
Object meshObject(const std::string& name, const TriangleMesh& m);

// The right hand's grip in every scenario (LOCAL): in front of and below the viewer.
inline constexpr XrPosef kGrip{{0, 0, 0, 1}, {0.2f, -0.3f, -0.4f}};

// An OpenXR pose as the engine's.
Pose toPose(const XrPosef& p);

// The outer-hand scenario's geometry: the right hand's grip, where the open hand synthesized from
// it is (its palm and its lowest point), and the targets: a table 5 mm below the hand and four
// 4 cm boxes on it beside the hand (the five in the hand's box), and `room` - 5 more spread over
// a 10 x 10 m room at least a metre from the hand (5 cm boxes and 3 cm spheres by turns).
struct OuterScene {
  XrPosef grip = kGrip;
  float gap = 0.005f;  // between the hand and the table in the near phase, metres
  std::vector<Object> objects;
  std::vector<XrPosef> poses;
  int inHandBox = 0;
};

// The scene for `room` targets in all (at least the five in the hand's box).
OuterScene outerScene(int room);

// The grip in frame i of the touching phase: down into the table by 2 cm past the touch over the
// first 10 frames, then sliding +-8 cm along x and back (one period over the phase).
XrPosef touchingGrip(const OuterScene& s, int i, int frames);

}  // namespace sdfg::frame_cost
