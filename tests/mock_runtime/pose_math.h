// Small pose arithmetic on OpenXR types for the mock runtime: composition, inverse and
// interpolation. Kept here (not glm) so the runtime depends on nothing but the OpenXR and
// Vulkan headers.
#pragma once

#include <openxr/openxr.h>

#include <cmath>

namespace sdfg::mock {

inline XrPosef identityPose() {
  return XrPosef{{0, 0, 0, 1}, {0, 0, 0}};
}

inline XrQuaternionf mul(const XrQuaternionf& a, const XrQuaternionf& b) {
  return {
      a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y, a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
      a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w, a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z};
}

inline XrQuaternionf conjugate(const XrQuaternionf& q) {
  return {-q.x, -q.y, -q.z, q.w};
}

inline XrVector3f rotate(const XrQuaternionf& q, const XrVector3f& v) {
  const XrQuaternionf p{v.x, v.y, v.z, 0};
  const XrQuaternionf r = mul(mul(q, p), conjugate(q));
  return {r.x, r.y, r.z};
}

// a * b: b expressed in a's frame, mapped to a's parent frame.
inline XrPosef compose(const XrPosef& a, const XrPosef& b) {
  const XrVector3f t = rotate(a.orientation, b.position);
  return {mul(a.orientation, b.orientation),
          {a.position.x + t.x, a.position.y + t.y, a.position.z + t.z}};
}

inline XrPosef inverse(const XrPosef& p) {
  const XrQuaternionf qi = conjugate(p.orientation);
  const XrVector3f t = rotate(qi, p.position);
  return {qi, {-t.x, -t.y, -t.z}};
}

inline float quatLength(const XrQuaternionf& q) {
  return std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
}

inline XrQuaternionf normalized(const XrQuaternionf& q) {
  const float n = quatLength(q);
  if (!(n > 0.0f)) return {0, 0, 0, 1};
  return {q.x / n, q.y / n, q.z / n, q.w / n};
}

// The spec's test for "a valid orientation": unit length within a small tolerance.
inline bool isUnitQuaternion(const XrQuaternionf& q) {
  const float n = quatLength(q);
  return std::isfinite(n) && std::fabs(n - 1.0f) < 1e-3f;
}

inline bool isFinite(const XrVector3f& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

inline float lerp(float a, float b, float t) {
  return a + (b - a) * t;
}

// Shortest-arc normalised lerp: exact at both ends, close to slerp for keyframes a few frames
// apart, and never undefined.
inline XrQuaternionf nlerp(XrQuaternionf a, const XrQuaternionf& b, float t) {
  const float d = a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w;
  if (d < 0) a = {-a.x, -a.y, -a.z, -a.w};
  return normalized({lerp(a.x, b.x, t), lerp(a.y, b.y, t), lerp(a.z, b.z, t), lerp(a.w, b.w, t)});
}

}  // namespace sdfg::mock
