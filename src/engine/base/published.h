// The newest value of something one thread updates and others read (what a hand shows, written
// by the grab update in xrSyncActions and drawn by xrLocateHandJointsEXT on the app's render
// thread; the outer hand's result, written by the session's worker): an immutable value behind a
// shared_ptr, swapped under a lock held for the pointer copy alone. A reader never waits for the
// writer's work, and keeps what it loaded for as long as it needs it. (Not
// std::atomic<std::shared_ptr>: libstdc++ 12 builds it on a lock bit that ThreadSanitizer cannot
// see, so every use was reported as a race.)
#pragma once

#include <memory>
#include <mutex>
#include <utility>

namespace sdfg {

template <class T>
class Published {
 public:
  // Null until the first store.
  std::shared_ptr<const T> load() const {
    std::lock_guard lock(mutex_);
    return value_;
  }
  void store(std::shared_ptr<const T> value) {
    {
      std::lock_guard lock(mutex_);
      value_.swap(value);
    }
    // The replaced value (now in `value`) is freed here, outside the lock.
  }

 private:
  mutable std::mutex mutex_;
  std::shared_ptr<const T> value_;
};

}  // namespace sdfg
