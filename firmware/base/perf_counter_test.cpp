#include "firmware/base/perf_counter.h"

#include <gtest/gtest.h>

#include "firmware/base/clock.h"

namespace fw {
namespace {

// A clock the test advances by hand (the common layer's tests use no HAL backend).
class ManualClock final : public Clock {
 public:
  std::uint64_t now_ns() const override { return now_ns_; }
  void advance_ns(std::uint64_t dt) { now_ns_ += dt; }

 private:
  std::uint64_t now_ns_ = 0;
};

TEST(PerfCounterTest, StatsFromSteppedClock) {
  ManualClock clock;
  PerfCounter counter("stage");
  for (int i = 1; i <= 100; ++i) {
    PerfScope scope(counter, clock);
    clock.advance_ns(static_cast<std::uint64_t>(i) * 1000000);  // i ms
  }
  const PerfStats s = counter.stats();
  EXPECT_EQ(s.count, 100u);
  EXPECT_NEAR(s.mean_ms, 50.5, 1e-9);
  EXPECT_NEAR(s.max_ms, 100.0, 1e-9);
  EXPECT_NEAR(s.p50_ms, 51.0, 1.0);
  EXPECT_NEAR(s.p99_ms, 99.0, 1.0);
}

}  // namespace
}  // namespace fw
