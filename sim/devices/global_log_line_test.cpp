// The global records of a black box file (issue 60): the line hal_can::BlackBox writes is read
// back exactly; a cut or broken line is refused with what is wrong (the reader adds file and line).
#include "sim/devices/global_log_line.h"

#include <gtest/gtest.h>

namespace sim {
namespace {

TEST(GlobalLogLineTest, ReadsWhatTheBlackBoxWrites) {
  const std::string l = "(1765432100.413300) global take 1765432100.013300 7";
  EXPECT_TRUE(is_global_log_line(l));
  hal::GlobalRecord r;
  std::string why;
  ASSERT_TRUE(parse_global_log_line(l, &r, &why)) << why;
  EXPECT_EQ(r.scan_ns, 1765432100413300000ull);
  EXPECT_EQ(r.job_scan_ns, 1765432100013300000ull);
  EXPECT_EQ(r.deadline_rounds, 7u);
  EXPECT_FALSE(r.dropped);
  ASSERT_TRUE(parse_global_log_line("(19.000000) global drop 1.000000 0", &r, &why)) << why;
  EXPECT_TRUE(r.dropped);
  EXPECT_EQ(r.scan_ns, 19000000000ull);
  EXPECT_FALSE(is_global_log_line("(1.000000) rx 118#AB01"));
  EXPECT_FALSE(is_global_log_line("(1.000000) rx laser 0280"));
}

TEST(GlobalLogLineTest, RefusesBrokenLines) {
  hal::GlobalRecord r;
  const char* bad[][2] = {
      {"(19.000000) global take 1.000000", "cut line"},
      {"(19.000000) global take", "cut line"},
      {"(19.0000) global take 1.000000 3", "time stamp"},
      {"(19.000000) global keep 1.000000 3", "take or drop"},
      {"(19.000000) global take 1.00000x 3", "job scan"},
      {"(19.000000) global take 1.000000 -3", "rounds"},
      {"(19.000000) global take 1.000000 3 4", "unexpected field"},
      {"(1.000000) global take 19.000000 3", "comes after"},
  };
  for (const auto& b : bad) {
    std::string why;
    EXPECT_FALSE(parse_global_log_line(b[0], &r, &why)) << b[0];
    EXPECT_NE(why.find(b[1]), std::string::npos) << b[0] << ": " << why;
  }
}

}  // namespace
}  // namespace sim
