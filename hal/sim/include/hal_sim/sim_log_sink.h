// SimLogSink: firmware log lines into a fixed ring of fixed-length lines (no heap). The host reads
// them (tests assert on them; mml-sim prints them with --verbose). When the ring is full the oldest
// line is overwritten and counted.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/ring_buffer.h"
#include "hal/log_sink.h"

namespace hal_sim {

struct SimLogLine {
  static constexpr std::size_t kMaxChars = 160;
  hal::LogLevel level = hal::LogLevel::kInfo;
  char text[kMaxChars] = {};  // truncated, always NUL-terminated
};

class SimLogSink final : public hal::LogSink {
 public:
  static constexpr std::size_t kCapacity = 128;

  explicit SimLogSink(hal::LogLevel min_level = hal::LogLevel::kDebug) : min_level_(min_level) {}
  void vlog(hal::LogLevel level, const char* fmt, va_list args) override;

  std::size_t size() const { return ring_.size(); }
  // i = 0 is the oldest kept line.
  const SimLogLine& line(std::size_t i) const { return ring_[i]; }
  bool pop(SimLogLine* out) { return ring_.pop(out); }
  std::uint64_t total() const { return total_; }
  std::uint64_t overwritten() const { return overwritten_; }
  std::uint64_t count(hal::LogLevel level) const { return per_level_[static_cast<int>(level)]; }

 private:
  hal::LogLevel min_level_;
  fw::RingBuffer<SimLogLine, kCapacity> ring_;
  std::uint64_t total_ = 0;
  std::uint64_t overwritten_ = 0;
  std::uint64_t per_level_[4] = {};
};

}  // namespace hal_sim
