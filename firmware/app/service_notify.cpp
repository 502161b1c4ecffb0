#include "firmware/app/service_notify.h"

#include <cstdio>

namespace fw {

void WatchdogFeed::start(std::uint64_t period_ns, std::uint64_t now_ns, std::uint64_t steps,
                         std::uint64_t deadline_misses) {
  interval_ns_ = period_ns / 2;
  window_start_ns_ = now_ns;
  window_steps_ = steps;
  window_misses_ = deadline_misses;
  fed_ = 0;
  withheld_ = 0;
}

bool WatchdogFeed::cycle(std::uint64_t now_ns, std::uint64_t steps, std::uint64_t deadline_misses) {
  if (interval_ns_ == 0 || now_ns - window_start_ns_ < interval_ns_) return false;
  const std::uint64_t stepped = steps - window_steps_;
  const std::uint64_t missed = deadline_misses - window_misses_;
  window_start_ns_ = now_ns;
  window_steps_ = steps;
  window_misses_ = deadline_misses;
  if (stepped > 0 && missed >= stepped) {
    ++withheld_;
    return false;
  }
  ++fed_;
  return true;
}

std::size_t format_service_status(char* buf, std::size_t len, const hal::PoseEstimate& estimate,
                                  const hal::Health& health) {
  if (len == 0) return 0;
  std::size_t n = 0;
  auto put = [&](int r) {
    if (r > 0) n += static_cast<std::size_t>(r);
    if (n >= len) n = len - 1;
  };
  put(std::snprintf(buf, len, "STATUS=%s", hal::status_name(estimate.status)));
  if (estimate.reason != hal::StatusReason::kNone) put(std::snprintf(buf + n, len - n, " (%s)", hal::reason_name(estimate.reason)));
  const std::uint32_t faults = health.fault_bits & hal::kHealthFaultMask;
  const hal::HealthFault named[] = {hal::HealthFault::kLaserTimeout, hal::HealthFault::kLaserDisconnected};
  const char* sep = ", faults ";
  for (hal::HealthFault f : named) {
    if (faults & static_cast<std::uint32_t>(f)) {
      put(std::snprintf(buf + n, len - n, "%s%s", sep, hal::health_fault_name(f)));
      sep = " ";
    }
  }
  if (health.fault_bits & ~hal::kHealthFaultMask) put(std::snprintf(buf + n, len - n, ", internal fault bits 0x%x", health.fault_bits & ~hal::kHealthFaultMask));
  put(std::snprintf(buf + n, len - n, ", %u scans, %u deadline misses", health.scans_processed, health.deadline_misses));
  return n;
}

bool service_status_changed(const hal::PoseEstimate& previous, std::uint32_t previous_faults,
                            const hal::PoseEstimate& estimate, std::uint32_t faults) {
  return previous.status != estimate.status || previous.reason != estimate.reason || previous_faults != faults;
}

bool service_status_due(const hal::PoseEstimate& previous, std::uint32_t previous_faults,
                        const hal::PoseEstimate& estimate, std::uint32_t faults, std::uint64_t now_ns,
                        std::uint64_t last_sent_ns) {
  const std::uint64_t since = now_ns - last_sent_ns;
  if (since >= kServiceStatusRefreshNs) return true;
  return service_status_changed(previous, previous_faults, estimate, faults) && since >= kServiceStatusMinIntervalNs;
}

}  // namespace fw
