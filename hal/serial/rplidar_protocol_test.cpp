// RPLIDAR protocol: request bytes as the protocol document lists them, sample and capsule codecs,
// the parser skipping a stream the STOP interrupted, and resynchronising after damage.
#include "hal_serial/rplidar_protocol.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace hal_serial {
namespace {

TEST(RplidarProtocol, RequestsAsTheDocumentListsThem) {
  std::uint8_t b[16];
  ASSERT_EQ(encode_rplidar_request(kRplidarCmdGetHealth, nullptr, 0, b, sizeof(b)), 2u);
  EXPECT_EQ(b[0], 0xA5);
  EXPECT_EQ(b[1], 0x52);
  // EXPRESS_SCAN, legacy: A5 82 05 00 00 00 00 00 22 (the document's example request).
  const std::uint8_t legacy[5] = {0, 0, 0, 0, 0};
  ASSERT_EQ(encode_rplidar_request(kRplidarCmdExpressScan, legacy, 5, b, sizeof(b)), 9u);
  EXPECT_EQ(b[2], 0x05);
  EXPECT_EQ(b[8], 0x22);
  // The SCAN descriptor: A5 5A 05 00 00 40 81.
  encode_rplidar_descriptor(5, 1, kRplidarAnsSample, b);
  const std::uint8_t scan_desc[7] = {0xA5, 0x5A, 0x05, 0x00, 0x00, 0x40, 0x81};
  for (int i = 0; i < 7; ++i) EXPECT_EQ(b[i], scan_desc[i]) << i;
}

TEST(RplidarProtocol, SampleCheckBits) {
  RplidarSample s;
  s.start = true;
  s.quality = 47;
  s.angle_q6 = 359 * 64 + 63;
  s.distance_q2 = 12000 * 4;
  std::uint8_t b[5];
  encode_rplidar_sample(s, b);
  RplidarSample d;
  ASSERT_TRUE(decode_rplidar_sample(b, &d));
  EXPECT_TRUE(d.start);
  EXPECT_EQ(d.quality, 47);
  EXPECT_EQ(d.angle_q6, s.angle_q6);
  EXPECT_EQ(d.distance_q2, s.distance_q2);
  std::uint8_t bad[5] = {b[0], b[1], b[2], b[3], b[4]};
  bad[0] |= 0x3;  // S and !S both set
  EXPECT_FALSE(decode_rplidar_sample(bad, &d));
  bad[0] = b[0];
  bad[1] &= 0xFE;  // C = 0
  EXPECT_FALSE(decode_rplidar_sample(bad, &d));
}

TEST(RplidarProtocol, CapsuleRoundTripAndSdkAngles) {
  RplidarCapsule a, b;
  a.start_angle_q6 = 350 * 64;
  b.start_angle_q6 = 6 * 64;  // 16° later, across 0°
  for (int k = 0; k < 32; ++k) {
    a.distance_mm[k] = static_cast<std::uint16_t>(1000 + k);
    a.offset_q3[k] = 0;
  }
  std::uint8_t raw[84];
  encode_rplidar_capsule(a, raw);
  RplidarCapsule d;
  ASSERT_TRUE(decode_rplidar_capsule(raw, &d));
  EXPECT_EQ(d.start_angle_q6, a.start_angle_q6);
  EXPECT_EQ(d.distance_mm[31], 1031);
  raw[40] ^= 0x04;
  EXPECT_FALSE(decode_rplidar_capsule(raw, &d));  // checksum
  RplidarSample s[32];
  ASSERT_EQ(rplidar_capsule_samples(a, b, s), 32u);
  EXPECT_EQ(s[0].angle_q6, 350 * 64);
  EXPECT_EQ(s[1].angle_q6, 350 * 64 + 32);  // 16° / 32 = 0.5°
  int starts = 0;
  for (const RplidarSample& x : s) starts += x.start ? 1 : 0;
  EXPECT_EQ(starts, 1);
  // The SDK flags the sample whose successor reaches 360° (350° + 19 × 0.5° = 359.5°).
  EXPECT_TRUE(s[19].start);
  EXPECT_EQ(s[31].distance_q2, 1031 * 4);
}

std::vector<std::uint8_t> sample_bytes(int n, int first_angle_deg, bool start_first) {
  std::vector<std::uint8_t> out;
  for (int i = 0; i < n; ++i) {
    RplidarSample s;
    s.start = start_first && i == 0;
    s.quality = 30;
    s.angle_q6 = static_cast<std::uint16_t>(((first_angle_deg + i) % 360) * 64);
    s.distance_q2 = static_cast<std::uint16_t>((500 + i) * 4);
    std::uint8_t b[5];
    encode_rplidar_sample(s, b);
    out.insert(out.end(), b, b + 5);
  }
  return out;
}

TEST(RplidarParser, SkipsTheOldStreamAndResyncsAfterAStrayByte) {
  RplidarParser p;
  p.expect(kRplidarAnsSample);
  std::vector<std::uint8_t> stream = sample_bytes(37, 100, false);  // the stream STOP cut off
  stream.push_back(0xA5);                                          // and a partial descriptor
  std::uint8_t d[7];
  encode_rplidar_descriptor(5, 1, kRplidarAnsSample, d);
  stream.insert(stream.end(), d, d + 7);
  auto good = sample_bytes(50, 0, true);
  stream.insert(stream.end(), good.begin(), good.end());
  stream.push_back(0x00);  // a stray byte shifts the framing
  good = sample_bytes(50, 50, false);
  stream.insert(stream.end(), good.begin(), good.end());
  std::mt19937 rng(3);
  RplidarEvent e;
  int samples = 0, started = 0;
  std::size_t off = 0;
  while (off < stream.size()) {
    std::size_t n = std::min<std::size_t>(1 + rng() % 40, stream.size() - off);
    std::size_t fed = 0;
    while (fed < n) {
      fed += p.feed(stream.data() + off + fed, n - fed);
      while (p.next(&e)) {
        if (e.kind == RplidarEvent::Kind::kStreamStarted) ++started;
        if (e.kind == RplidarEvent::Kind::kSample) ++samples;
      }
    }
    off += n;
  }
  EXPECT_EQ(started, 1);
  EXPECT_EQ(p.stats().skipped_bytes, 37u * 5 + 1);
  EXPECT_EQ(p.stats().check_errors, 1u);
  // All 50 before the stray byte; after it, the framing is found again within a few samples.
  EXPECT_GE(samples, 95);
  EXPECT_LE(samples, 100);
}

TEST(RplidarParser, SingleAnswers) {
  RplidarParser p;
  p.expect(kRplidarAnsHealth);
  std::uint8_t d[7];
  encode_rplidar_descriptor(3, 0, kRplidarAnsHealth, d);
  std::vector<std::uint8_t> s(d, d + 7);
  s.insert(s.end(), {0x02, 0x34, 0x12});
  p.feed(s.data(), s.size());
  RplidarEvent e;
  ASSERT_TRUE(p.next(&e));
  EXPECT_EQ(e.kind, RplidarEvent::Kind::kHealth);
  EXPECT_EQ(e.health.status, 2);
  EXPECT_EQ(e.health.error_code, 0x1234);
  EXPECT_FALSE(p.next(&e));
}

}  // namespace
}  // namespace hal_serial
