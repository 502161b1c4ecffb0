#include "firmware/base/perf_counter.h"

#include <algorithm>

namespace fw {

void PerfCounter::add_ns(std::uint64_t elapsed_ns) {
  window_[count_ % kWindow] = elapsed_ns;
  ++count_;
  total_ns_ += elapsed_ns;
  if (elapsed_ns > max_ns_) max_ns_ = elapsed_ns;
}

PerfStats PerfCounter::stats() const {
  PerfStats s;
  s.count = count_;
  if (count_ == 0) return s;
  s.mean_ms = static_cast<double>(total_ns_) / static_cast<double>(count_) * 1e-6;
  s.max_ms = static_cast<double>(max_ns_) * 1e-6;
  // Percentiles on a stack copy: 16 KiB, only when somebody asks for the figures.
  const std::size_t n = count_ < kWindow ? static_cast<std::size_t>(count_) : kWindow;
  std::uint64_t sorted[kWindow];
  std::copy(window_, window_ + n, sorted);
  std::sort(sorted, sorted + n);
  auto pct = [&](double p) {
    std::size_t idx = static_cast<std::size_t>(p * static_cast<double>(n - 1) + 0.5);
    if (idx >= n) idx = n - 1;
    return static_cast<double>(sorted[idx]) * 1e-6;
  };
  s.p50_ms = pct(0.50);
  s.p99_ms = pct(0.99);
  return s;
}

void PerfCounter::reset() {
  count_ = total_ns_ = max_ns_ = 0;
}

void PerfCounter::print(std::FILE* out) const {
  const PerfStats s = stats();
  std::fprintf(out, "%-24s n=%-8llu mean=%.3f ms p50=%.3f ms p99=%.3f ms max=%.3f ms\n", name_,
               static_cast<unsigned long long>(s.count), s.mean_ms, s.p50_ms, s.p99_ms, s.max_ms);
}

}  // namespace fw
