#include "sim/devices/sensor_transport.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <string>

#include "hal_sim/stepped_clock.h"

namespace sim {
namespace {

hal::LaserScan make_scan(std::uint32_t id, std::uint32_t beams, std::uint64_t t_ns) {
  hal::LaserScan s;
  s.scan_id = id;
  s.timestamp_ns = t_ns;
  s.beam_count = beams;
  s.angle_min = -1.5707963f;
  s.angle_increment = 3.14159265f / static_cast<float>(beams - 1);
  s.range_min = 0.02f;
  s.range_max = 8.0f;
  for (std::uint32_t i = 0; i < beams; ++i) s.ranges[i] = 0.5f + 0.01234567f * static_cast<float>(i % 300);
  s.ranges[3] = 9.5f;  // beyond range_max: "no return"
  return s;
}

hal::Odometry make_odom(std::uint64_t t_ns, float x) {
  hal::Odometry o;
  o.timestamp_ns = t_ns;
  o.x = x;
  o.y = -2.3456789f;
  o.theta = 0.7853981f;
  return o;
}

bool same_bytes(const hal::LaserScan& a, const hal::LaserScan& b) {
  return a.timestamp_ns == b.timestamp_ns && a.scan_id == b.scan_id && a.beam_count == b.beam_count &&
         std::memcmp(&a.angle_min, &b.angle_min, sizeof(float)) == 0 &&
         std::memcmp(&a.angle_increment, &b.angle_increment, sizeof(float)) == 0 &&
         std::memcmp(&a.range_min, &b.range_min, sizeof(float)) == 0 &&
         std::memcmp(&a.range_max, &b.range_max, sizeof(float)) == 0 &&
         std::memcmp(a.ranges, b.ranges, sizeof(float) * a.beam_count) == 0;
}

// Field by field: the struct's tail padding (28 bytes of fields in 32) is not part of the message,
// and a whole-struct memcmp compared it (uninitialised in the polled copy: failed under ASan).
bool same_bytes(const hal::Odometry& a, const hal::Odometry& b) {
  return a.timestamp_ns == b.timestamp_ns && std::memcmp(&a.x, &b.x, sizeof(float)) == 0 &&
         std::memcmp(&a.y, &b.y, sizeof(float)) == 0 && std::memcmp(&a.theta, &b.theta, sizeof(float)) == 0 &&
         std::memcmp(&a.v, &b.v, sizeof(float)) == 0 && std::memcmp(&a.omega, &b.omega, sizeof(float)) == 0;
}

TEST(WireResolution, IsTheCodecsRoundTripAndIdempotent) {
  auto scan = std::make_unique<hal::LaserScan>(make_scan(7, 361, 1'234'567'891ull));
  auto q = std::make_unique<hal::LaserScan>(*scan);
  to_wire_resolution(q.get());
  EXPECT_EQ(q->timestamp_ns, 1'234'567'000ull);  // µs on the wire
  EXPECT_EQ(q->scan_id, 7u);
  for (std::uint32_t i = 0; i < 361; ++i) {
    if (i == 3) {
      EXPECT_EQ(q->ranges[i], q->range_max);
    } else {
      EXPECT_NEAR(q->ranges[i], scan->ranges[i], 0.0005f + 1e-6f);  // 1 mm range unit
    }
  }
  auto qq = std::make_unique<hal::LaserScan>(*q);
  to_wire_resolution(qq.get());
  EXPECT_TRUE(same_bytes(*q, *qq));

  hal::Odometry o = make_odom(5'000'000'123ull, 12.3456789f);
  to_wire_resolution(&o);
  hal::Odometry oo = o;
  to_wire_resolution(&oo);
  EXPECT_TRUE(same_bytes(o, oo));
  EXPECT_NEAR(o.x, 12.3456789f, 0.0005f);
}

// The CAN path (encoder → hal/sim loopback bus → CanNode) delivers exactly what the direct path
// would: the wire-resolution messages, bit for bit, with their time stamps.
TEST(SensorTransport, CanPathDeliversTheWireResolutionMessagesUnchanged) {
  hal_sim::SteppedClock clock;
  auto t = std::make_unique<SensorTransport>();
  std::string err;
  TransportOptions opt;
  opt.transport = Transport::kCan;
  ASSERT_TRUE(t->init(opt, &clock, &err)) << err;
  auto got = std::make_unique<hal::LaserScan>();
  for (std::uint32_t k = 0; k < 70000; k += 997) {  // crosses the 16-bit scan id of the wire
    const std::uint64_t ts = 1'000'000'000ull + k * 100'000'000ull + 17;
    hal::Odometry o = make_odom(ts - 50'000'000, 0.01f * static_cast<float>(k));
    to_wire_resolution(&o);
    auto s = std::make_unique<hal::LaserScan>(make_scan(k, 181 + k % 900, ts));
    to_wire_resolution(s.get());
    clock.set_ns(ts);
    t->send_odometry(o);
    t->send_scan(*s);
    hal::Odometry go;
    ASSERT_TRUE(t->odometry().poll(&go));
    EXPECT_TRUE(same_bytes(go, o)) << "odometry " << k;
    ASSERT_TRUE(t->laser().poll(got.get()));
    EXPECT_TRUE(same_bytes(*got, *s)) << "scan " << k << ": id " << got->scan_id;
  }
  const TransportStats st = t->stats();
  EXPECT_EQ(st.decoder.scans_dropped, 0u);
  EXPECT_EQ(st.decoder.crc_errors, 0u);
  EXPECT_EQ(st.frames_dropped + st.frames_corrupted, 0u);
}

// One bit flipped in one range byte: the scan is dropped, counted as a CRC error, and the next
// scan arrives intact.
TEST(SensorTransport, OneCorruptedFrameIsACountedDropNotACrash) {
  hal_sim::SteppedClock clock;
  auto t = std::make_unique<SensorTransport>();
  std::string err;
  TransportOptions opt;
  opt.transport = Transport::kCan;
  opt.fault_frame = 10;  // a data segment of the first scan (4 start parts, then segments)
  ASSERT_TRUE(t->init(opt, &clock, &err)) << err;
  auto got = std::make_unique<hal::LaserScan>();
  for (std::uint32_t k = 0; k < 2; ++k) {
    auto s = std::make_unique<hal::LaserScan>(make_scan(k, 181, 1'000'000'000ull * (k + 1)));
    to_wire_resolution(s.get());
    t->send_scan(*s);
  }
  ASSERT_TRUE(t->laser().poll(got.get()));
  EXPECT_EQ(got->scan_id, 1u);
  EXPECT_FALSE(t->laser().poll(got.get()));
  const TransportStats st = t->stats();
  EXPECT_EQ(st.frames_corrupted, 1u);
  EXPECT_EQ(st.decoder.crc_errors, 1u);
  EXPECT_EQ(st.decoder.scans_dropped, 1u);
  EXPECT_EQ(st.decoder.scans_ok, 1u);
}

// Random byte faults at a high rate over many scans and odometry records: never a crash, every
// scan sent is either delivered or counted as dropped by the decoder.
TEST(SensorTransport, RandomByteFaultsAreCountedAndNeverCrash) {
  hal_sim::SteppedClock clock;
  auto t = std::make_unique<SensorTransport>();
  std::string err;
  TransportOptions opt;
  opt.transport = Transport::kCan;
  opt.byte_fault_rate = 0.02;
  opt.seed = 3;
  ASSERT_TRUE(t->init(opt, &clock, &err)) << err;
  auto got = std::make_unique<hal::LaserScan>();
  std::uint32_t delivered = 0;
  for (std::uint32_t k = 0; k < 300; ++k) {
    const std::uint64_t ts = 1'000'000'000ull + k * 100'000'000ull;
    clock.set_ns(ts);
    t->send_odometry(make_odom(ts, 0.1f * static_cast<float>(k)));
    t->send_scan(make_scan(k, 361, ts));
    while (t->laser().poll(got.get())) ++delivered;
    hal::Odometry o;
    while (t->odometry().poll(&o)) {
    }
  }
  const TransportStats st = t->stats();
  EXPECT_GT(st.frames_dropped + st.frames_corrupted, 100u);
  EXPECT_GT(st.decoder.scans_dropped, 50u);
  EXPECT_EQ(delivered, st.decoder.scans_ok);
  // A scan is lost whole or delivered whole; a START lost with its END leaves no trace but lost segments.
  EXPECT_LE(st.decoder.scans_ok + st.decoder.scans_dropped, 300u);
  EXPECT_GT(delivered, 0u);
  EXPECT_LT(delivered, 300u);
}

// The SICK path (telegram encoder → hal/sim serial port → SickLaser) delivers exactly the scan
// to_sick_resolution() gives the direct path, with the simulator's index; a telegram with one bit
// flipped is a CRC-16 error, counted, and the next scan arrives intact.
TEST(SensorTransport, SickPathDeliversTheSickResolutionScanAndCountsACorruptTelegram) {
  hal_sim::SteppedClock clock;
  auto t = std::make_unique<SensorTransport>();
  std::string err;
  TransportOptions opt;
  opt.transport = Transport::kSick;
  opt.fault_frame = 1;  // the second telegram
  ASSERT_TRUE(t->init(opt, &clock, &err)) << err;
  auto got = std::make_unique<hal::LaserScan>();
  std::uint32_t delivered = 0;
  for (std::uint32_t k = 0; k < 4; ++k) {
    const std::uint64_t ts = 1'000'000'000ull * (k + 1);
    auto s = std::make_unique<hal::LaserScan>(make_scan(100 + k, 361, ts));
    to_sick_resolution(s.get(), 3.14159265f);
    EXPECT_EQ(s->scan_id, 100 + k);
    EXPECT_EQ(s->timestamp_ns, ts);
    t->send_scan(*s);
    clock.set_ns(ts);  // the driver stamps at receipt: in lockstep, the sample time
    if (k == 1) {
      EXPECT_FALSE(t->laser().poll(got.get()));
      continue;
    }
    ASSERT_TRUE(t->laser().poll(got.get())) << k;
    EXPECT_TRUE(same_bytes(*got, *s)) << "scan " << k << ": id " << got->scan_id;
    ++delivered;
  }
  EXPECT_EQ(delivered, 3u);
  const TransportStats st = t->stats();
  EXPECT_EQ(st.frames_corrupted, 1u);
  EXPECT_EQ(st.sick_crc_errors, 1u);
  EXPECT_EQ(st.sick_scans, 3u);
}

// Issue 60: the Hokuyo path (a UTM-30LX's SCIP 2.0 answers → HokuyoLaser) runs the driver's
// start-up handshake against the simulated device at the first scan and delivers every scan with the
// simulator's index, in that unit's geometry (1081 steps of 0.25°), the ranges to the mm.
TEST(SensorTransport, HokuyoPathHandshakesAndDeliversEachScan) {
  hal_sim::SteppedClock clock;
  auto t = std::make_unique<SensorTransport>();
  std::string err;
  TransportOptions opt;
  opt.transport = Transport::kHokuyo;
  ASSERT_TRUE(t->init(opt, &clock, &err)) << err;
  auto got = std::make_unique<hal::LaserScan>();
  for (std::uint32_t k = 0; k < 4; ++k) {
    const std::uint64_t ts = 1'000'000'000ull + 25'000'000ull * k;
    auto s = std::make_unique<hal::LaserScan>(make_scan(100 + k, 361, ts));
    t->send_scan(*s);
    clock.set_ns(ts);
    ASSERT_TRUE(t->laser().poll(got.get())) << k << " " << t->stats().serial_handshake_error;
    EXPECT_EQ(got->scan_id, 100 + k);
    EXPECT_EQ(got->timestamp_ns, ts);  // whole ms: the sensor's counter maps back exactly
    ASSERT_EQ(got->beam_count, 1081u);
    EXPECT_NEAR(got->ranges[540], s->ranges[180], 0.0006f);  // straight ahead, in mm
  }
  EXPECT_EQ(t->stats().serial.scans, 4u);
  EXPECT_TRUE(t->stats().serial_handshake_error.empty());
}

// The RPLIDAR path (an A1's SCAN samples, one turn per scan → RplidarLaser): a turn reaches the
// firmware when the next begins, stamped with its own time and index, resampled onto 360 beams.
TEST(SensorTransport, RplidarPathDeliversEachTurnOneScanLater) {
  hal_sim::SteppedClock clock;
  auto t = std::make_unique<SensorTransport>();
  std::string err;
  TransportOptions opt;
  opt.transport = Transport::kRplidar;
  ASSERT_TRUE(t->init(opt, &clock, &err)) << err;
  auto got = std::make_unique<hal::LaserScan>();
  for (std::uint32_t k = 0; k < 4; ++k) {
    const std::uint64_t ts = 1'000'000'000ull + 181'818'000ull * k;
    t->send_scan(make_scan(100 + k, 361, ts));
    clock.set_ns(ts);
    const bool delivered = t->laser().poll(got.get());
    EXPECT_EQ(delivered, k > 0) << k;
    if (!delivered) continue;
    EXPECT_EQ(got->scan_id, 100 + k - 1);
    EXPECT_EQ(got->timestamp_ns, ts - 181'818'000ull);
    EXPECT_EQ(got->beam_count, 360u);
  }
  EXPECT_EQ(t->stats().serial.scans, 3u);
}

TEST(SensorTransport, BadOptionsAreRefused) {
  hal_sim::SteppedClock clock;
  auto t = std::make_unique<SensorTransport>();
  std::string err;
  TransportOptions opt;
  opt.byte_fault_rate = 0.1;  // transport none has no bytes
  EXPECT_FALSE(t->init(opt, &clock, &err));
  EXPECT_NE(err.find("--transport can"), std::string::npos) << err;
  opt.transport = Transport::kCan;
  opt.byte_fault_rate = 1.5;
  EXPECT_FALSE(t->init(opt, &clock, &err));
  opt.byte_fault_rate = 0;
  opt.resolution = SensorResolution::kCan;  // sick carries its own wire's values
  opt.transport = Transport::kSick;
  EXPECT_FALSE(t->init(opt, &clock, &err));
  opt.resolution = SensorResolution::kAuto;
  opt.laser_model = "urg-04lx";  // a Hokuyo, not an RPLIDAR
  opt.transport = Transport::kRplidar;
  EXPECT_FALSE(t->init(opt, &clock, &err));
  EXPECT_NE(err.find("a1, a2, a3, s1"), std::string::npos) << err;
  opt.transport = Transport::kSick;  // a SICK plays no model
  EXPECT_FALSE(t->init(opt, &clock, &err));
  opt.transport = Transport::kHokuyo;
  EXPECT_TRUE(t->init(opt, &clock, &err)) << err;
  Transport tr;
  EXPECT_TRUE(parse_transport("can", &tr));
  EXPECT_EQ(tr, Transport::kCan);
  EXPECT_TRUE(parse_transport("sick", &tr));
  EXPECT_TRUE(parse_transport("hokuyo", &tr));
  EXPECT_EQ(tr, Transport::kHokuyo);
  EXPECT_TRUE(parse_transport("rplidar", &tr));
  EXPECT_EQ(tr, Transport::kRplidar);
  EXPECT_FALSE(parse_transport("serial", &tr));
}

}  // namespace
}  // namespace sim
