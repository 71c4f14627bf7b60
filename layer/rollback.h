// Gives back what the runtime made when the layer fails after the runtime succeeded: an
// exception from the layer's own part of a create call (a map insert, a worker thread that
// cannot start, the layer's action set) must not leave the runtime's object behind while the app
// is told the call failed. Made right after the call down succeeded with the matching destroy,
// dismissed once the layer's part is done; an exception in between runs the destroy on its way
// to the entry point's catch-all, which returns the error. Holds its undo by value: making one
// allocates nothing.
#pragma once

#include <utility>

namespace sdfg::layer {

template <class Undo>
class Rollback {
 public:
  explicit Rollback(Undo undo) : undo_(std::move(undo)) {}
  ~Rollback() {
    if (armed_) undo_();
  }
  Rollback(const Rollback&) = delete;
  Rollback& operator=(const Rollback&) = delete;
  void dismiss() { armed_ = false; }

 private:
  Undo undo_;
  bool armed_ = true;
};

}  // namespace sdfg::layer
