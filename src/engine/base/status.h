// Error reporting of the core library.
//
// The core never uses XrResult or VkResult in its interfaces: it returns a Status code and a
// message that names the problem. The layer maps Status to XR_ERROR_* in one place; tools print
// the message. No exception crosses a public core function for bad input.
#pragma once

#include <string>
#include <utility>
#include <variant>

namespace sdfg {

enum class Status {
  ok = 0,
  invalid_argument,  // bad value from the caller (NaN, out-of-range index, zero count...)
  io_error,          // a file could not be read or parsed
  unsupported,       // valid request the current build or device cannot serve
  out_of_memory,
  device_lost,  // the GPU went away; callers fall back to the CPU path
  timed_out,    // the work passed its time bound (WorkLimit) or its owner stopped it
  internal,     // a bug in this library
};

const char* toString(Status status);

// A failure: what kind, and a message a user can act on ("mesh: index 7 of triangle 2 is 40,
// but the mesh has 12 vertices").
struct Error {
  Status code = Status::internal;
  std::string message;
};

// A value or an Error. Small on purpose: C++20 has no std::expected.
template <class T>
class Result {
 public:
  Result(T value) : state_(std::move(value)) {}      // NOLINT: implicit by design
  Result(Error error) : state_(std::move(error)) {}  // NOLINT: implicit by design

  bool ok() const { return std::holds_alternative<T>(state_); }
  explicit operator bool() const { return ok(); }

  T& value() & { return std::get<T>(state_); }
  const T& value() const& { return std::get<T>(state_); }
  T&& value() && { return std::get<T>(std::move(state_)); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }

  const Error& error() const { return std::get<Error>(state_); }

 private:
  std::variant<T, Error> state_;
};

inline Error makeError(Status code, std::string message) {
  return Error{code, std::move(message)};
}

}  // namespace sdfg
