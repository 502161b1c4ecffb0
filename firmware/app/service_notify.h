// What mmlfw tells its service manager (systemd, Type=notify; the socket itself is
// hal_linux::SdNotify): READY=1 once start-up is done, WATCHDOG=1 from the sensor loop only while
// it keeps its deadline, STATUS= with the localization status. Pure logic: no clock, no socket,
// so the rules are unit-tested here and the binary only carries the messages.
//
// The watchdog rule (WatchdogFeed): the sensor context checks every half watchdog period (as
// sd_watchdog_enabled(3) advises) whether to feed. It feeds when, in the window since the last
// check, it either stepped no scan (a silent laser is a fault shown in HEALTH and STATUS, not a
// reason to restart) or at least one step kept the step deadline. It withholds the feed when every
// step of the window missed its deadline, and a loop that stalls never reaches the check at all:
// a full watchdog period (two windows) of either and the manager restarts the firmware. One slow
// step among good ones (a page fault, a cold cache) never costs a restart.
#pragma once

#include <cstddef>
#include <cstdint>

#include "hal/msg/health.h"
#include "hal/msg/pose_estimate.h"

namespace fw {

class WatchdogFeed {
 public:
  // period_ns = the manager's watchdog period (WATCHDOG_USEC); 0 disables the feed.
  void start(std::uint64_t period_ns, std::uint64_t now_ns, std::uint64_t steps, std::uint64_t deadline_misses);
  // One sensor-loop cycle with the loop's running totals; true = send WATCHDOG=1 now.
  bool cycle(std::uint64_t now_ns, std::uint64_t steps, std::uint64_t deadline_misses);
  std::uint64_t check_interval_ns() const { return interval_ns_; }
  std::uint64_t fed() const { return fed_; }
  // Windows in which every step missed its deadline (feed withheld).
  std::uint64_t withheld() const { return withheld_; }

 private:
  std::uint64_t interval_ns_ = 0;
  std::uint64_t window_start_ns_ = 0;
  std::uint64_t window_steps_ = 0;
  std::uint64_t window_misses_ = 0;
  std::uint64_t fed_ = 0;
  std::uint64_t withheld_ = 0;
};

// "STATUS=<status>[ (<reason>)][, faults <names>], <n> scans, <m> deadline misses" into buf
// (always NUL-terminated, truncated at len - 1). Returns the length written.
std::size_t format_service_status(char* buf, std::size_t len, const hal::PoseEstimate& estimate,
                                  const hal::Health& health);

// True when the published STATUS would change: status, reason or fault bits (the counters are
// not a reason to send; the manager shows the last text).
bool service_status_changed(const hal::PoseEstimate& previous, std::uint32_t previous_faults,
                            const hal::PoseEstimate& estimate, std::uint32_t faults);

// STATUS= goes out at most this often: a status that flips on every scan (75 Hz) must not flood
// the service manager; the last change is sent once the interval has passed.
constexpr std::uint64_t kServiceStatusMinIntervalNs = 250000000ull;
// An unchanged STATUS= is refreshed this often, so that `systemctl status` shows current counters.
constexpr std::uint64_t kServiceStatusRefreshNs = 5000000000ull;

// True when a STATUS= is due now: changed since the last one sent (at last_sent_ns) and at least
// kServiceStatusMinIntervalNs after it, or unchanged for kServiceStatusRefreshNs.
bool service_status_due(const hal::PoseEstimate& previous, std::uint32_t previous_faults,
                        const hal::PoseEstimate& estimate, std::uint32_t faults, std::uint64_t now_ns,
                        std::uint64_t last_sent_ns);

}  // namespace fw
