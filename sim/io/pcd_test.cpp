// PCD reader: every DATA kind (ascii, binary, binary_compressed) and gzip give the same points;
// NaN points are dropped and counted; organized clouds keep their pixel index; every kind of
// malformed input fails with "path:line: problem".
#include "sim/io/pcd.h"

#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace sim {
namespace {

namespace fs = std::filesystem;

const char* kHeader3 =
    "# .PCD v0.7 - Point Cloud Data file format\n"
    "VERSION 0.7\n"
    "FIELDS x y z rgb\n"
    "SIZE 4 4 4 4\n"
    "TYPE F F F U\n"
    "COUNT 1 1 1 1\n"
    "WIDTH 3\n"
    "HEIGHT 1\n"
    "VIEWPOINT 0 0 0 1 0 0 0\n"
    "POINTS 3\n";

// Three points: (1,2,3), NaN, (-4.5,0.25,7); rgb values 10, 20, 30.
const float kXyz[3][3] = {{1, 2, 3}, {NAN, NAN, NAN}, {-4.5f, 0.25f, 7}};

std::string binary_rows() {
  std::string s;
  for (int i = 0; i < 3; ++i) {
    s.append(reinterpret_cast<const char*>(kXyz[i]), 12);
    const std::uint32_t rgb = 10u * static_cast<std::uint32_t>(i + 1);
    s.append(reinterpret_cast<const char*>(&rgb), 4);
  }
  return s;
}

// Column layout of binary_compressed (all x, all y, all z, all rgb).
std::string columns() {
  std::string s;
  for (int f = 0; f < 3; ++f)
    for (int i = 0; i < 3; ++i) s.append(reinterpret_cast<const char*>(&kXyz[i][f]), 4);
  for (int i = 0; i < 3; ++i) {
    const std::uint32_t rgb = 10u * static_cast<std::uint32_t>(i + 1);
    s.append(reinterpret_cast<const char*>(&rgb), 4);
  }
  return s;
}

// A valid LZF stream of `raw` made of literal runs only (≤ 32 bytes each).
std::string lzf_literals(const std::string& raw) {
  std::string s;
  for (std::size_t i = 0; i < raw.size(); i += 32) {
    const std::size_t len = std::min<std::size_t>(32, raw.size() - i);
    s.push_back(static_cast<char>(len - 1));
    s.append(raw, i, len);
  }
  return s;
}

class PcdTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("pcd_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& bytes) const {
    const std::string p = (dir_ / name).string();
    std::ofstream o(p, std::ios::binary);
    o << bytes;
    return p;
  }
  // Reads and expects failure; returns the message.
  std::string fail(const std::string& name, const std::string& bytes) const {
    PcdCloud c;
    std::string err;
    EXPECT_FALSE(read_pcd(write(name, bytes), &c, &err)) << name;
    EXPECT_NE(err.find(name), std::string::npos) << err;
    return err;
  }
  static void expect_three(const PcdCloud& c) {
    ASSERT_EQ(c.points.size(), 2u);
    EXPECT_EQ(c.dropped_nonfinite, 1u);
    EXPECT_EQ(c.declared_points, 3u);
    EXPECT_EQ(c.points[0], Eigen::Vector3f(1, 2, 3));
    EXPECT_EQ(c.points[1], Eigen::Vector3f(-4.5f, 0.25f, 7));
    EXPECT_EQ(c.index[0], 0u);
    EXPECT_EQ(c.index[1], 2u);
  }
  fs::path dir_;
};

TEST_F(PcdTest, AsciiDropsNanAndCountsThem) {
  PcdCloud c;
  std::string err;
  ASSERT_TRUE(read_pcd(write("a.pcd", std::string(kHeader3) + "DATA ascii\n1 2 3 10\nnan nan nan 20\n-4.5 0.25 7 30\n"),
                       &c, &err)) << err;
  expect_three(c);
  EXPECT_EQ(c.data, "ascii");
  EXPECT_FALSE(c.organized());
  EXPECT_EQ(c.fields.size(), 4u);
}

