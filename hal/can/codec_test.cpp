#include "hal_can/codec.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <deque>
#include <limits>
#include <random>
#include <vector>

#include "hal_can/can_node.h"

namespace hal_can {
namespace {

hal::LaserScan make_scan(std::uint32_t id, std::uint32_t beams) {
  hal::LaserScan s;
  s.scan_id = id;
  s.beam_count = beams;
  s.timestamp_ns = 1234567890123000ull + id * 13333000ull;
  s.angle_min = -1.5707963f;
  // 1° steps, or a 270° field of view for more than 361 beams (1081 = 0.25°): the codec refuses a
  // field of view beyond 2π.
  s.angle_increment = beams > 361 ? 4.71238898f / static_cast<float>(beams - 1) : 0.017453292f;
  s.range_min = 0.0f;
  s.range_max = 81.91f;
  for (std::uint32_t i = 0; i < beams; ++i) s.ranges[i] = 0.5f + 0.037f * static_cast<float>((i * 7 + id) % 300);
  s.ranges[beams / 2] = 81.91f;             // max reading: "no return"
  s.ranges[beams / 3] = std::nanf("");      // NaN: "no return"
  return s;
}

std::vector<hal::CanFrame> encode(const hal::LaserScan& s, bool fd) {
  std::vector<hal::CanFrame> f(kMaxScanFrames);
  std::size_t n = 0;
  EncodeOptions o;
  o.fd = fd;
  EXPECT_TRUE(encode_scan(s, o, f.data(), f.size(), &n).is_ok());
  f.resize(n);
  return f;
}

void expect_scan_eq(const hal::LaserScan& in, const hal::LaserScan& out) {
  EXPECT_EQ(out.scan_id, in.scan_id);
  EXPECT_EQ(out.beam_count, in.beam_count);
  EXPECT_EQ(out.timestamp_ns, in.timestamp_ns);
  EXPECT_NEAR(out.angle_min, in.angle_min, 1e-6);
  EXPECT_NEAR(out.angle_increment, in.angle_increment, 1e-7);
  EXPECT_NEAR(out.range_max, in.range_max, 0.01);
  for (std::uint32_t i = 0; i < in.beam_count; ++i) {
    if (std::isfinite(in.ranges[i]) && in.ranges[i] < in.range_max) {
      EXPECT_NEAR(out.ranges[i], in.ranges[i], 0.0011) << i;
    } else {
      EXPECT_EQ(out.ranges[i], out.range_max) << i;
    }
  }
}

TEST(Crc32, CheckValue) {
  const char* s = "123456789";
  EXPECT_EQ(crc32(reinterpret_cast<const std::uint8_t*>(s), 9), 0xCBF43926u);
}

TEST(FdLength, ValidLengths) {
  EXPECT_EQ(fd_length_for(8), 8);
  EXPECT_EQ(fd_length_for(9), 12);
  EXPECT_EQ(fd_length_for(29), 32);
  EXPECT_EQ(fd_length_for(36), 48);
  EXPECT_EQ(fd_length_for(64), 64);
}

TEST(ScanCodec, RoundTripClassicAndFd) {
  for (bool fd : {false, true}) {
    for (std::uint32_t beams : {1u, 3u, 180u, 181u, 361u, 1081u}) {
      hal::LaserScan s = make_scan(17, beams);
      auto frames = encode(s, fd);
      ASSERT_EQ(frames.size(), scan_frame_count(beams, fd));
      for (const auto& f : frames) {
        EXPECT_LE(f.len, fd ? 64 : 8);
        if (!fd) EXPECT_FALSE(f.fd);
      }
      Decoder d;
      int scans = 0;
      for (const auto& f : frames) scans += d.feed(f) == Decoded::kScan;
      ASSERT_EQ(scans, 1) << "fd=" << fd << " beams=" << beams;
      expect_scan_eq(s, d.scan());
      EXPECT_EQ(d.stats().scans_ok, 1u);
      EXPECT_EQ(d.stats().scans_dropped, 0u);
    }
  }
  // FD is what makes 75 Hz scans cheap: 180 beams = 65 classic frames vs 8 FD frames.
  EXPECT_EQ(scan_frame_count(180, false), 65u);
  EXPECT_EQ(scan_frame_count(180, true), 8u);
}

TEST(ScanCodec, RejectsBadInput) {
  hal::LaserScan s = make_scan(1, 180);
  std::vector<hal::CanFrame> f(kMaxScanFrames);
  std::size_t n = 0;
  s.beam_count = 0;
  EXPECT_FALSE(encode_scan(s, {}, f.data(), f.size(), &n).is_ok());
  s.beam_count = 180;
  EXPECT_FALSE(encode_scan(s, {}, f.data(), 10, &n).is_ok());  // buffer too small
  s.range_max = std::nanf("");
  fw::Status st = encode_scan(s, {}, f.data(), f.size(), &n);
  EXPECT_FALSE(st.is_ok());
  EXPECT_NE(std::strstr(st.message(), "scan 1"), nullptr) << st.message();
}

// A scan transfer built field by field (not by encode_scan, which refuses impossible geometry),
// with a correct CRC: what a buggy or hostile sender can put on the bus.
struct RawScan {
  std::uint16_t scan_id = 3, unit_um = 50000, range_max_cm = 1, range_min_cm = 65500;
  std::int32_t angle_min_urad = -1570796, increment_01urad = 0;
  std::vector<std::uint16_t> codes = std::vector<std::uint16_t>(30, 60000);  // 60000 · 50 mm = 3000 m
};
std::vector<hal::CanFrame> raw_scan_frames(const RawScan& r) {
  std::uint8_t start[kScanStartParts * kPartBytes] = {};
  put_u16(start + 0, r.scan_id);
  put_u16(start + 2, static_cast<std::uint16_t>(r.codes.size()));
  put_u16(start + 4, r.unit_um);
  put_u32(start + 7, static_cast<std::uint32_t>(r.angle_min_urad));
  put_u16(start + 11, r.range_max_cm);
  put_u32(start + 14, static_cast<std::uint32_t>(r.increment_01urad));
  put_u16(start + 18, r.range_min_cm);
  put_u48(start + 21, 1000000);
  std::vector<hal::CanFrame> out;
  for (std::size_t k = 0; k < kScanStartParts; ++k) {
    hal::CanFrame f;
    f.id = kScanStartId + static_cast<std::uint32_t>(k);
    f.len = 8;
    f.data[0] = static_cast<std::uint8_t>(r.scan_id);
    std::memcpy(f.data + 1, start + k * kPartBytes, kPartBytes);
    out.push_back(f);
  }
  std::uint32_t crc = crc32_update(crc32_begin(), start, sizeof(start));
  std::uint16_t seg = 0;
  for (std::size_t b = 0; b < r.codes.size(); b += kClassicRangesPerSegment, ++seg) {
    hal::CanFrame f;
    f.id = kScanDataId;
    put_u16(f.data, static_cast<std::uint16_t>(seg | ((r.scan_id & 0xF) << 12)));
    const std::size_t nb = std::min(kClassicRangesPerSegment, r.codes.size() - b);
    for (std::size_t i = 0; i < nb; ++i) put_u16(f.data + 2 + 2 * i, r.codes[b + i]);
    crc = crc32_update(crc, f.data + 2, 2 * nb);
    f.len = static_cast<std::uint8_t>(2 + 2 * nb);
    out.push_back(f);
  }
  hal::CanFrame e;
  e.id = kScanEndId;
  e.len = 8;
  put_u16(e.data, r.scan_id);
  put_u16(e.data + 2, seg);
  put_u32(e.data + 4, crc32_end(crc));
  out.push_back(e);
  return out;
}

// Issue 13: a CRC-correct scan with range_max 0.01 m, range_min 655 m, angle increment 0 and
// readings of 3000 m was delivered as valid.
TEST(ScanCodec, CrcCorrectScanWithImpossibleGeometryIsANamedDecodeError) {
  Decoder d;
  const RawScan reproducer;
  for (const auto& f : raw_scan_frames(reproducer)) EXPECT_NE(d.feed(f), Decoded::kScan);
  EXPECT_EQ(d.stats().crc_errors, 0u);
  EXPECT_EQ(d.stats().scans_ok, 0u);
  EXPECT_EQ(d.stats().invalid_scans, 1u);
  EXPECT_EQ(d.stats().scans_dropped, 1u);
  EXPECT_EQ(d.stats().last_defect, ScanDefect::kRangeMax);
  EXPECT_STREQ(scan_defect_name(d.stats().last_defect), "range_max not in [0.1, 250] m");

  // Each defect on its own (everything else sane: 30 beams of 1 deg, 1 mm unit, 30 m max).
  RawScan sane;
  sane.unit_um = 1000;
  sane.range_max_cm = 3000;
  sane.range_min_cm = 2;
  sane.increment_01urad = 174533;
  sane.codes.assign(30, 4000);  // 4 m
  struct Case {
    ScanDefect defect;
    void (*spoil)(RawScan*);
  } cases[] = {
      {ScanDefect::kRangeMax, [](RawScan* r) { r->range_max_cm = 0; }},
      {ScanDefect::kRangeMax, [](RawScan* r) { r->range_max_cm = 60000; r->unit_um = 10000; }},  // 600 m
      {ScanDefect::kRangeMin, [](RawScan* r) { r->range_min_cm = 3000; }},
      {ScanDefect::kAngleIncrement, [](RawScan* r) { r->increment_01urad = 0; }},
      {ScanDefect::kAngleIncrement, [](RawScan* r) { r->increment_01urad = 70000000; }},  // 7 rad
      {ScanDefect::kFieldOfView, [](RawScan* r) { r->increment_01urad = 3000000; }},     // 29 × 0.3 rad
      {ScanDefect::kAngleMin, [](RawScan* r) { r->angle_min_urad = 100000000; }},        // 100 rad
      {ScanDefect::kRangeBeyondMax, [](RawScan* r) { r->codes[7] = 60000; }},            // 60 m > 30 m
  };
  std::uint32_t expected = 1;
  for (const Case& c : cases) {
    RawScan r = sane;
    c.spoil(&r);
    ++r.scan_id;
    for (const auto& f : raw_scan_frames(r)) EXPECT_NE(d.feed(f), Decoded::kScan) << scan_defect_name(c.defect);
    ++expected;
    EXPECT_EQ(d.stats().invalid_scans, expected) << scan_defect_name(c.defect);
    EXPECT_EQ(d.stats().last_defect, c.defect) << scan_defect_name(d.stats().last_defect);
  }
  EXPECT_EQ(d.stats().invalid_by_defect[static_cast<int>(ScanDefect::kRangeMax)], 3u);
  // The sane scan itself (and a clockwise one) decode; "no return" codes are not readings.
  RawScan ok = sane;
  ok.codes[3] = kNoReturn;
  for (const auto& f : raw_scan_frames(ok)) d.feed(f);
  ok.increment_01urad = -174533;
  ++ok.scan_id;
  bool got = false;
  for (const auto& f : raw_scan_frames(ok)) got = d.feed(f) == Decoded::kScan || got;
  EXPECT_TRUE(got);
  EXPECT_EQ(d.stats().scans_ok, 2u);
  EXPECT_EQ(d.stats().crc_errors, 0u);

  // The encoder refuses to produce such a scan.
  hal::LaserScan bad = make_scan(9, 30);
  bad.angle_increment = 0.0f;
  std::vector<hal::CanFrame> frames(kMaxScanFrames);
  std::size_t n = 0;
  const fw::Status st = encode_scan(bad, {}, frames.data(), frames.size(), &n);
  EXPECT_FALSE(st.is_ok());
  EXPECT_NE(std::strstr(st.message(), "angle increment"), nullptr) << st.message();
}

TEST(ScanCodec, CorruptSegmentIsCrcError) {
  hal::LaserScan s = make_scan(5, 180);
  auto frames = encode(s, false);
  frames[10].data[3] ^= 0x40;
  Decoder d;
  for (const auto& f : frames) EXPECT_NE(d.feed(f), Decoded::kScan);
  EXPECT_EQ(d.stats().crc_errors, 1u);
  EXPECT_EQ(d.stats().scans_dropped, 1u);
  // The next scan is fine again.
  for (const auto& f : encode(make_scan(6, 180), false)) d.feed(f);
  EXPECT_EQ(d.stats().scans_ok, 1u);
}

TEST(ScanCodec, MissingDuplicateOutOfOrderDropTheScan) {
  Decoder d;
  auto a = encode(make_scan(1, 180), true);
  a.erase(a.begin() + 3);  // missing segment
  auto b = encode(make_scan(2, 180), true);
  b.insert(b.begin() + 3, b[3]);  // duplicated segment
  auto c = encode(make_scan(3, 180), true);
  std::swap(c[2], c[3]);  // out of order
  auto e = encode(make_scan(4, 180), true);
  for (auto* v : {&a, &b, &c, &e})
    for (const auto& f : *v) d.feed(f);
  EXPECT_EQ(d.stats().scans_ok, 1u);
  EXPECT_EQ(d.stats().scans_dropped, 3u);
  EXPECT_EQ(d.stats().duplicate_segments, 1u);
  EXPECT_GE(d.stats().lost_segments, 2u);
  EXPECT_EQ(d.scan().scan_id, 4u);
}

TEST(ScanCodec, MissingStartOrEndIsCounted) {
  Decoder d;
  auto a = encode(make_scan(1, 180), false);
  a.erase(a.begin());  // start part 0 lost → the whole start record is broken
  auto b = encode(make_scan(2, 180), false);
  b.pop_back();  // END lost → dropped when the next START arrives
  auto c = encode(make_scan(3, 180), false);
  for (auto* v : {&a, &b, &c})
    for (const auto& f : *v) d.feed(f);
  EXPECT_EQ(d.stats().scans_ok, 1u);
  EXPECT_EQ(d.stats().scans_dropped, 2u);
  EXPECT_GE(d.stats().broken_records, 1u);
}

TEST(ScanCodec, TimeoutDropsStalledTransfer) {
  Decoder::Options o;
  o.scan_timeout_ns = 100'000'000;
  Decoder d(o);
  auto a = encode(make_scan(1, 180), false);
  for (std::size_t i = 0; i < 20; ++i) {
    a[i].timestamp_ns = 1'000'000'000;
    d.feed(a[i]);
  }
  d.check_timeout(1'200'000'000);
  EXPECT_EQ(d.stats().timeouts, 1u);
  EXPECT_EQ(d.stats().scans_dropped, 1u);
}

TEST(ScanCodec, RandomGarbageNeverCrashesAndNeverDeliversWrongScans) {
  std::mt19937 rng(42);
  Decoder d;
  std::uint32_t delivered = 0;
  for (int round = 0; round < 200; ++round) {
    auto frames = encode(make_scan(static_cast<std::uint32_t>(round), 180), round % 2 == 0);
    const int mode = round % 4;
    if (mode == 1) {  // flip random bits in one frame
      auto& f = frames[rng() % frames.size()];
      f.data[rng() % (f.len ? f.len : 1)] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
    } else if (mode == 2) {  // truncate a frame
      frames[rng() % frames.size()].len = static_cast<std::uint8_t>(rng() % 3);
    } else if (mode == 3) {  // inject a random frame
      hal::CanFrame g;
      g.id = 0x100 + rng() % 0x40;
      g.len = 8;
      for (int i = 0; i < 8; ++i) g.data[i] = static_cast<std::uint8_t>(rng());
      frames.insert(frames.begin() + static_cast<long>(rng() % frames.size()), g);
    }
    for (const auto& f : frames) {
      if (d.feed(f) == Decoded::kScan) {
        ++delivered;
        // A delivered scan must be exactly the scan that was sent.
        expect_scan_eq(make_scan(d.scan().scan_id, 180), d.scan());
      }
    }
  }
  EXPECT_GE(delivered, 50u);  // every untouched scan (mode 0) at least
  EXPECT_EQ(delivered + d.stats().scans_dropped, 200u);
}

TEST(RecordCodec, OdometryPoseHealthRoundTrip) {
  for (bool fd : {false, true}) {
    Decoder d;
    hal::CanFrame f[kMaxParts];
    std::size_t n = 0;
    hal::Odometry o;
    o.timestamp_ns = 2691287460000000ull;  // 2691 s (u48 µs: monotonic sender clock)
    o.x = -12.345f;
    o.y = 101.5f;
    o.theta = -3.1f;
    o.v = 0.5f;
    o.omega = -0.25f;
    ASSERT_TRUE(encode_odometry(o, 9, fd, f, kMaxParts, &n).is_ok());
    EXPECT_EQ(n, fd ? 1u : kOdomParts);
    Decoded last = Decoded::kNothing;
    for (std::size_t i = 0; i < n; ++i) last = d.feed(f[i]);
    ASSERT_EQ(last, Decoded::kOdometry);
    EXPECT_NEAR(d.odometry().x, o.x, 1e-3);
    EXPECT_NEAR(d.odometry().y, o.y, 1e-3);
    EXPECT_NEAR(d.odometry().theta, o.theta, 1e-6);
    EXPECT_NEAR(d.odometry().v, o.v, 1e-3);
    EXPECT_EQ(d.odometry().timestamp_ns, o.timestamp_ns);

    hal::PoseEstimate p;
    p.timestamp_ns = 42'000'000;
    p.scan_id = 77;
    p.x = 3.25f;
    p.y = -4.5f;
    p.theta = 1.0f;
    p.cov[0] = 0.01f;
    p.cov[4] = 0.04f;
    p.cov[8] = 0.0001f;
    p.status = hal::LocalizationStatus::kLocalized;
    p.mode = hal::LocalizationMode::kTracking;
    p.hypothesis_count = 300;
    p.cluster_count = 2;
    p.rating = 0.5f;
    ASSERT_TRUE(encode_pose(p, 3, fd, f, kMaxParts, &n).is_ok());
    for (std::size_t i = 0; i < n; ++i) last = d.feed(f[i]);
    ASSERT_EQ(last, Decoded::kPose);
    EXPECT_EQ(d.pose().scan_id, 77u);
    EXPECT_EQ(d.pose().status, hal::LocalizationStatus::kLocalized);
    EXPECT_EQ(d.pose().mode, hal::LocalizationMode::kTracking);
    EXPECT_NEAR(d.pose().x, 3.25, 1e-3);
    EXPECT_NEAR(d.pose().y, -4.5, 1e-3);
    EXPECT_NEAR(d.pose().cov[4], 0.04, 1e-4);
    EXPECT_EQ(d.pose().hypothesis_count, 300);
    EXPECT_EQ(d.pose().timestamp_ns, 42'000'000u);
    // Defaults: no protection bound, confirmed by this scan.
    EXPECT_EQ(d.pose().protection_xy_m, 0.0f);
    EXPECT_EQ(d.pose().protection_theta_rad, 0.0f);
    EXPECT_EQ(d.pose().unsupported_steps, 0);

    HealthRecord h;
    h.uptime_ms = 123456;
    h.crc_errors = 3;
    h.lost_segments = 7;
    h.bus_off = 1;
    h.error_frames = 5;
    h.scans_processed = 1000;
    h.fault_bits = 0x10;
    h.state = 2;
    ASSERT_TRUE(encode_health(h, 1, fd, f, kMaxParts, &n).is_ok());
    for (std::size_t i = 0; i < n; ++i) last = d.feed(f[i]);
    ASSERT_EQ(last, Decoded::kHealth);
    EXPECT_EQ(d.health().uptime_ms, 123456u);
    EXPECT_EQ(d.health().lost_segments, 7);
    EXPECT_EQ(d.health().error_frames, 5);
    EXPECT_EQ(d.health().fault_bits, 0x10u);
    EXPECT_EQ(d.health().scans_processed, 1000u);
  }
}

hal::PoseEstimate pose_with_protection(float xy, float theta, std::uint16_t unsupported) {
  hal::PoseEstimate p;
  p.timestamp_ns = 7'000'000;
  p.scan_id = 901;
  p.x = 1.5f;
  p.status = hal::LocalizationStatus::kLocalized;
  p.protection_xy_m = xy;
  p.protection_theta_rad = theta;
  p.unsupported_steps = unsupported;
  return p;
}

// Encodes and decodes one pose; fails the test if the decoder does not deliver it.
hal::PoseEstimate round_trip(const hal::PoseEstimate& p, bool fd, std::size_t* frames = nullptr) {
  hal::CanFrame f[kMaxParts];
  std::size_t n = 0;
  EXPECT_TRUE(encode_pose(p, 11, fd, f, kMaxParts, &n).is_ok());
  if (frames) *frames = n;
  Decoder d;
  Decoded last = Decoded::kNothing;
  for (std::size_t i = 0; i < n; ++i) last = d.feed(f[i]);
  EXPECT_EQ(last, Decoded::kPose);
  EXPECT_EQ(d.stats().malformed + d.stats().broken_records + d.stats().unknown_ids, 0u);
  return d.pose();
}

TEST(PoseProtection, RoundTripClassicAndFd) {
  for (bool fd : {false, true}) {
    std::size_t n = 0;
    const hal::PoseEstimate got = round_trip(pose_with_protection(0.75f, 0.0523f, 17), fd, &n);
    EXPECT_EQ(n, fd ? 1u : 6u);  // classic: parts 0x120..0x125
    EXPECT_NEAR(got.protection_xy_m, 0.75, 1e-6);
    EXPECT_NEAR(got.protection_theta_rad, 0.0523, 1e-6);
    EXPECT_EQ(got.unsupported_steps, 17);
    EXPECT_EQ(got.scan_id, 901u);
    EXPECT_NEAR(got.x, 1.5, 1e-3);
    EXPECT_EQ(round_trip(pose_with_protection(1.0f, 0.1f, 65535), fd).unsupported_steps, 65535);
  }
  hal::CanFrame f[kMaxParts];
  std::size_t n = 0;
  ASSERT_TRUE(encode_pose(pose_with_protection(1, 1, 1), 0, true, f, kMaxParts, &n).is_ok());
  EXPECT_EQ(f[0].len, 48);  // 1 + 42 bytes: the FD frame length did not change
  ASSERT_TRUE(encode_pose(pose_with_protection(1, 1, 1), 0, false, f, kMaxParts, &n).is_ok());
  EXPECT_EQ(f[5].id, 0x125u);
  EXPECT_EQ(f[5].len, 8);
}

TEST(PoseProtection, RoundsUpNeverDown) {
  // The published bound must hold: it may grow by less than one LSB, never shrink.
  for (float xy : {0.0004f, 0.0011f, 0.1f, 0.2345f, 1.0f, 12.3456f, 65.0f}) {
    const float got = round_trip(pose_with_protection(xy, 0.0f, 0), false).protection_xy_m;
    EXPECT_GE(got, xy * (1 - 1e-6f)) << xy;
    EXPECT_LT(got, xy + 0.001f) << xy;
  }
  for (float th : {0.00001f, 0.01f, 0.017453292f, 0.5f, 3.1415927f, 6.5f}) {
    const float got = round_trip(pose_with_protection(0.0f, th, 0), true).protection_theta_rad;
    EXPECT_GE(got, th * (1 - 1e-6f)) << th;
    EXPECT_LT(got, th + 1e-4f) << th;
  }
  // Exact decimal inputs keep their code (float noise does not add an LSB).
  EXPECT_EQ(protection_code(0.1f, kProtectionXyPerMetre), 100);
  EXPECT_EQ(protection_code(0.3f, kProtectionXyPerMetre), 300);
  EXPECT_EQ(protection_code(0.0523f, kProtectionThetaPerRad), 523);
  EXPECT_EQ(protection_code(0.0001f, kProtectionXyPerMetre), 1);  // tiny bound: 1 LSB, not "no bound"
  EXPECT_EQ(protection_code(0.1001f, kProtectionXyPerMetre), 101);
}

TEST(PoseProtection, HugeValuesSaturateAndDecodeAsNoFiniteBound) {
  const float inf = std::numeric_limits<float>::infinity();
  for (bool fd : {false, true}) {
    for (float xy : {65.535f, 70.0f, 1e6f, 3e38f, inf}) {
      EXPECT_EQ(protection_code(xy, kProtectionXyPerMetre), kProtectionSaturated) << xy;
      EXPECT_EQ(round_trip(pose_with_protection(xy, 0.1f, 0), fd).protection_xy_m, inf) << xy;
    }
    for (float th : {6.6f, 100.0f, 3e38f, inf}) {
      EXPECT_EQ(protection_code(th, kProtectionThetaPerRad), kProtectionSaturated) << th;
      EXPECT_EQ(round_trip(pose_with_protection(0.5f, th, 0), fd).protection_theta_rad, inf) << th;
    }
  }
  // Just below saturation stays a finite bound: 65.534 m and 6.5534 rad are the largest.
  EXPECT_EQ(protection_code(65.534f, kProtectionXyPerMetre), 65534);
  EXPECT_NEAR(protection_value(65534, kProtectionXyPerMetre), 65.534, 1e-4);
  EXPECT_EQ(protection_code(6.5534f, kProtectionThetaPerRad), 65534);
}

TEST(PoseProtection, ZeroNanAndNegativeMeanNoBound) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  for (bool fd : {false, true}) {
    for (float bad : {0.0f, -0.0f, -1.0f, -1e30f, -inf, nan}) {
      const hal::PoseEstimate got = round_trip(pose_with_protection(bad, bad, 3), fd);
      EXPECT_EQ(got.protection_xy_m, 0.0f) << bad;
      EXPECT_EQ(got.protection_theta_rad, 0.0f) << bad;
      EXPECT_EQ(got.unsupported_steps, 3);
    }
  }
  EXPECT_EQ(protection_code(nan, kProtectionXyPerMetre), 0);
  EXPECT_EQ(protection_value(0, kProtectionXyPerMetre), 0.0f);
}

TEST(PoseProtection, DecodesLayoutZeroSenders) {
  // A sender from before protection levels: 5 classic parts with byte 34 (frame 0x124, byte 7)
  // = 0, or a 48-byte FD frame with zero padding. Both decode, with "no bound".
  for (bool fd : {false, true}) {
    hal::CanFrame f[kMaxParts];
    std::size_t n = 0;
    ASSERT_TRUE(encode_pose(pose_with_protection(0.5f, 0.05f, 9), 4, fd, f, kMaxParts, &n).is_ok());
    if (fd) {
      f[0].data[1 + kPoseLayoutOffset] = 0;
      for (std::size_t i = 1 + kPoseLegacyParts * kPartBytes; i < f[0].len; ++i) f[0].data[i] = 0;
    } else {
      f[4].data[7] = 0;
      n = kPoseLegacyParts;
    }
    Decoder d;
    // A layout-1 pose first, so stale bytes of a previous record cannot leak into the old one.
    hal::CanFrame g[kMaxParts];
    std::size_t m = 0;
    ASSERT_TRUE(encode_pose(pose_with_protection(2.0f, 0.2f, 5), 3, fd, g, kMaxParts, &m).is_ok());
    for (std::size_t i = 0; i < m; ++i) d.feed(g[i]);
    ASSERT_EQ(d.pose().unsupported_steps, 5);
    Decoded last = Decoded::kNothing;
    for (std::size_t i = 0; i < n; ++i) last = d.feed(f[i]);
    ASSERT_EQ(last, Decoded::kPose) << "fd=" << fd;
    EXPECT_EQ(d.pose().scan_id, 901u);
    EXPECT_EQ(d.pose().protection_xy_m, 0.0f);
    EXPECT_EQ(d.pose().protection_theta_rad, 0.0f);
    EXPECT_EQ(d.pose().unsupported_steps, 0);
    EXPECT_EQ(d.stats().poses_ok, 2u);
    EXPECT_EQ(d.stats().broken_records, 0u);
  }
}

TEST(PoseReason, RoundTripsOlderLayoutsReadNoneAndAnUnknownReasonIsMalformed) {
  for (bool fd : {false, true}) {
    hal::PoseEstimate p = pose_with_protection(0.3f, 0.02f, 4);
    p.status = hal::LocalizationStatus::kAmbiguous;
    for (std::uint8_t r = 0; r < hal::kStatusReasonCount; ++r) {
      p.reason = static_cast<hal::StatusReason>(r);
      EXPECT_EQ(round_trip(p, fd).reason, p.reason) << "fd=" << fd << " reason " << int(r);
    }
    // The reason byte and the layout byte in the frames (payload offsets 41 and 34).
    auto reason_byte = [fd](hal::CanFrame* f) -> std::uint8_t& {
      return fd ? f[0].data[1 + kPoseReasonOffset] : f[5].data[1 + (kPoseReasonOffset - 5 * kPartBytes)];
    };
    auto layout_byte = [fd](hal::CanFrame* f) -> std::uint8_t& {
      return fd ? f[0].data[1 + kPoseLayoutOffset] : f[4].data[1 + (kPoseLayoutOffset - 4 * kPartBytes)];
    };
    hal::CanFrame f[kMaxParts];
    std::size_t n = 0;
    p.reason = hal::StatusReason::kTrackAlias;
    ASSERT_TRUE(encode_pose(p, 2, fd, f, kMaxParts, &n).is_ok());
    ASSERT_EQ(reason_byte(f), static_cast<std::uint8_t>(hal::StatusReason::kTrackAlias));
    ASSERT_EQ(layout_byte(f), kPoseLayout);
    // A layout-1 sender: byte 41 was reserved (0) and is not read as a reason.
    layout_byte(f) = 1;
    reason_byte(f) = 0;
    {
      Decoder d;
      Decoded last = Decoded::kNothing;
      for (std::size_t i = 0; i < n; ++i) last = d.feed(f[i]);
      ASSERT_EQ(last, Decoded::kPose);
      EXPECT_EQ(d.pose().reason, hal::StatusReason::kNone);
      EXPECT_EQ(d.pose().unsupported_steps, 4);
    }
    // Layout 2 with a reason the receiver does not know: malformed, never delivered as something else.
    layout_byte(f) = kPoseLayout;
    reason_byte(f) = hal::kStatusReasonCount;
    {
      Decoder d;
      Decoded last = Decoded::kNothing;
      for (std::size_t i = 0; i < n; ++i) last = d.feed(f[i]);
      EXPECT_EQ(last, Decoded::kNothing);
      EXPECT_EQ(d.stats().malformed, 1u);
      EXPECT_EQ(d.stats().poses_ok, 0u);
    }
  }
}

TEST(PoseProtection, MissingProtectionPartDropsThePose) {
  // Layout 1 announces part 5: without it the pose is not delivered (and never delivered with
  // a made-up bound); the next complete pose is fine again.
  Decoder d;
  hal::CanFrame f[kMaxParts];
  std::size_t n = 0;
  ASSERT_TRUE(encode_pose(pose_with_protection(0.5f, 0.05f, 9), 1, false, f, kMaxParts, &n).is_ok());
  for (std::size_t i = 0; i + 1 < n; ++i) EXPECT_EQ(d.feed(f[i]), Decoded::kNothing);
  ASSERT_TRUE(encode_pose(pose_with_protection(0.25f, 0.05f, 2), 2, false, f, kMaxParts, &n).is_ok());
  Decoded last = Decoded::kNothing;
  for (std::size_t i = 0; i < n; ++i) last = d.feed(f[i]);
  ASSERT_EQ(last, Decoded::kPose);
  EXPECT_NEAR(d.pose().protection_xy_m, 0.25, 1e-6);
  EXPECT_EQ(d.stats().poses_ok, 1u);
  EXPECT_EQ(d.stats().broken_records, 1u);
  // Part 5 of another record (wrong tag) is not accepted either.
  hal::CanFrame g[kMaxParts];
  ASSERT_TRUE(encode_pose(pose_with_protection(9.0f, 0.05f, 2), 7, false, g, kMaxParts, &n).is_ok());
  ASSERT_TRUE(encode_pose(pose_with_protection(0.5f, 0.05f, 2), 8, false, f, kMaxParts, &n).is_ok());
  for (std::size_t i = 0; i + 1 < n; ++i) d.feed(f[i]);
  EXPECT_EQ(d.feed(g[5]), Decoded::kNothing);
  EXPECT_EQ(d.stats().poses_ok, 1u);
}

TEST(RecordCodec, PartsOfDifferentRecordsAreNotMixed) {
  Decoder d;
  hal::CanFrame a[kMaxParts], b[kMaxParts];
  std::size_t n = 0;
  hal::Odometry o1, o2;
  o1.x = 1;
  o2.x = 2;
  ASSERT_TRUE(encode_odometry(o1, 1, false, a, kMaxParts, &n).is_ok());
  ASSERT_TRUE(encode_odometry(o2, 2, false, b, kMaxParts, &n).is_ok());
  // Parts 0,1 of record 1 then parts 2,3 of record 2: nothing must come out.
  EXPECT_EQ(d.feed(a[0]), Decoded::kNothing);
  EXPECT_EQ(d.feed(a[1]), Decoded::kNothing);
  EXPECT_EQ(d.feed(b[2]), Decoded::kNothing);
  EXPECT_EQ(d.feed(b[3]), Decoded::kNothing);
  EXPECT_GE(d.stats().broken_records, 1u);
  // Bad status byte in a pose is malformed, not a pose.
  hal::PoseEstimate p;
  ASSERT_TRUE(encode_pose(p, 1, true, a, kMaxParts, &n).is_ok());
  a[0].data[1 + 2] = 9;
  EXPECT_EQ(d.feed(a[0]), Decoded::kNothing);
  EXPECT_EQ(d.stats().malformed, 1u);
}

// A loopback bus: what one side sends, the other receives (unit test of CanNode only; the real
// bus is tested over vcan in tests/hil).
class LoopbackBus final : public hal::CanBus {
 public:
  bool receive(hal::CanFrame* out) override {
    if (rx.empty()) return false;
    *out = rx.front();
    rx.pop_front();
    ++stats_.rx_frames;
    return true;
  }
  bool send(const hal::CanFrame& f) override {
    tx.push_back(f);
    ++stats_.tx_frames;
    return true;
  }
  const hal::CanBusStats& stats() const override { return stats_; }
  std::deque<hal::CanFrame> rx;
  std::vector<hal::CanFrame> tx;
  hal::CanBusStats stats_;
};

TEST(CanNode, DeliversScansAndOdometryAndEncodesPoses) {
  static LoopbackBus bus;
  static CanNode node;
  node.init(&bus, nullptr, true);
  for (const auto& f : encode(make_scan(8, 180), true)) bus.rx.push_back(f);
  hal::CanFrame f[kMaxParts];
  std::size_t n = 0;
  hal::Odometry o;
  o.x = 5;
  ASSERT_TRUE(encode_odometry(o, 0, false, f, kMaxParts, &n).is_ok());
  for (std::size_t i = 0; i < n; ++i) bus.rx.push_back(f[i]);
  static hal::LaserScan s;
  ASSERT_TRUE(node.laser().poll(&s));
  EXPECT_EQ(s.scan_id, 8u);
  hal::Odometry got;
  ASSERT_TRUE(node.odometry().poll(&got));
  EXPECT_NEAR(got.x, 5.0, 1e-3);
  EXPECT_FALSE(node.laser().poll(&s));

  hal::PoseEstimate p;
  p.scan_id = 8;
  node.pose_sink().publish(p);
  hal::Health h;
  h.deadline_misses = 2;
  node.pose_sink().publish_health(h);
  ASSERT_EQ(bus.tx.size(), 2u);  // one FD frame each
  Decoder d;
  EXPECT_EQ(d.feed(bus.tx[0]), Decoded::kPose);
  EXPECT_EQ(d.feed(bus.tx[1]), Decoded::kHealth);
  EXPECT_EQ(d.health().deadline_misses, 2);
}

TEST(CanNode, InvalidScansReachTheHealthFrame) {
  static LoopbackBus bus;
  static CanNode node;
  node.init(&bus, nullptr, false);
  for (const auto& f : raw_scan_frames(RawScan())) bus.rx.push_back(f);
  static hal::LaserScan s;
  EXPECT_FALSE(node.laser().poll(&s));
  EXPECT_EQ(node.laser().invalid_scans(), 1u);
  // The loop copies the source's count into Health (localization_loop.cpp); the node sends it.
  hal::Health h;
  h.invalid_scans = node.laser().invalid_scans();
  h.fault_bits = static_cast<std::uint32_t>(hal::HealthFault::kLaserTimeout);
  node.pose_sink().publish_health(h);
  Decoder d;
  Decoded k = Decoded::kNothing;
  for (const auto& f : bus.tx) k = d.feed(f);
  ASSERT_EQ(k, Decoded::kHealth);
  EXPECT_EQ(d.health().invalid_scans, 1);
  EXPECT_EQ(d.health().fault_bits, 1u << 16);
  EXPECT_EQ(d.health().state, 2);
  EXPECT_EQ(d.health().dropped_scans, 1);
}

TEST(CanNode, MapsSenderTimeToTheLocalClock) {
  static LoopbackBus bus;
  static CanNode node;
  node.init(&bus, nullptr, false);
  hal::CanFrame f[kMaxParts];
  std::size_t n = 0;
  // Sender clock at 1 s, received at local 100 s (+2 ms latency), then one with 5 ms latency.
  for (int k = 0; k < 2; ++k) {
    hal::Odometry o;
    o.timestamp_ns = 1'000'000'000ull + k * 100'000'000ull;
    ASSERT_TRUE(encode_odometry(o, static_cast<std::uint8_t>(k), false, f, kMaxParts, &n).is_ok());
    for (std::size_t i = 0; i < n; ++i) {
      f[i].timestamp_ns = 100'002'000'000ull + k * 100'000'000ull + (k ? 3'000'000ull : 0);
      bus.rx.push_back(f[i]);
    }
  }
  hal::LaserScan sent = make_scan(3, 180);
  sent.timestamp_ns = 1'200'000'000ull;  // same sender clock; END received 15 ms later
  auto scan_frames = encode(sent, false);
  for (auto& g : scan_frames) g.timestamp_ns = 100'217'000'000ull;
  for (const auto& g : scan_frames) bus.rx.push_back(g);
  hal::Odometry a, b;
  ASSERT_TRUE(node.odometry().poll(&a));
  ASSERT_TRUE(node.odometry().poll(&b));
  EXPECT_EQ(a.timestamp_ns, 100'002'000'000ull);  // offset = min delay sample
  EXPECT_NEAR(static_cast<double>(b.timestamp_ns), 100'102'000'000.0, 5e3);
  static hal::LaserScan s;
  ASSERT_TRUE(node.laser().poll(&s));
  EXPECT_NEAR(static_cast<double>(s.timestamp_ns), 100'202'000'000.0, 1e4);
  // Poses go back out in the sender's clock.
  hal::PoseEstimate p;
  p.timestamp_ns = b.timestamp_ns;
  bus.tx.clear();
  node.pose_sink().publish(p);
  Decoder d;
  for (const auto& g : bus.tx) d.feed(g);
  EXPECT_NEAR(static_cast<double>(d.pose().timestamp_ns), 1'100'000'000.0, 1e4);
}

}  // namespace
}  // namespace hal_can
