// PerfCounter: per-stage timing (PX4's perf_counter): count, mean, p50, p99, max. Always on and
// cheap: O(1) per sample into a fixed ring of the last kWindow samples; percentiles are computed
// on request (never on the hot path). Time comes from the clock interface (firmware/base/clock.h,
// implemented by the HAL backends) so the simulator can step it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>

#include "firmware/base/clock.h"

namespace fw {

struct PerfStats {
  std::uint64_t count = 0;
  double mean_ms = 0, p50_ms = 0, p99_ms = 0, max_ms = 0;
};

class PerfCounter {
 public:
  static constexpr std::size_t kWindow = 2048;

  explicit PerfCounter(const char* name = "unnamed") : name_(name) {}
  const char* name() const { return name_; }

  void add_ns(std::uint64_t elapsed_ns);
  std::uint64_t count() const { return count_; }
  std::uint64_t total_ns() const { return total_ns_; }  // of every sample since reset
  // Percentiles over the last kWindow samples; count/mean/max over all samples.
  PerfStats stats() const;
  void reset();
  void print(std::FILE* out) const;

 private:
  const char* name_;
  std::uint64_t count_ = 0;
  std::uint64_t total_ns_ = 0;
  std::uint64_t max_ns_ = 0;
  std::uint64_t window_[kWindow] = {};
};

// Scoped timer: adds the elapsed time of its scope to a counter.
class PerfScope {
 public:
  PerfScope(PerfCounter& counter, const fw::Clock& clock) : counter_(counter), clock_(clock), start_(clock.now_ns()) {}
  ~PerfScope() { counter_.add_ns(clock_.now_ns() - start_); }
  PerfScope(const PerfScope&) = delete;
  PerfScope& operator=(const PerfScope&) = delete;

 private:
  PerfCounter& counter_;
  const fw::Clock& clock_;
  std::uint64_t start_;
};

}  // namespace fw
