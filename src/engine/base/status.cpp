#include "base/status.h"

namespace sdfg {

const char* toString(Status status) {
  switch (status) {
    case Status::ok:
      return "ok";
    case Status::invalid_argument:
      return "invalid argument";
    case Status::io_error:
      return "i/o error";
    case Status::unsupported:
      return "unsupported";
    case Status::out_of_memory:
      return "out of memory";
    case Status::device_lost:
      return "device lost";
    case Status::timed_out:
      return "timed out";
    case Status::internal:
      return "internal error";
  }
  return "unknown status";
}

}  // namespace sdfg
