// StderrLogSink: firmware logs to stderr with a level prefix.
#pragma once

#include "hal/log_sink.h"

namespace hal_linux {

class StderrLogSink final : public hal::LogSink {
 public:
  explicit StderrLogSink(hal::LogLevel min_level = hal::LogLevel::kInfo) : min_level_(min_level) {}
  void vlog(hal::LogLevel level, const char* fmt, va_list args) override;

 private:
  hal::LogLevel min_level_;
};

}  // namespace hal_linux
