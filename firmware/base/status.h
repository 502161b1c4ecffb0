// Status: the error value every fallible firmware/hal call returns (no exceptions here).
// A status carries a code and a short message that names the input and the problem,
// e.g. "map image 'intel.mmap': CRC mismatch (stored 0x1234, computed 0x5678)".
#pragma once

#include <cstdarg>
#include <cstddef>
#include <cstdint>

namespace fw {

enum class Errc : std::uint8_t {
  kOk = 0,
  kInvalidArgument,   // caller passed something out of contract (bad config value, NaN, ...)
  kOutOfRange,        // index/value outside a valid range
  kCapacityExceeded,  // a fixed-capacity container/pool/arena is full
  kNotFound,
  kIoError,           // read/write/open failed
  kCorruptData,       // bad CRC, truncated record, malformed line
  kTimeout,
  kUnsupported,
  kNotInitialized,
  kBusy,
  kNumerical,         // singular matrix, degenerate geometry
};

const char* errc_name(Errc code);

class Status {
 public:
  // Room for a path (config keys hold up to 255 characters) plus the line, key and problem: a
  // long path must not cut off what went wrong (160 used to lose the line and key of a config).
  static constexpr std::size_t kMessageCapacity = 512;

  constexpr Status() = default;

  static Status ok() { return Status(); }
  // printf-style message; truncated (never overflowed) at kMessageCapacity - 1 characters, the
  // last three then being "..." so a cut message is recognisable.
  static Status error(Errc code, const char* fmt, ...) __attribute__((format(printf, 2, 3)));
  static Status verror(Errc code, const char* fmt, va_list args);

  bool is_ok() const { return code_ == Errc::kOk; }
  explicit operator bool() const { return is_ok(); }
  Errc code() const { return code_; }
  const char* message() const { return message_; }

 private:
  Errc code_ = Errc::kOk;
  char message_[kMessageCapacity] = {0};
};

}  // namespace fw

// Propagate a failed status to the caller (no exceptions in firmware).
#define FW_RETURN_IF_ERROR(expr)              \
  do {                                        \
    ::fw::Status fw_status_tmp_ = (expr);     \
    if (!fw_status_tmp_.is_ok()) return fw_status_tmp_; \
  } while (0)
