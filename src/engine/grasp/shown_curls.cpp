#include "grasp/shown_curls.h"

#include <algorithm>

namespace sdfg {

ShownCurls shownCurls(const GraspResult& grasp, const FingerCurls& user, float closing) {
  ShownCurls out;
  const float c = std::clamp(closing, 0.0f, 1.0f);
  for (int f = 0; f < kFingerCount; ++f) {
    const FingerState& fs = grasp.fingers[size_t(f)];
    out.replace[size_t(f)] = c * fs.curl < user[size_t(f)];
    for (size_t k = 0; k < out.curls[size_t(f)].size(); ++k)
      out.curls[size_t(f)][k] = std::min(user[size_t(f)], c * fs.jointCurls[k]);
  }
  return out;
}

}  // namespace sdfg
