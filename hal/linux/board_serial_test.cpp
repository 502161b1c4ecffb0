// Board with a serial SICK laser on a pseudo-terminal whose peer closes and comes back (issue 13:
// the firmware then polled/read ~7000 times a second, logged nothing and HEALTH showed no fault).
// The pty is made here (posix_openpt) and reached through a symlink, as socat's `link=` and udev's
// /dev/serial/by-id names are: the peer "returns" as a new pty behind the same name.
#include "hal_linux/board.h"

#include <gtest/gtest.h>
#include <fcntl.h>
#include <poll.h>
#include <stdlib.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <string>

#include "hal_serial/sick_telegram.h"

namespace hal_linux {
namespace {

using Clock = std::chrono::steady_clock;

// Master side of a pty, its slave reachable as `link`.
// Like socat's `link=`, the name exists only while the peer is there: a dangling link to the freed
// /dev/pts/N could be reopened by the board onto a pty another process (a parallel test) was given.
struct Peer {
  int master = -1;
  std::string link;
  bool open(const std::string& name) {
    master = ::posix_openpt(O_RDWR | O_NOCTTY);
    if (master < 0 || ::grantpt(master) != 0 || ::unlockpt(master) != 0) return false;
    const char* slave = ::ptsname(master);
    if (slave == nullptr) return false;
    link = name;
    ::unlink(link.c_str());
    return ::symlink(slave, link.c_str()) == 0;
  }
  void close() {
    if (!link.empty()) ::unlink(link.c_str());
    if (master >= 0) ::close(master);
    master = -1;
  }
  // True when the scanner request (mode change to continuous output) arrived within timeout_ms.
  bool got_request(int timeout_ms) {
    hal_serial::SickParser parser;
    hal_serial::SickTelegram t;
    std::uint8_t buf[256];
    const auto end = Clock::now() + std::chrono::milliseconds(timeout_ms);
    while (Clock::now() < end) {
      pollfd p{master, POLLIN, 0};
      if (::poll(&p, 1, 5) > 0 && (p.revents & POLLIN)) {
        const ssize_t n = ::read(master, buf, sizeof(buf));
        if (n > 0) parser.feed(buf, static_cast<std::size_t>(n));
        if (parser.next(&t)) return t.command == hal_serial::kCmdModeChange;
      }
    }
    return false;
  }
  bool send_scan(std::uint16_t first) {
    hal_serial::MeasuredValues v;
    v.count = 181;
    for (int i = 0; i < 181; ++i) v.values[i] = static_cast<std::uint16_t>(first + i);
    std::uint8_t buf[hal_serial::kMaxTelegramBytes];
    const std::size_t n = hal_serial::encode_measured_values(v, buf, sizeof(buf));
    return ::write(master, buf, n) == static_cast<ssize_t>(n);
  }
  ~Peer() { close(); }
};

// Runs the firmware's idle cycle (wait_for_input(5) + laser poll) for `ms`; returns the cycles.
int run_cycles(Board* board, int ms, int* scans) {
  const auto end = Clock::now() + std::chrono::milliseconds(ms);
  int cycles = 0;
  hal::LaserScan scan;
  while (Clock::now() < end) {
    board->wait_for_input(5);
    if (board->hal().laser->poll(&scan)) ++*scans;
    ++cycles;
  }
  return cycles;
}

TEST(BoardSerial, PeerClosesThenReturns) {
  char dir[] = "/tmp/mmlfw-board-serial.XXXXXX";
  ASSERT_NE(::mkdtemp(dir), nullptr);
  const std::string link = std::string(dir) + "/ttyLASER";
  Peer peer;
  ASSERT_TRUE(peer.open(link)) << std::strerror(errno);

  static Board board;  // large (rings, parser): static storage as in mmlfw
  BoardSpec spec;
  const std::string laser = "serial:" + link + "@38400";
  spec.laser = laser.c_str();
  spec.odometry = "none";
  spec.output = "log";
  spec.log_level = hal::LogLevel::kWarning;
  fw::Status s = board.create(spec);
  ASSERT_TRUE(s.is_ok()) << s.message();
  ASSERT_TRUE(peer.got_request(1000));
  ASSERT_TRUE(peer.send_scan(100));
  int scans = 0;
  run_cycles(&board, 100, &scans);
  EXPECT_EQ(scans, 1);
  const hal::LaserScanSource& source = *board.hal().laser;
  const std::uint32_t kDisconnected = static_cast<std::uint32_t>(hal::HealthFault::kLaserDisconnected);
  EXPECT_EQ(source.fault_bits(), 0u);

  // The peer closes (scanner unplugged / socat gone). 500 ms of the idle cycle: with a 5 ms wait
  // that is ~100 cycles; the busy loop on the dead descriptor made thousands.
  peer.close();
  const int cycles = run_cycles(&board, 500, &scans);
  EXPECT_LE(cycles, 150) << "busy loop on a hung-up serial port";
  EXPECT_EQ(source.fault_bits() & kDisconnected, kDisconnected);
  EXPECT_LE(board.sick()->stats().read_errors, 1u);  // not one error per cycle

  // The peer returns behind the same name: the board reopens it within its back-off, requests
  // continuous output again, and scans flow; the fault clears.
  ASSERT_TRUE(peer.open(link));
  bool requested = false;
  const auto deadline = Clock::now() + std::chrono::milliseconds(2 * Board::kSerialRetryMaxMs + 1000);
  while (!requested && Clock::now() < deadline) {
    run_cycles(&board, 20, &scans);
    requested = peer.got_request(10);
  }
  ASSERT_TRUE(requested) << "the board did not reopen the port";
  EXPECT_EQ(board.serial_reconnects(), 1u);
  EXPECT_EQ(source.fault_bits() & kDisconnected, 0u);
  ASSERT_TRUE(peer.send_scan(200));
  int after = 0;
  run_cycles(&board, 200, &after);
  EXPECT_EQ(after, 1);
  ::unlink(link.c_str());
  ::rmdir(dir);
}

TEST(BoardSerial, LaserSpecsOfTheSerialLasers) {
  SerialLaserSpec ls;
  ASSERT_TRUE(parse_serial_laser_spec("rplidar", "/dev/ttyUSB0@256000,express,pwm=660,beams=720", &ls).is_ok());
  EXPECT_STREQ(ls.device, "/dev/ttyUSB0");
  EXPECT_EQ(ls.baud, 256000u);
  EXPECT_STREQ(ls.mode, "express");
  EXPECT_EQ(ls.motor_pwm, 660);
  EXPECT_EQ(ls.beams, 720u);
  EXPECT_FALSE(parse_serial_laser_spec("rplidar", "/dev/ttyUSB0,beams=1082", &ls).is_ok());
  ASSERT_TRUE(parse_serial_laser_spec("hokuyo", "/dev/ttyACM0,intensity", &ls).is_ok());
  EXPECT_TRUE(ls.intensity);
  EXPECT_EQ(ls.baud, 115200u);  // the default of a Hokuyo (USB-ACM ignores it)
  ASSERT_TRUE(parse_serial_laser_spec("sick", "/dev/ttyS0", &ls).is_ok());
  EXPECT_EQ(ls.baud, 38400u);
  fw::Status s = parse_serial_laser_spec("hokuyo", "/dev/ttyACM0,express", &ls);
  ASSERT_FALSE(s.is_ok());
  EXPECT_NE(std::string(s.message()).find("option 'express' unknown"), std::string::npos) << s.message();
  EXPECT_FALSE(parse_serial_laser_spec("rplidar", "/dev/ttyUSB0@9x", &ls).is_ok());
}

// Issue 59: a device that is not the configured laser is a start-up error naming the port and what
// it answered (a SICK-like peer that says something else, a silent one).
TEST(BoardSerial, WrongDeviceIsAStartupErrorNamingPortAndAnswer) {
  char dir[] = "/tmp/mmlfw-board-serial.XXXXXX";
  ASSERT_NE(::mkdtemp(dir), nullptr);
  const std::string link = std::string(dir) + "/ttyLIDAR";
  {
    Peer peer;
    ASSERT_TRUE(peer.open(link));
    const char junk[] = "Welcome to the LD06\r\n";
    ASSERT_EQ(::write(peer.master, junk, sizeof(junk) - 1), static_cast<ssize_t>(sizeof(junk) - 1));
    static Board board;
    BoardSpec spec;
    const std::string laser = "hokuyo:" + link + "@115200";
    spec.laser = laser.c_str();
    spec.log_level = hal::LogLevel::kError;
    spec.laser_handshake_ms = 400;
    const fw::Status s = board.create(spec);
    ASSERT_FALSE(s.is_ok());
    const std::string m = s.message();
    EXPECT_NE(m.find(link), std::string::npos) << m;
    EXPECT_NE(m.find("no answer as a hokuyo within 400 ms"), std::string::npos) << m;
    EXPECT_NE(m.find("Welcome to the LD06"), std::string::npos) << m;
  }
  {
    Peer peer;
    ASSERT_TRUE(peer.open(link));
    static Board board;
    BoardSpec spec;
    const std::string laser = "rplidar:" + link;
    spec.laser = laser.c_str();
    spec.log_level = hal::LogLevel::kError;
    spec.laser_handshake_ms = 300;
    const fw::Status s = board.create(spec);
    ASSERT_FALSE(s.is_ok());
    const std::string m = s.message();
    EXPECT_NE(m.find(link), std::string::npos) << m;
    EXPECT_NE(m.find("waiting for the GET_HEALTH answer"), std::string::npos) << m;
    EXPECT_NE(m.find("nothing"), std::string::npos) << m;
  }
  ::rmdir(dir);
}

// laser_mount (issue 59): a laser turned 90° CCW on the robot and hanging upside down; the board
// hands the firmware the scan in the robot's orientation.
TEST(BoardSerial, MountTurnsAndMirrorsTheScan) {
  char dir[] = "/tmp/mmlfw-board-serial.XXXXXX";
  ASSERT_NE(::mkdtemp(dir), nullptr);
  const std::string link = std::string(dir) + "/ttyLASER";
  Peer peer;
  ASSERT_TRUE(peer.open(link));
  static Board board;
  BoardSpec spec;
  const std::string laser = "sick:" + link + "@38400";
  spec.laser = laser.c_str();
  spec.log_level = hal::LogLevel::kError;
  spec.laser_yaw_rad = 1.5707963f;
  spec.laser_upside_down = true;
  ASSERT_TRUE(board.create(spec).is_ok());
  ASSERT_TRUE(peer.got_request(1000));
  ASSERT_TRUE(peer.send_scan(100));  // 181 beams, 1°, from -90°: beam i reads 100 + i cm
  int scans = 0;
  hal::LaserScan scan;
  const auto end = Clock::now() + std::chrono::milliseconds(500);
  while (scans == 0 && Clock::now() < end) {
    board.wait_for_input(5);
    if (board.hal().laser->poll(&scan)) ++scans;
  }
  ASSERT_EQ(scans, 1);
  // Upside down the sensor's -90° beam (1.00 m) looks to +90°, its +90° beam (2.80 m) to -90°;
  // then the mount turns both by +90°: the scan runs from 0° to 180°, starting with 2.80 m.
  EXPECT_NEAR(scan.angle_min, 0.0f, 1e-5);
  EXPECT_NEAR(scan.ranges[0], 2.80f, 1e-4);
  EXPECT_NEAR(scan.ranges[180], 1.00f, 1e-4);
  EXPECT_NEAR(scan.angle_increment, 3.14159265f / 180.0f, 1e-6);
  ::unlink(link.c_str());
  ::rmdir(dir);
}

}  // namespace
}  // namespace hal_linux
