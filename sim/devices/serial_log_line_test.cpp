// Serial black box lines (issue 60): the format the firmware writes reads back exactly; every kind of
// damage is a clear error, never a crash.
#include "sim/devices/serial_log_line.h"

#include <gtest/gtest.h>

namespace sim {
namespace {

TEST(SerialLogLine, ReadsWhatTheRingWrites) {
  SerialLogLine l;
  std::string err;
  ASSERT_TRUE(parse_serial_log_line("(1700000000.123456) rx laser 0280FFa0", &l, &err)) << err;
  EXPECT_EQ(l.t_ns, 1700000000123456000ull);
  EXPECT_FALSE(l.tx);
  EXPECT_EQ(l.bytes, (std::vector<std::uint8_t>{0x02, 0x80, 0xFF, 0xA0}));
  ASSERT_TRUE(parse_serial_log_line("(2.000000) tx laser 20", &l, &err)) << err;
  EXPECT_TRUE(l.tx);
  EXPECT_TRUE(is_serial_log_line("(2.000000) tx laser 20"));
  EXPECT_FALSE(is_serial_log_line("(2.000000) rx 118#0011"));
}

TEST(SerialLogLine, DamageIsAnErrorNamingTheProblem) {
  const char* bad[][2] = {
      {"(2.000000) rx laser 028", "3 hex digits"},        // cut inside a byte
      {"(2.000000) rx laser", "0 hex digits"},            // cut before the bytes
      {"(2.0000", "bad time stamp"},                      // cut inside the stamp
      {"2.000000 rx laser 02", "bad time stamp"},
      {"(2.000000) xx laser 02", "direction 'xx'"},
      {"(2.000000) rx can0 02", "port 'can0'"},
      {"(2.000000) rx laser 0G", "'0G' at byte 0"},
      {"(2.000000) rx laser 02 03", "unexpected field '03'"},
      {"(-1.000000) rx laser 02", "bad time stamp"},
  };
  for (const auto& b : bad) {
    SerialLogLine l;
    std::string err;
    EXPECT_FALSE(parse_serial_log_line(b[0], &l, &err)) << b[0];
    EXPECT_NE(err.find(b[1]), std::string::npos) << b[0] << " -> " << err;
  }
  SerialLogLine l;
  std::string err;
  EXPECT_FALSE(parse_serial_log_line("(2.000000) rx laser " + std::string(130, 'A'), &l, &err));
  EXPECT_NE(err.find("130 hex digits"), std::string::npos) << err;
}

}  // namespace
}  // namespace sim
