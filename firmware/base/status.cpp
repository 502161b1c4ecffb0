#include "firmware/base/status.h"

#include <cstdio>
#include <cstring>

namespace fw {

const char* errc_name(Errc code) {
  switch (code) {
    case Errc::kOk: return "ok";
    case Errc::kInvalidArgument: return "invalid argument";
    case Errc::kOutOfRange: return "out of range";
    case Errc::kCapacityExceeded: return "capacity exceeded";
    case Errc::kNotFound: return "not found";
    case Errc::kIoError: return "i/o error";
    case Errc::kCorruptData: return "corrupt data";
    case Errc::kTimeout: return "timeout";
    case Errc::kUnsupported: return "unsupported";
    case Errc::kNotInitialized: return "not initialized";
    case Errc::kBusy: return "busy";
    case Errc::kNumerical: return "numerical failure";
  }
  return "unknown";
}

Status Status::verror(Errc code, const char* fmt, va_list args) {
  Status s;
  s.code_ = code;
  const int n = std::vsnprintf(s.message_, kMessageCapacity, fmt, args);
  if (n >= static_cast<int>(kMessageCapacity)) std::memcpy(s.message_ + kMessageCapacity - 4, "...", 3);
  return s;
}

Status Status::error(Errc code, const char* fmt, ...) {
  va_list args;
  va_start(args, fmt);
  Status s = verror(code, fmt, args);
  va_end(args);
  return s;
}

}  // namespace fw
