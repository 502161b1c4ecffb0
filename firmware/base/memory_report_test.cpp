#include "firmware/base/memory_report.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>

#include "firmware/base/ring_buffer.h"

namespace fw {
namespace {

TEST(MemoryReportTest, ContainersRegisterBytesAndHighWater) {
  MemoryReport::instance().clear();
  static RingBuffer<float, 1000> v;
  static RingBuffer<int, 16> r;
  ASSERT_TRUE(v.report_as("rbsm", "weights").is_ok());
  ASSERT_TRUE(r.report_as("hal", "scan ring").is_ok());
  for (int i = 0; i < 10; ++i) (void)v.push(1.0f);
  EXPECT_EQ(MemoryReport::instance().module_bytes("rbsm"), sizeof(v));
  EXPECT_EQ(MemoryReport::instance().total_bytes(), sizeof(v) + sizeof(r));
  char buf[4096] = {0};
  std::FILE* f = fmemopen(buf, sizeof(buf), "w");
  MemoryReport::instance().print(f);
  std::fclose(f);
  EXPECT_NE(std::strstr(buf, "weights"), nullptr);
  EXPECT_NE(std::strstr(buf, "TOTAL"), nullptr);
  EXPECT_EQ(*MemoryReport::instance().region(0).high_water, 10u);
  MemoryReport::instance().clear();
}

}  // namespace
}  // namespace fw
