// The percentile the quality gates and the scene figures report: linear interpolation between
// order statistics, as the benchmark's tables (tools/bench/run_mesh.h, which gives NaN rather
// than 0 for an empty sample, since its tables print "-" there).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace sdfg {

// The q-quantile (q in [0, 1]) of `v`; 0 for an empty sample.
inline double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double pos = q * double(v.size() - 1);
  const size_t lo = size_t(std::floor(pos));
  const size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (v[hi] - v[lo]) * (pos - double(lo));
}

}  // namespace sdfg
