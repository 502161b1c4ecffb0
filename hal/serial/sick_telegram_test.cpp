#include "hal_serial/sick_telegram.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace hal_serial {
namespace {

TEST(SickCrc, KnownTelegrams) {
  // From the LMS2xx telegram listing: request continuous output and the mode-change response.
  const std::uint8_t req[] = {0x02, 0x00, 0x02, 0x00, 0x20, 0x24};
  EXPECT_EQ(sick_crc16(req, sizeof(req)), 0x0834);
  const std::uint8_t resp[] = {0x02, 0x80, 0x03, 0x00, 0xA0, 0x00, 0x10};
  EXPECT_EQ(sick_crc16(resp, sizeof(resp)), 0x0A16);
  std::uint8_t out[16];
  const std::uint8_t payload[] = {0x20, 0x24};
  ASSERT_EQ(encode_sick_telegram(0x00, payload, 2, out, sizeof(out)), 8u);
  EXPECT_EQ(out[6], 0x34);
  EXPECT_EQ(out[7], 0x08);
}

MeasuredValues make_values(std::uint16_t n, std::uint16_t seed) {
  MeasuredValues v;
  v.count = n;
  for (std::uint16_t i = 0; i < n; ++i) v.values[i] = static_cast<std::uint16_t>((i * 37 + seed) % 8192);
  v.values[n / 2] = kSickNoReturn;
  return v;
}

TEST(SickParser, RoundTripAndResyncAfterGarbageAndBadCrc) {
  std::vector<std::uint8_t> stream;
  std::uint8_t buf[kMaxTelegramBytes];
  std::mt19937 rng(7);
  int good = 0, corrupted = 0;
  for (int k = 0; k < 60; ++k) {
    const std::size_t n = encode_measured_values(make_values(k % 2 ? 361 : 181, static_cast<std::uint16_t>(k)), buf, sizeof(buf));
    ASSERT_GT(n, 0u);
    std::vector<std::uint8_t> t(buf, buf + n);
    if (k % 7 == 3) {
      t[10 + rng() % (n - 12)] ^= 0x21;  // bad CRC
      ++corrupted;
    } else {
      ++good;
    }
    if (k % 5 == 1) {  // garbage, including fake STX bytes and impossible lengths
      for (int g = 0; g < 23; ++g) stream.push_back(static_cast<std::uint8_t>(rng()));
      stream.push_back(kStx);
      stream.push_back(0x80);
      stream.push_back(0xFF);
      stream.push_back(0xFF);
    }
    stream.insert(stream.end(), t.begin(), t.end());
  }
  // Feed in random-sized chunks, as a serial port delivers them.
  SickParser p;
  SickTelegram tg;
  MeasuredValues v;
  int got = 0;
  std::size_t off = 0;
  while (off < stream.size()) {
    const std::size_t chunk = 1 + rng() % 300;
    std::size_t take = std::min(chunk, stream.size() - off);
    off += p.feed(stream.data() + off, take);
    while (p.next(&tg)) {
      if (tg.command != kRespMeasuredValues) continue;
      ASSERT_TRUE(decode_measured_values(tg, &v).is_ok());
      EXPECT_TRUE(v.count == 181 || v.count == 361);
      EXPECT_EQ(v.values[v.count / 2], kSickNoReturn);
      ++got;
    }
  }
  EXPECT_EQ(got, good);
  EXPECT_GE(p.stats().crc_errors, static_cast<std::uint32_t>(corrupted));
  EXPECT_GT(p.stats().garbage_bytes, 0u);
  EXPECT_GT(p.stats().bad_length, 0u);
}

TEST(SickParser, RejectsWrongContent) {
  SickTelegram t;
  t.command = 0xB0;
  t.length = 4;
  t.data[0] = 5;  // 5 values announced, LEN says none
  MeasuredValues v;
  fw::Status s = decode_measured_values(t, &v);
  EXPECT_FALSE(s.is_ok());
  EXPECT_NE(std::string(s.message()).find("LEN"), std::string::npos);
  t.command = 0xA0;
  EXPECT_FALSE(decode_measured_values(t, &v).is_ok());
}

}  // namespace
}  // namespace hal_serial
