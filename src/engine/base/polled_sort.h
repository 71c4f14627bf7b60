// A sort that can be stopped: std::sort gives no point to look at a WorkLimit, and sorting the
// 3 x 2^24 half-edges of the largest mesh the layer takes runs for seconds. polledSort() sorts
// runs of kRun elements with std::sort, looking at the limit between runs, then merges runs
// pairwise through a buffer, looking at it every few thousand elements merged, so the time
// between two looks stays bounded whatever the size. Equal elements may end in any order, as
// with std::sort.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

#include "base/work_limit.h"

namespace sdfg {

// Sorts `values` by `less`; returns false once `limit` is reached, leaving `values` in an
// unspecified state (its owner is giving the work up).
template <class T, class Less>
bool polledSort(std::vector<T>& values, Less less, const WorkLimit& limit) {
  constexpr size_t kRun = size_t(1) << 14;
  const size_t n = values.size();
  for (size_t first = 0; first < n; first += kRun) {
    if (limit.reached()) return false;
    std::sort(values.begin() + first, values.begin() + std::min(n, first + kRun), less);
  }
  if (n <= kRun) return true;
  std::vector<T> buffer(n);
  LimitPoll poll(limit);
  std::vector<T>* from = &values;
  std::vector<T>* to = &buffer;
  for (size_t width = kRun; width < n; width *= 2) {
    for (size_t first = 0; first < n; first += 2 * width) {
      const size_t mid = std::min(n, first + width), last = std::min(n, first + 2 * width);
      size_t a = first, b = mid, out = first;
      while (a < mid && b < last) {
        if (poll.reached()) return false;
        // Ties take from the left run first, so a merge keeps the runs' order.
        (*to)[out++] = less((*from)[b], (*from)[a]) ? (*from)[b++] : (*from)[a++];
      }
      std::copy((*from).begin() + ptrdiff_t(a), (*from).begin() + ptrdiff_t(mid),
                (*to).begin() + ptrdiff_t(out));
      out += mid - a;
      std::copy((*from).begin() + ptrdiff_t(b), (*from).begin() + ptrdiff_t(last),
                (*to).begin() + ptrdiff_t(out));
    }
    std::swap(from, to);
  }
  if (from != &values) values.swap(buffer);
  return true;
}

}  // namespace sdfg
