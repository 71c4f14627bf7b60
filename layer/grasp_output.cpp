// XR_SDFG_auto_grasp version 2 outputs chained on XrGraspStateSDFG: the per-finger contacts and
// the held pose. Both are copies of what the engine computed at the solve (contact.h), so
// answering costs no distance query.
#include "intercepts.h"
#include "state.h"

namespace sdfg::layer {
namespace {

XrVector3f toXr(const glm::vec3& v) {
  return {v.x, v.y, v.z};
}

void writeContacts(const HandGrasp& g, bool held, XrGraspContactsSDFG& out) {
  for (int f = 0; f < kFingerCount; ++f) {
    XrGraspFingerContactSDFG& o = out.fingers[f];
    o = XrGraspFingerContactSDFG{};
    o.part = XR_GRASP_CONTACT_PART_NONE_SDFG;
    const FingerContact& c = g.contacts[f];
    if (!held || !g.result.fingers[f].contact || !c.valid) continue;
    o.part = c.jointSphere ? XR_GRASP_CONTACT_PART_JOINT_SPHERE_SDFG
                           : XR_GRASP_CONTACT_PART_BONE_CAPSULE_SDFG;
    // The core's Joint enumerates the joints in XrHandJointEXT order.
    o.joint = static_cast<XrHandJointEXT>(c.joint);
    o.boneFraction = c.boneFraction;
    o.sphereRadius = c.radius;
    o.sphereCenter = toXr(c.center);
    o.surfacePoint = toXr(c.surfacePoint);
    o.surfaceNormal = toXr(c.normal);
    o.distance = c.distance;
    o.isExact = c.exact ? XR_TRUE : XR_FALSE;
  }
}

void writeHeldPose(const SessionState& s, Hand hand, const HandGrasp& g, bool held,
                   XrGraspHeldPoseSDFG& out) {
  out.isValid = XR_FALSE;
  out.palmFromTarget = XrPosef{{0, 0, 0, 1}, {0, 0, 0}};
  out.time = 0;
  if (!held) return;
  // The palm joint does not move with the finger curls: its pose in the wrist frame is the
  // model's at any curl.
  JointPoses joints;
  s.grasp->model(hand).pose(FingerCurls{}, joints);
  const Pose& wristFromPalm = joints[size_t(Joint::palm)];
  const Pose palmFromTarget = wristFromPalm.inverse() * g.objectFromHand.inverse();
  out.isValid = XR_TRUE;
  out.palmFromTarget = ::sdfg::layer::toXr(palmFromTarget);
  out.time = g.time;
}

}  // namespace

void writeGraspStateV2(const SessionState& s, Hand hand, bool held, XrGraspStateSDFG* state) {
  const HandGrasp& g = s.grasp->grasp(hand);
  if (auto* c = findInChain<XrGraspContactsSDFG>(state->next, XR_TYPE_GRASP_CONTACTS_SDFG))
    writeContacts(g, held, *c);
  if (auto* p = findInChain<XrGraspHeldPoseSDFG>(state->next, XR_TYPE_GRASP_HELD_POSE_SDFG))
    writeHeldPose(s, hand, g, held, *p);
}

}  // namespace sdfg::layer
