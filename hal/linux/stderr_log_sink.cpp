#include "hal_linux/stderr_log_sink.h"

#include <cstdio>

namespace hal_linux {

void StderrLogSink::vlog(hal::LogLevel level, const char* fmt, va_list args) {
  if (level < min_level_) return;
  static const char* const kPrefix[] = {"debug", "info", "warning", "error"};
  std::fprintf(stderr, "%s: ", kPrefix[static_cast<int>(level)]);
  std::vfprintf(stderr, fmt, args);
  std::fputc('\n', stderr);
}

}  // namespace hal_linux
