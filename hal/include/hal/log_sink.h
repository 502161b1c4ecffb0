// LogSink: where firmware text logs go (stderr on Linux, a ring in the simulator).
#pragma once

#include <cstdarg>

namespace hal {

enum class LogLevel { kDebug, kInfo, kWarning, kError };

class LogSink {
 public:
  virtual ~LogSink() = default;
  virtual void vlog(LogLevel level, const char* fmt, va_list args) = 0;
  void log(LogLevel level, const char* fmt, ...) __attribute__((format(printf, 3, 4))) {
    va_list args;
    va_start(args, fmt);
    vlog(level, fmt, args);
    va_end(args);
  }
};

}  // namespace hal
