// libFuzzer target: the mmlfw configuration parser (firmware/app/app_config.*). Oracle beyond "no
// crash": an accepted configuration holds only values inside the documented ranges, and its
// strings are terminated within their arrays.
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "firmware/app/app_config.h"

namespace {
void check(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "fuzz_app_config: accepted config with %s\n", what);
    std::abort();
  }
}
template <std::size_t N>
bool terminated(const char (&s)[N]) { return std::memchr(s, 0, N) != nullptr; }
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fw::AppConfig c;
  const fw::Status st = fw::parse_app_config("fuzz.conf", reinterpret_cast<const char*>(data), size, &c);
  if (!st) {
    check(st.message() != nullptr && st.message()[0] != '\0', "an error without a message");
    return 0;
  }
  check(terminated(c.laser) && terminated(c.odometry) && terminated(c.output) && terminated(c.localizer) &&
            terminated(c.map), "an unterminated string");
  check(c.laser[0] != '\0', "no laser");
  check(c.mml_preset >= 1 && c.mml_preset <= 4, "mml_preset out of range");
  check(c.workers >= 1 && c.workers <= 16, "workers out of range");
  check(c.num_cores >= 0 && c.num_cores <= fw::AppConfig::kMaxCores, "too many cores");
  check(c.arena_mib >= 1 && c.arena_mib <= 4096, "arena_mib out of range");
  check(c.step_deadline_ms >= 0.1 && c.step_deadline_ms <= 1000.0, "step_deadline_ms out of range");
  check(c.health_period_ms >= 10 && c.health_period_ms <= 10000, "health_period_ms out of range");
  check(c.laser_timeout_ms >= 10 && c.laser_timeout_ms <= 60000, "laser_timeout_ms out of range");
  check(c.can_fd >= -1 && c.can_fd <= 1, "can_fd out of range");
  return 0;
}