TEST_F(PcdTest, BinaryGivesTheSamePoints) {
  PcdCloud c;
  std::string err;
  ASSERT_TRUE(read_pcd(write("b.pcd", std::string(kHeader3) + "DATA binary\n" + binary_rows()), &c, &err)) << err;
  expect_three(c);
}

TEST_F(PcdTest, BinaryCompressedLiteralsAndBackReference) {
  const std::string raw = columns();
  const std::string lzf = lzf_literals(raw);
  std::string block(8, '\0');
  const std::uint32_t cs = static_cast<std::uint32_t>(lzf.size()), us = static_cast<std::uint32_t>(raw.size());
  std::memcpy(&block[0], &cs, 4);
  std::memcpy(&block[4], &us, 4);
  PcdCloud c;
  std::string err;
  ASSERT_TRUE(read_pcd(write("c.pcd", std::string(kHeader3) + "DATA binary_compressed\n" + block + lzf), &c, &err))
      << err;
  expect_three(c);
  // A back reference: "abc" then "copy 6 bytes from 3 back" = "abcabcabc" (overlapping copy).
  const std::uint8_t stream[] = {2, 'a', 'b', 'c', (4 << 5) | 0, 2};
  std::uint8_t out[9];
  ASSERT_TRUE(lzf_decompress(stream, sizeof(stream), out, sizeof(out)));
  EXPECT_EQ(std::string(reinterpret_cast<char*>(out), 9), "abcabcabc");
  // Corrupt: a reference before the start, a run past the end, a wrong inflated size.
  const std::uint8_t before[] = {0, 'a', (1 << 5) | 0, 5};
  EXPECT_FALSE(lzf_decompress(before, sizeof(before), out, 4));
  const std::uint8_t past[] = {10, 'a'};
  EXPECT_FALSE(lzf_decompress(past, sizeof(past), out, 9));
  EXPECT_FALSE(lzf_decompress(stream, sizeof(stream), out, 8));
  std::string bad = lzf;
  bad[0] = static_cast<char>(0xE0);  // a back reference as the first token
  const std::string e = fail("corrupt.pcd", std::string(kHeader3) + "DATA binary_compressed\n" + block + bad);
  EXPECT_NE(e.find("corrupt"), std::string::npos) << e;
}

