#include "scene.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>

#include "grasp/hand_clearance.h"
#include "hand/hand_synthesis.h"

namespace sdfg::demo {
namespace {

constexpr float kPi = 3.14159265358979f;

// Any unit vector perpendicular to `n`.
glm::vec3 perpendicular(const glm::vec3& n) {
  const glm::vec3 a = std::abs(n.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
  return glm::normalize(glm::cross(n, a));
}

void triangle(std::vector<Vertex>& out, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c,
              const glm::vec3& na, const glm::vec3& nb, const glm::vec3& nc,
              const glm::vec3& colour) {
  out.push_back({a, na, colour});
  out.push_back({b, nb, colour});
  out.push_back({c, nc, colour});
}

// A cone frustum from a (radius ra) to b (radius rb), side only; the joint spheres cap it.
void appendCone(std::vector<Vertex>& out, const glm::vec3& a, float ra, const glm::vec3& b,
                float rb, const glm::vec3& colour) {
  const glm::vec3 axis = b - a;
  const float len = glm::length(axis);
  if (len < 1e-6f) return;
  const glm::vec3 z = axis / len;
  const glm::vec3 x = perpendicular(z);
  const glm::vec3 y = glm::cross(z, x);
  constexpr int kSides = 20;
  // The side's normal leans toward the thinner end by the taper.
  const float slope = (ra - rb) / len;
  for (int i = 0; i < kSides; ++i) {
    const float t0 = 2 * kPi * i / kSides, t1 = 2 * kPi * (i + 1) / kSides;
    const glm::vec3 d0 = std::cos(t0) * x + std::sin(t0) * y;
    const glm::vec3 d1 = std::cos(t1) * x + std::sin(t1) * y;
    const glm::vec3 n0 = glm::normalize(d0 + slope * z), n1 = glm::normalize(d1 + slope * z);
    const glm::vec3 a0 = a + ra * d0, a1 = a + ra * d1, b0 = b + rb * d0, b1 = b + rb * d1;
    triangle(out, a0, a1, b1, n0, n1, n1, colour);
    triangle(out, a0, b1, b0, n0, n1, n0, colour);
  }
}

}  // namespace

void appendMesh(std::vector<Vertex>& out, const TriangleMesh& mesh, const Pose& worldFromObject,
                const glm::vec3& colour) {
  out.reserve(out.size() + mesh.indices.size());
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const glm::vec3 a = worldFromObject.transformPoint(mesh.positions[mesh.indices[t]]);
    const glm::vec3 b = worldFromObject.transformPoint(mesh.positions[mesh.indices[t + 1]]);
    const glm::vec3 c = worldFromObject.transformPoint(mesh.positions[mesh.indices[t + 2]]);
    glm::vec3 n = glm::cross(b - a, c - a);
    const float l = glm::length(n);
    n = l > 0.0f ? n / l : glm::vec3(0, 1, 0);
    triangle(out, a, b, c, n, n, n, colour);
  }
}

void appendSphere(std::vector<Vertex>& out, const glm::vec3& centre, float radius,
                  const glm::vec3& colour, bool unlit) {
  constexpr int kRings = 10, kSegments = 16;
  auto point = [&](int ring, int seg) {
    const float th = kPi * ring / kRings, ph = 2 * kPi * seg / kSegments;
    return glm::vec3(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
  };
  for (int r = 0; r < kRings; ++r) {
    for (int s = 0; s < kSegments; ++s) {
      const glm::vec3 p00 = point(r, s), p01 = point(r, s + 1), p10 = point(r + 1, s),
                      p11 = point(r + 1, s + 1);
      auto n = [&](const glm::vec3& p) { return unlit ? glm::vec3(0.0f) : p; };
      triangle(out, centre + radius * p00, centre + radius * p10, centre + radius * p11, n(p00),
               n(p10), n(p11), colour);
      triangle(out, centre + radius * p00, centre + radius * p11, centre + radius * p01, n(p00),
               n(p11), n(p01), colour);
    }
  }
}

void appendHand(std::vector<Vertex>& out, const HandPose& hand, const glm::vec3& colour) {
  const auto& p = hand.positions;
  const auto& r = hand.radii;
  auto bone = [&](Joint a, Joint b) {
    appendCone(out, p[size_t(a)], r[size_t(a)], p[size_t(b)], r[size_t(b)], colour);
  };
  for (int f = 0; f < kFingerCount; ++f) {
    const auto joints = fingerJoints(Finger(f));
    bone(Joint::wrist, joints[0]);
    for (size_t j = 0; j + 1 < joints.size(); ++j) bone(joints[j], joints[j + 1]);
  }
  // The palm: across the knuckles and the metacarpal bases, so it reads as a hand.
  const Joint knuckles[] = {Joint::index_proximal, Joint::middle_proximal, Joint::ring_proximal,
                            Joint::little_proximal};
  const Joint bases[] = {Joint::index_metacarpal, Joint::middle_metacarpal, Joint::ring_metacarpal,
                         Joint::little_metacarpal};
  for (int i = 0; i < 3; ++i) {
    bone(knuckles[i], knuckles[i + 1]);
    bone(bases[i], bases[i + 1]);
  }
  bone(Joint::palm, Joint::middle_proximal);
  bone(Joint::palm, Joint::wrist);
  for (int j = 0; j < kJointCount; ++j) appendSphere(out, p[j], r[j], colour, false);
}

Aabb handBounds(const HandPose& hand) {
  Aabb b{glm::vec3(1e9f), glm::vec3(-1e9f)};
  for (int j = 0; j < kJointCount; ++j) {
    b.min = glm::min(b.min, hand.positions[size_t(j)] - hand.radii[size_t(j)]);
    b.max = glm::max(b.max, hand.positions[size_t(j)] + hand.radii[size_t(j)]);
  }
  return b;
}

glm::mat4 graspCamera(const HandPose& hand, const Aabb& objectBounds, float aspect,
                      glm::vec3& lightOut) {
  // Frame the hand and the object near it (a big object is cut to 6 cm around the hand).
  const Aabb handBox = handBounds(hand);
  glm::vec3 lo = handBox.min, hi = handBox.max;
  const glm::vec3 objLo = glm::max(objectBounds.min, lo - 0.06f);
  const glm::vec3 objHi = glm::min(objectBounds.max, hi + 0.06f);
  if (glm::all(glm::lessThan(objLo, objHi))) {
    lo = glm::min(lo, objLo);
    hi = glm::max(hi, objHi);
  }
  const glm::vec3 centre = (lo + hi) * 0.5f;
  const float radius = 0.5f * glm::length(hi - lo);
  // Hand axes in world: +Y back of the hand, -Z toward the fingers, thumb on -X (right hand).
  const glm::quat q = hand.worldFromWrist.orientation;
  const glm::vec3 hx = q * glm::vec3(1, 0, 0), hy = q * glm::vec3(0, 1, 0),
                  hz = q * glm::vec3(0, 0, 1);
  // In front of the fingers, from the thumb side and a little below the palm: the fingers wrap
  // toward the camera and the object stays visible between them.
  const glm::vec3 toCamera = glm::normalize(-0.6f * hx - 0.3f * hy - 1.0f * hz);
  return lookCamera(centre, radius, toCamera, hy, aspect, lightOut);
}

glm::mat4 lookCamera(const glm::vec3& centre, float radius, const glm::vec3& toCamera,
                     const glm::vec3& up, float aspect, glm::vec3& lightOut) {
  const float fov = glm::radians(35.0f);
  // The bounding sphere of a box is loose: come closer than it asks.
  const float distance = radius / std::sin(fov * 0.5f) * 0.78f;
  const glm::vec3 eye = centre + toCamera * distance;
  const glm::vec3 u = glm::normalize(up - glm::dot(up, toCamera) * toCamera);
  const glm::mat4 view = glm::lookAtRH(eye, centre, u);
  glm::mat4 proj = glm::perspectiveRH_ZO(fov, aspect, distance * 0.05f, distance * 4.0f);
  proj[1][1] *= -1.0f;  // Vulkan's y points down
  const glm::vec3 right = glm::normalize(glm::cross(-toCamera, u));
  lightOut = glm::normalize(toCamera + 0.8f * u - 0.4f * right);
  return proj * view;
}

Pose gripAround(const HandModel& model, const glm::vec3& centre, const glm::vec3& along,
                const glm::vec3& outward) {
  // The grip frame's origin is where a controller's handle sits in the closed hand, -Z along
  // the handle; the palm lies on one side of it in grip X. Put the palm on `outward`.
  const Pose gripFromWrist = wristFromGrip(model).inverse();
  JointPoses open;
  model.pose(FingerCurls{}, open);
  const glm::vec3 palmInGrip = gripFromWrist.transformPoint(open[size_t(Joint::palm)].position);
  const glm::vec3 z = -glm::normalize(along);
  glm::vec3 o = outward - glm::dot(outward, z) * z;
  o = glm::length(o) > 1e-6f ? glm::normalize(o) : perpendicular(z);
  const glm::vec3 x = palmInGrip.x < 0.0f ? -o : o;
  const glm::vec3 y = glm::cross(z, x);
  return Pose{glm::normalize(glm::quat_cast(glm::mat3(x, y, z))), centre};
}

Pose seededGrip(const HandModel& model, const MeshDistance& distance, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> gauss;
  glm::vec3 u(gauss(rng), gauss(rng), gauss(rng));
  u = glm::length(u) > 1e-6f ? glm::normalize(u) : glm::vec3(1, 0, 0);
  // The vertex farthest along u is on the surface and on the outside.
  const auto& pos = distance.mesh().positions;
  glm::vec3 p = pos[0];
  for (const auto& v : pos)
    if (glm::dot(v, u) > glm::dot(p, u)) p = v;
  // Outward normal from the distance field's gradient just outside the point.
  const float h = 0.002f;
  const glm::vec3 q = p + u * 0.005f;
  glm::vec3 n(distance.signedDistance(q + glm::vec3(h, 0, 0)) -
                  distance.signedDistance(q - glm::vec3(h, 0, 0)),
              distance.signedDistance(q + glm::vec3(0, h, 0)) -
                  distance.signedDistance(q - glm::vec3(0, h, 0)),
              distance.signedDistance(q + glm::vec3(0, 0, h)) -
                  distance.signedDistance(q - glm::vec3(0, 0, h)));
  n = glm::length(n) > 1e-8f ? glm::normalize(n) : u;
  // A seeded direction along the surface for the "handle", and the grip 0-1 cm under the
  // surface, which puts the palm 1-3 cm above it.
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  const float angle = 2 * kPi * uni(rng);
  const glm::vec3 t0 = perpendicular(n), t1 = glm::cross(n, t0);
  const glm::vec3 along = std::cos(angle) * t0 + std::sin(angle) * t1;
  const glm::vec3 centre = p - n * (0.01f * uni(rng));
  return gripAround(model, centre, along, n);
}

std::vector<uint8_t> sdfSlice(const SdfGrid& grid, const HandPose& hand,
                              const std::vector<glm::vec3>& contacts, uint32_t width) {
  const GridBox& box = grid.box();
  const glm::vec3 c = box.handFromBox.position;
  const glm::vec3 half = box.size * 0.5f;
  // The middle finger's plane (hand space x), kept inside the box.
  float x = 0.0f;
  for (Joint j : fingerJoints(Finger::middle)) x += hand.positions[size_t(j)].x;
  x /= float(fingerJoints(Finger::middle).size());
  x = std::clamp(x, c.x - half.x, c.x + half.x);
  // Pixel (u, v) -> hand space: u from the wrist side (+z) to the fingers (-z), v from the back
  // of the hand (+y) down.
  const float span = std::max(box.size.y, box.size.z);
  const float metresPerPixel = span / float(width);
  auto toHand = [&](float u, float v) {
    return glm::vec3(x, c.y + span * 0.5f - v * metresPerPixel,
                     c.z + span * 0.5f - u * metresPerPixel);
  };
  auto toPixel = [&](const glm::vec3& p) {
    return glm::vec2((c.z + span * 0.5f - p.z) / metresPerPixel,
                     (c.y + span * 0.5f - p.y) / metresPerPixel);
  };
  std::vector<uint8_t> rgba(size_t(width) * width * 4);
  for (uint32_t v = 0; v < width; ++v) {
    for (uint32_t u = 0; u < width; ++u) {
      const float d = grid.sample(toHand(u + 0.5f, v + 0.5f));
      const float t = std::clamp(std::abs(d) / 0.06f, 0.0f, 1.0f);
      glm::vec3 col =
          d < 0.0f ? glm::mix(glm::vec3(0.70f, 0.82f, 1.0f), glm::vec3(0.05f, 0.12f, 0.55f), t)
                   : glm::mix(glm::vec3(1.0f, 0.86f, 0.80f), glm::vec3(0.60f, 0.06f, 0.04f), t);
      // 1 cm isolines, and the surface (d = 0) in black.
      const float band = std::abs(d) / 0.01f;
      if (std::abs(band - std::round(band)) * 0.01f < metresPerPixel * 0.6f) col *= 0.8f;
      if (std::abs(d) < metresPerPixel * 1.2f) col = glm::vec3(0.0f);
      uint8_t* px = &rgba[(size_t(v) * width + u) * 4];
      for (int k = 0; k < 3; ++k)
        px[k] = uint8_t(std::lround(std::clamp(col[k], 0.0f, 1.0f) * 255));
      px[3] = 255;
    }
  }
  auto plot = [&](int u, int v, const glm::vec3& col) {
    if (u < 0 || v < 0 || u >= int(width) || v >= int(width)) return;
    uint8_t* px = &rgba[(size_t(v) * width + u) * 4];
    for (int k = 0; k < 3; ++k) px[k] = uint8_t(col[k] * 255);
  };
  // The hand's bones (projected on the plane) and the joint circles that cut it.
  auto segment = [&](const glm::vec3& a, const glm::vec3& b) {
    const glm::vec2 pa = toPixel(a), pb = toPixel(b);
    const int steps = int(glm::length(pb - pa)) + 1;
    for (int s = 0; s <= steps; ++s) {
      const glm::vec2 p = glm::mix(pa, pb, float(s) / float(steps));
      plot(int(p.x), int(p.y), glm::vec3(1.0f));
      plot(int(p.x) + 1, int(p.y), glm::vec3(1.0f));
    }
  };
  for (int f = 0; f < kFingerCount; ++f) {
    const auto joints = fingerJoints(Finger(f));
    segment(hand.positions[size_t(Joint::wrist)], hand.positions[size_t(joints[0])]);
    for (size_t j = 0; j + 1 < joints.size(); ++j)
      segment(hand.positions[size_t(joints[j])], hand.positions[size_t(joints[j + 1])]);
  }
  for (int j = 0; j < kJointCount; ++j) {
    const float dx = hand.positions[j].x - x;
    const float r2 = hand.radii[j] * hand.radii[j] - dx * dx;
    if (r2 <= 0.0f) continue;
    const float rp = std::sqrt(r2) / metresPerPixel;
    const glm::vec2 centre = toPixel(hand.positions[j]);
    const int n = int(2 * kPi * rp) + 8;
    for (int s = 0; s < n; ++s) {
      const float a = 2 * kPi * s / n;
      plot(int(centre.x + rp * std::cos(a)), int(centre.y + rp * std::sin(a)), glm::vec3(1.0f));
    }
  }
  for (const glm::vec3& p : contacts) {
    const glm::vec2 q = toPixel(p);
    for (int dv = -4; dv <= 4; ++dv)
      for (int du = -4; du <= 4; ++du)
        if (du * du + dv * dv <= 16) plot(int(q.x) + du, int(q.y) + dv, kContactColour);
  }
  return rgba;
}

std::vector<uint8_t> downsample(const std::vector<uint8_t>& rgba, uint32_t width, uint32_t height,
                                uint32_t factor) {
  if (factor <= 1) return rgba;
  const uint32_t w = width / factor, h = height / factor;
  std::vector<uint8_t> out(size_t(w) * h * 4);
  for (uint32_t y = 0; y < h; ++y) {
    for (uint32_t x = 0; x < w; ++x) {
      for (int k = 0; k < 4; ++k) {
        uint32_t sum = 0;
        for (uint32_t dy = 0; dy < factor; ++dy)
          for (uint32_t dx = 0; dx < factor; ++dx)
            sum += rgba[((size_t(y) * factor + dy) * width + x * factor + dx) * 4 + k];
        out[(size_t(y) * w + x) * 4 + k] = uint8_t(sum / (factor * factor));
      }
    }
  }
  return out;
}

HandPose modelHand(const HandModel& model, const std::array<JointCurls, kFingerCount>& curls,
                   const Pose& worldFromWrist) {
  JointPoses poses;
  JointRadii radii;
  placeJoints(model, FingerCurls{}, worldFromWrist, poses, radii);
  replaceFingers(model, curls, {true, true, true, true, true}, worldFromWrist, poses);
  HandPose hand;
  for (int k = 0; k < kJointCount; ++k) {
    hand.positions[size_t(k)] = poses[size_t(k)].position;
    hand.radii[size_t(k)] = radii[size_t(k)];
  }
  hand.worldFromWrist = worldFromWrist;
  return hand;
}

float leastClearance(const HandPose& hand, const std::function<float(const glm::vec3&)>& distance) {
  JointPoses joints{};
  for (int k = 0; k < kJointCount; ++k) joints[size_t(k)].position = hand.positions[size_t(k)];
  HandParts parts;
  const int n = jointParts(joints, hand.radii, parts);
  float least = std::numeric_limits<float>::infinity();
  for (int i = 0; i < n; ++i)
    least = std::min(least, distance(parts[size_t(i)].centre) - parts[size_t(i)].radius);
  return least;
}

bool renderPanel(Renderer& renderer, const DrawList& list, const glm::mat4& viewProjection,
                 const glm::vec3& light, uint32_t width, uint32_t height, uint32_t supersample,
                 std::vector<uint8_t>& picture, uint32_t pictureWidth, uint32_t x0, uint32_t y0,
                 std::string& error) {
  std::vector<uint8_t> big;
  if (!renderer.render(list, viewProjection, light, width * supersample, height * supersample,
                       kBackground, big, error))
    return false;
  const std::vector<uint8_t> small =
      downsample(big, width * supersample, height * supersample, supersample);
  for (uint32_t y = 0; y < height; ++y)
    std::memcpy(&picture[(size_t(y0 + y) * pictureWidth + x0) * 4], &small[size_t(y) * width * 4],
                size_t(width) * 4);
  return true;
}

}  // namespace sdfg::demo
