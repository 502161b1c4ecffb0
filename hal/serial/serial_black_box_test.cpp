// The serial black box ring (issue 60): chunks split at kChunkBytes, the oldest overwritten when
// full, lines in the documented format, and the recording port between a driver and its port.
#include "hal_serial/serial_black_box.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "hal_serial/recording_serial_port.h"

namespace hal_serial {
namespace {

class FakeClock final : public hal::Clock {
 public:
  std::uint64_t now_ns() const override { return t_ns; }
  std::uint64_t t_ns = 0;
};

class LoopPort final : public hal::SerialPort {
 public:
  long read(std::uint8_t* buf, std::size_t len) override {
    const std::size_t n = pending.size() < len ? pending.size() : len;
    for (std::size_t i = 0; i < n; ++i) buf[i] = pending[i];
    pending.erase(pending.begin(), pending.begin() + static_cast<long>(n));
    return static_cast<long>(n);
  }
  long write(const std::uint8_t* buf, std::size_t len) override {
    written.insert(written.end(), buf, buf + len);
    return static_cast<long>(len);
  }
  std::vector<std::uint8_t> pending, written;
};

std::string line(const SerialBlackBox& box, std::size_t i) {
  char buf[SerialBlackBox::kMaxLineBytes];
  const std::size_t n = box.format_line(i, buf, sizeof(buf));
  return std::string(buf, n);
}

TEST(SerialBlackBox, OffWithoutStorage) {
  SerialBlackBox box;
  const std::uint8_t b[3] = {1, 2, 3};
  box.record(b, 3, 5, false);
  EXPECT_FALSE(box.enabled());
  EXPECT_EQ(box.size(), 0u);
}

TEST(SerialBlackBox, SplitsLongChunksAndFormatsLines) {
  std::vector<SerialBlackBoxEntry> storage(8);
  SerialBlackBox box;
  box.init(storage.data(), storage.size());
  std::vector<std::uint8_t> bytes(150);
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<std::uint8_t>(i);
  box.record(bytes.data(), bytes.size(), 1'700'000'000'123'456'789ull, false);
  const std::uint8_t req[4] = {0x02, 0x00, 0xAB, 0xFF};
  box.record(req, 4, 2'000'000'000ull, true);
  ASSERT_EQ(box.size(), 4u);  // 64 + 64 + 22, then the request
  EXPECT_EQ(box.entry(0).len, 64);
  EXPECT_EQ(box.entry(2).len, 22);
  EXPECT_EQ(box.bytes_recorded(), 154u);
  EXPECT_EQ(line(box, 0).substr(0, 39), "(1700000000.123456) rx laser 0001020304");
  EXPECT_EQ(line(box, 2).size(), std::string("(1700000000.123456) rx laser ").size() + 44 + 1);
  EXPECT_EQ(line(box, 3), "(2.000000) tx laser 0200ABFF\n");
  char small[10];
  EXPECT_EQ(box.format_line(0, small, sizeof(small)), 0u);  // never past the end
  EXPECT_EQ(line(box, 4), "");
}

TEST(SerialBlackBox, KeepsTheNewestWhenFull) {
  std::vector<SerialBlackBoxEntry> storage(3);
  SerialBlackBox box;
  box.init(storage.data(), storage.size());
  for (std::uint8_t i = 0; i < 10; ++i) box.record(&i, 1, 1000ull * i, false);
  ASSERT_EQ(box.size(), 3u);
  EXPECT_EQ(box.overwritten(), 7u);
  EXPECT_EQ(box.entry(0).data[0], 7);
  EXPECT_EQ(box.entry(2).data[0], 9);
  EXPECT_EQ(line(box, 0), "(0.000007) rx laser 07\n");
}

TEST(RecordingSerialPort, RecordsReadsAtTheClockAndWrites) {
  LoopPort inner;
  FakeClock clock;
  std::vector<SerialBlackBoxEntry> storage(16);
  SerialBlackBox box;
  box.init(storage.data(), storage.size());
  RecordingSerialPort port;
  port.init(&inner, &clock, &box);
  std::uint8_t buf[8];
  EXPECT_EQ(port.read(buf, sizeof(buf)), 0);  // nothing read, nothing recorded
  EXPECT_EQ(box.size(), 0u);
  inner.pending = {0xDE, 0xAD, 0xBE, 0xEF, 0x01};
  clock.t_ns = 3'000'000;
  EXPECT_EQ(port.read(buf, 3), 3);
  clock.t_ns = 4'000'000;
  const std::uint8_t cmd[2] = {0x20, 0x24};
  EXPECT_EQ(port.write(cmd, 2), 2);
  EXPECT_EQ(inner.written.size(), 2u);
  ASSERT_EQ(box.size(), 2u);
  EXPECT_EQ(line(box, 0), "(0.003000) rx laser DEADBE\n");
  EXPECT_EQ(line(box, 1), "(0.004000) tx laser 2024\n");
  RecordingSerialPort unset;
  EXPECT_EQ(unset.read(buf, 1), -1);
  EXPECT_FALSE(unset.connected());
}

}  // namespace
}  // namespace hal_serial