TEST_F(PcdTest, GzipAndOrganized) {
  const std::string text =
      "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nHEIGHT 2\nPOINTS 4\nDATA ascii\n"
      "0 0 1\nnan nan nan\n1 0 1\n1 1 1\n";
  const std::string p = (dir_ / "o.pcd.gz").string();
  gzFile f = gzopen(p.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  gzwrite(f, text.data(), static_cast<unsigned>(text.size()));
  gzclose(f);
  PcdCloud c;
  std::string err;
  ASSERT_TRUE(read_pcd(p, &c, &err)) << err;
  EXPECT_TRUE(c.organized());
  EXPECT_EQ(c.width, 2u);
  EXPECT_EQ(c.height, 2u);
  ASSERT_EQ(c.points.size(), 3u);
  EXPECT_EQ(c.dropped_nonfinite, 1u);
  EXPECT_EQ(c.index[1], 2u);  // row 1, column 0
  EXPECT_EQ(c.points[2], Eigen::Vector3f(1, 1, 1));
}

TEST_F(PcdTest, MalformedHeadersNameFileAndLine) {
  const std::string h = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nHEIGHT 1\n";
  EXPECT_NE(fail("k.pcd", "VERSION 0.7\nFOO 1\n").find("k.pcd:2: unknown header keyword 'FOO'"), std::string::npos);
  EXPECT_NE(fail("r.pcd", h + "WIDTH 1\nDATA ascii\n1 2 3\n").find("r.pcd:7: repeated"), std::string::npos);
  EXPECT_NE(fail("s.pcd", "FIELDS x y z\nSIZE 4 4\nTYPE F F F\nWIDTH 1\nHEIGHT 1\nDATA ascii\n1 2 3\n")
                .find("s.pcd:6: FIELDS lists 3 fields but SIZE has 2"),
            std::string::npos);
  EXPECT_NE(fail("t.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F Q\n").find("t.pcd:3: TYPE value 'Q'"),
            std::string::npos);
  EXPECT_NE(fail("sz.pcd", "FIELDS x y z\nSIZE 4 4 3\nTYPE F F F\nWIDTH 1\nHEIGHT 1\nDATA ascii\n1 2 3\n")
                .find("SIZE 3"),
            std::string::npos);
  EXPECT_NE(fail("x.pcd", "FIELDS x y\nSIZE 4 4\nTYPE F F\nWIDTH 1\nHEIGHT 1\nDATA ascii\n1 2\n")
                .find("x.pcd:1: FIELDS must include x, y and z"),
            std::string::npos);
  EXPECT_NE(fail("p.pcd", h + "POINTS 2\nDATA ascii\n1 2 3\n").find("p.pcd:8: POINTS 2 != WIDTH x HEIGHT 1"),
            std::string::npos);
  EXPECT_NE(fail("d.pcd", h + "DATA xml\n").find("d.pcd:7: DATA must be"), std::string::npos);
  EXPECT_NE(fail("n.pcd", h).find("without a DATA line"), std::string::npos);
  EXPECT_NE(fail("w.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH abc\n").find("w.pcd:4: WIDTH needs"),
            std::string::npos);
  EXPECT_NE(fail("v.pcd", h + "VIEWPOINT 0 0 0 1 0 0\nDATA ascii\n1 2 3\n").find("v.pcd:7: VIEWPOINT needs 7"),
            std::string::npos);
  EXPECT_NE(fail("big.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 4000000000\nHEIGHT 4000000000\nDATA binary\n")
                .find("exceeds the cap"),
            std::string::npos);
  EXPECT_NE(fail("empty.pcd", "").find("without a DATA line"), std::string::npos);
  PcdCloud c;
  std::string err;
  EXPECT_FALSE(read_pcd((dir_ / "missing.pcd").string(), &c, &err));
  EXPECT_NE(err.find("missing.pcd"), std::string::npos) << err;
}

TEST_F(PcdTest, MalformedDataNamesFileAndLine) {
  const std::string h = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nHEIGHT 1\n";
  EXPECT_NE(fail("c.pcd", h + "DATA ascii\n1 2 3\n1 2\n").find("c.pcd:8: 2 values, expected 3"), std::string::npos);
  EXPECT_NE(fail("q.pcd", h + "DATA ascii\n1 2 3\n1 two 3\n").find("q.pcd:8: value 2 'two' is not a number"),
            std::string::npos);
  EXPECT_NE(fail("f.pcd", h + "DATA ascii\n1 2 3\n").find("file ends after 1 of 2 points"), std::string::npos);
  EXPECT_NE(fail("m.pcd", h + "DATA ascii\n1 2 3\n4 5 6\n7 8 9\n").find("m.pcd:9: more data lines"),
            std::string::npos);
  const std::string rows(24, '\0');
  EXPECT_NE(fail("tb.pcd", h + "DATA binary\n" + rows.substr(0, 20)).find("binary data of 20 bytes"),
            std::string::npos);
  EXPECT_NE(fail("lb.pcd", h + "DATA binary\n" + rows + "xx").find("binary data of 26 bytes"), std::string::npos);
  EXPECT_NE(fail("tc.pcd", h + "DATA binary_compressed\n" + "abc").find("truncated"), std::string::npos);
  std::string block(8, '\0');
  const std::uint32_t cs = 100, us = 24;
  std::memcpy(&block[0], &cs, 4);
  std::memcpy(&block[4], &us, 4);
  EXPECT_NE(fail("tc2.pcd", h + "DATA binary_compressed\n" + block + "abc").find("truncated"), std::string::npos);
  const std::uint32_t us_bad = 25;
  std::memcpy(&block[4], &us_bad, 4);
  EXPECT_NE(fail("us.pcd", h + "DATA binary_compressed\n" + block).find("inflates to 25 bytes, expected 24"),
            std::string::npos);
}

}  // namespace
}  // namespace sim
