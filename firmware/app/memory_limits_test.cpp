#include "firmware/app/memory_limits.h"

#include <gtest/gtest.h>

#include <cstring>

namespace fw {
namespace {

TEST(MemoryLimits, FootprintBeyondAnyLimitIsAnErrorNamingIt) {
  MemoryLimits l;
  l.physical_bytes = 512ull << 20;
  l.cgroup_bytes = 300ull << 20;
  l.address_space_bytes = 2048ull << 20;
  EXPECT_TRUE(check_memory_fits(200ull << 20, l, "arena + statics").is_ok());
  Status s = check_memory_fits(400ull << 20, l, "arena + statics");
  ASSERT_FALSE(s.is_ok());
  EXPECT_NE(std::strstr(s.message(), "memory.max"), nullptr) << s.message();
  EXPECT_NE(std::strstr(s.message(), "arena + statics need 400.0 MiB"), nullptr) << s.message();
  s = check_memory_fits(600ull << 20, l, "x");
  EXPECT_NE(std::strstr(s.message(), "physical memory"), nullptr) << s.message();
  l.cgroup_bytes = MemoryLimits::kNone;
  s = check_memory_fits(1000ull << 20, l, "x");
  EXPECT_NE(std::strstr(s.message(), "physical memory"), nullptr) << s.message();
  l.physical_bytes = MemoryLimits::kNone;
  s = check_memory_fits(3000ull << 20, l, "x");
  EXPECT_NE(std::strstr(s.message(), "ulimit -v"), nullptr) << s.message();
}

TEST(MemoryLimits, ThisMachineHasPhysicalMemoryAndFitsASmallFootprint) {
  const MemoryLimits l = read_memory_limits();
  EXPECT_NE(l.physical_bytes, MemoryLimits::kNone);
  EXPECT_GT(l.physical_bytes, 16ull << 20);
  EXPECT_TRUE(check_memory_fits(1 << 20, l, "1 MiB").is_ok());
  EXPECT_FALSE(check_memory_fits(std::uint64_t(1) << 60, l, "1 EiB").is_ok());
}

}  // namespace
}  // namespace fw
