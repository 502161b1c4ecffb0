#include "hal_linux/black_box_file.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace hal_linux {
namespace {

TEST(BlackBoxFile, WritesACandumpLogAndReplacesItWhole) {
  std::vector<hal_can::BlackBoxEntry> storage(4000);
  hal_can::BlackBox box;
  box.init(storage.data(), storage.size());
  hal::CanFrame f;
  f.len = 8;
  for (int i = 0; i < 5000; ++i) {
    f.id = 0x118;
    f.data[0] = static_cast<std::uint8_t>(i);
    box.record(f, 1'000'000'000ull + static_cast<std::uint64_t>(i) * 1000, (i % 7) == 0);
  }
  const std::string path = ::testing::TempDir() + "/mmlfw_blackbox_test.log";
  std::size_t written = 0;
  ASSERT_TRUE(write_black_box_file(box, path.c_str(), &written).is_ok());
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  EXPECT_EQ(text.size(), written);
  EXPECT_EQ(text.rfind("(1.001000) ", 0), 0u) << text.substr(0, 40);  // the oldest kept: frame 1000
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 4000);
  EXPECT_NE(access((path + ".tmp").c_str(), F_OK), 0);
  unlink(path.c_str());
}

TEST(BlackBoxFile, MergesTheSerialAndCanRingsByTime) {
  std::vector<hal_can::BlackBoxEntry> cs(8);
  hal_can::BlackBox can;
  can.init(cs.data(), cs.size());
  std::vector<hal_serial::SerialBlackBoxEntry> ss(8);
  hal_serial::SerialBlackBox serial;
  serial.init(ss.data(), ss.size());
  hal::CanFrame f;
  f.id = 0x110;
  f.len = 1;
  can.record(f, 2'000, false);
  can.record(f, 5'000, false);
  const std::uint8_t b[2] = {0x02, 0x80};
  serial.record(b, 2, 1'000, true);
  serial.record(b, 2, 2'000, false);  // same µs as a CAN frame: after it
  const std::string path = ::testing::TempDir() + "/mmlfw_blackbox_merged.log";
  ASSERT_TRUE(write_black_box_file(&can, &serial, path.c_str(), nullptr).is_ok());
  std::ifstream in(path);
  std::stringstream ss2;
  ss2 << in.rdbuf();
  EXPECT_EQ(ss2.str(),
            "(0.000001) tx laser 0280\n(0.000002) rx 110#00\n(0.000002) rx laser 0280\n(0.000005) rx 110#00\n");
  ASSERT_TRUE(write_black_box_file(nullptr, &serial, path.c_str(), nullptr).is_ok());
  unlink(path.c_str());
}

TEST(BlackBoxFile, AnUnwritablePathIsAnErrorNamingIt) {
  hal_can::BlackBox box;
  const fw::Status s = write_black_box_file(box, "/nonexistent-dir/bb.log", nullptr);
  EXPECT_FALSE(s.is_ok());
  EXPECT_NE(std::string(s.message()).find("/nonexistent-dir/bb.log"), std::string::npos) << s.message();
  EXPECT_FALSE(write_black_box_file(box, "", nullptr).is_ok());
}

}  // namespace
}  // namespace hal_linux
