// SickLaser over an in-memory serial port: telegrams with a valid CRC but impossible content are
// counted under a named counter that reaches HEALTH (issue 13: they vanished without a count), and
// a port that is gone reports laser-disconnected.
#include "hal_serial/sick_laser.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <vector>

namespace hal_serial {
namespace {

class MemoryPort final : public hal::SerialPort {
 public:
  long read(std::uint8_t* buf, std::size_t len) override {
    if (!connected_) return -1;
    const std::size_t n = std::min(len, in.size() - pos);
    std::memcpy(buf, in.data() + pos, n);
    pos += n;
    return static_cast<long>(n);
  }
  long write(const std::uint8_t*, std::size_t len) override { return connected_ ? static_cast<long>(len) : -1; }
  bool connected() const override { return connected_; }
  std::vector<std::uint8_t> in;
  std::size_t pos = 0;
  bool connected_ = true;
};

void append_telegram(MemoryPort* port, const std::uint8_t* payload, std::size_t n) {
  std::uint8_t buf[kMaxTelegramBytes];
  const std::size_t len = encode_sick_telegram(kDeviceAddressBit, payload, n, buf, sizeof(buf));
  ASSERT_GT(len, 0u);
  port->in.insert(port->in.end(), buf, buf + len);
}

// Issue 13 fault campaign: two scans in one read — the driver hands out the newest and the one it
// replaced is reported as skipped (HEALTH dropped_scans via the loop), not lost silently.
TEST(SickLaser, ScanReplacedBeforePollIsReportedSkipped) {
  MemoryPort port;
  SickLaser laser;
  laser.init(&port, nullptr, SickLaserOptions{});
  MeasuredValues v;
  v.count = 181;
  std::uint8_t buf[kMaxTelegramBytes];
  for (int k = 0; k < 2; ++k) {
    for (int i = 0; i < 181; ++i) v.values[i] = static_cast<std::uint16_t>(300 + i + k);
    const std::size_t n = encode_measured_values(v, buf, sizeof(buf));
    port.in.insert(port.in.end(), buf, buf + n);
  }
  hal::LaserScan scan;
  ASSERT_TRUE(laser.poll(&scan));
  EXPECT_FLOAT_EQ(scan.ranges[0], 3.01f);  // the newer one
  const hal::LaserScanSource& source = laser;
  EXPECT_EQ(source.skipped_scans(), 1u);
  EXPECT_FALSE(laser.poll(&scan));
}

TEST(SickLaser, CrcValidTelegramsWithImpossibleContentAreCounted) {
  MemoryPort port;
  SickLaser laser;
  laser.init(&port, nullptr, SickLaserOptions{});
  // Each has a valid CRC (the parser accepts it) but cannot be a measurement:
  const std::uint8_t zero_values[] = {kRespMeasuredValues, 0x00, 0x00, 0x00};        // 0 values
  const std::uint8_t unit_3[] = {kRespMeasuredValues, 0x01, 0xC0, 0x10, 0x00, 0x00};  // unit bits 3
  const std::uint8_t len_mismatch[] = {kRespMeasuredValues, 0x05, 0x00, 0x10, 0x00, 0x00};  // 5 values, 1 sent
  const std::uint8_t too_many[] = {kRespMeasuredValues, 0xFF, 0x03, 0x00};            // 1023 values
  append_telegram(&port, zero_values, sizeof(zero_values));
  append_telegram(&port, unit_3, sizeof(unit_3));
  append_telegram(&port, len_mismatch, sizeof(len_mismatch));
  append_telegram(&port, too_many, sizeof(too_many));
  MeasuredValues good;
  good.count = 181;
  for (int i = 0; i < 181; ++i) good.values[i] = static_cast<std::uint16_t>(200 + i);
  std::uint8_t buf[kMaxTelegramBytes];
  const std::size_t n = encode_measured_values(good, buf, sizeof(buf));
  port.in.insert(port.in.end(), buf, buf + n);

  hal::LaserScan scan;
  ASSERT_TRUE(laser.poll(&scan));
  EXPECT_EQ(scan.beam_count, 181u);
  EXPECT_EQ(laser.parser_stats().crc_errors, 0u);
  EXPECT_EQ(laser.parser_stats().telegrams, 5u);
  EXPECT_EQ(laser.stats().scans, 1u);
  EXPECT_EQ(laser.stats().bad_measurements, 4u);
  // The named counter the loop copies into Health::invalid_scans (HEALTH InvalidScans).
  const hal::LaserScanSource& source = laser;
  EXPECT_EQ(source.invalid_scans(), 4u);
  EXPECT_EQ(source.fault_bits(), 0u);
}

TEST(SickLaser, PortGoneIsLaserDisconnectedAndNotReadInALoop) {
  MemoryPort port;
  SickLaser laser;
  laser.init(&port, nullptr, SickLaserOptions{});
  port.connected_ = false;
  hal::LaserScan scan;
  for (int i = 0; i < 100; ++i) EXPECT_FALSE(laser.poll(&scan));
  EXPECT_EQ(laser.stats().read_errors, 0u);  // not an error per poll: the board reopens the port
  EXPECT_EQ(laser.fault_bits(), static_cast<std::uint32_t>(hal::HealthFault::kLaserDisconnected));
  EXPECT_STREQ(hal::health_fault_name(hal::HealthFault::kLaserDisconnected), "laser-disconnected");
  port.connected_ = true;
  EXPECT_TRUE(laser.restart());
  EXPECT_EQ(laser.fault_bits(), 0u);
  EXPECT_EQ(laser.stats().restarts, 1u);
}

}  // namespace
}  // namespace hal_serial
