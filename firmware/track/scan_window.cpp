#include "firmware/track/scan_window.h"

namespace fw {
namespace track {

void ScanWindow::step(std::uint64_t now_ns) {
  if (have_last_ && now_ns > last_ns_ && now_ns - last_ns_ <= kMaxIntervalNs) {
    intervals_[next_] = now_ns - last_ns_;
    next_ = (next_ + 1) % kIntervals;
    if (count_ < kIntervals) ++count_;
  }
  last_ns_ = now_ns;
  have_last_ = true;
}

std::uint64_t ScanWindow::median_interval_ns() const {
  if (count_ == 0) return 0;
  std::uint64_t v[kIntervals];
  for (std::size_t i = 0; i < count_; ++i) v[i] = intervals_[i];
  for (std::size_t i = 1; i < count_; ++i) {  // insertion sort of at most 8 values
    const std::uint64_t x = v[i];
    std::size_t j = i;
    for (; j > 0 && v[j - 1] > x; --j) v[j] = v[j - 1];
    v[j] = x;
  }
  return count_ % 2 == 1 ? v[count_ / 2] : (v[count_ / 2 - 1] + v[count_ / 2]) / 2;
}

std::uint64_t ScanWindow::window_ns(std::uint32_t delay_scans, std::uint64_t configured_ns) const {
  const std::uint64_t measured = static_cast<std::uint64_t>(delay_scans) * median_interval_ns();
  return measured > configured_ns ? measured : configured_ns;
}

}  // namespace track
}  // namespace fw
