// Nearest-rank percentiles of a run's per-frame or per-call times, as the timing tools
// (autograsp-frame-cost, autograsp-outer, autograsp-threads) report them: p50 and p99 are values
// that occurred, never interpolated between two frames.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace sdfg::tools {

struct Percentiles {
  double p50 = 0, p99 = 0, max = 0;
  size_t count = 0;
};

// All zero for an empty `v`.
inline Percentiles percentiles(std::vector<double> v) {
  Percentiles p;
  p.count = v.size();
  if (v.empty()) return p;
  std::sort(v.begin(), v.end());
  auto at = [&](double q) {
    const size_t i = size_t(std::ceil(q * double(v.size()))) - 1;
    return v[std::min(i, v.size() - 1)];
  };
  p.p50 = at(0.5);
  p.p99 = at(0.99);
  p.max = v.back();
  return p;
}

}  // namespace sdfg::tools
