#include "firmware/base/crc32.h"

#include <gtest/gtest.h>

#include <cstring>

namespace fw {
namespace {

TEST(Crc32Test, StandardCheckValue) {
  // The CRC-32/ISO-HDLC check value (same as zlib crc32("123456789")).
  const char* s = "123456789";
  EXPECT_EQ(crc32(reinterpret_cast<const std::uint8_t*>(s), std::strlen(s)), 0xCBF43926u);
  EXPECT_EQ(crc32(nullptr, 0), 0u);
}

TEST(Crc32Test, IncrementalEqualsOneShot) {
  std::uint8_t buf[1000];
  for (int i = 0; i < 1000; ++i) buf[i] = static_cast<std::uint8_t>(i * 7 + 3);
  const std::uint32_t whole = crc32(buf, sizeof(buf));
  const std::uint32_t part = crc32_update(crc32_update(0, buf, 333), buf + 333, 667);
  EXPECT_EQ(whole, part);
  buf[500] ^= 1;
  EXPECT_NE(crc32(buf, sizeof(buf)), whole);
}

}  // namespace
}  // namespace fw
