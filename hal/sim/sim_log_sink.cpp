#include "hal_sim/sim_log_sink.h"

#include <cstdio>

namespace hal_sim {

void SimLogSink::vlog(hal::LogLevel level, const char* fmt, va_list args) {
  if (static_cast<int>(level) < static_cast<int>(min_level_)) return;
  SimLogLine line;
  line.level = level;
  std::vsnprintf(line.text, sizeof(line.text), fmt, args);
  if (ring_.push_overwrite(line)) ++overwritten_;
  ++total_;
  ++per_level_[static_cast<int>(level)];
}

}  // namespace hal_sim
