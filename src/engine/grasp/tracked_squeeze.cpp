#include "grasp/tracked_squeeze.h"

namespace sdfg {

float squeezeFromTrackedHand(const HandModel& model, const JointPoses& wristSpaceJoints) {
  const FingerCurls c = model.estimateCurls(wristSpaceJoints);
  return (c[size_t(Finger::index)] + c[size_t(Finger::middle)] + c[size_t(Finger::ring)] +
          c[size_t(Finger::little)]) *
         0.25f;
}

}  // namespace sdfg
