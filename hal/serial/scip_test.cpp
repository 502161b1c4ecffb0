// SCIP 2.0 parser and encoder: the published answers of a URG-04LX (PP and VV as printed in the
// SCIP 2.0 specification C-42-03320B and the URG network wiki, sums included), the encoding
// examples of the specification, round trips of MD/MS/ME answers fed in random chunks, and every
// kind of damage (wrong sum, cut answer, overlong line, garbage) counted and survived.
#include "hal_serial/scip.h"

#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace hal_serial {
namespace {

// As published (C-42-03320B Sec. 8.12 and the URG wiki "scip_status_en"), byte for byte.
const char kPublishedPP[] =
    "PP\n00P\nMODL:URG-04LX(Hokuyo Automatic Co.,Ltd.);N\nDMIN:20;4\nDMAX:5600;_\nARES:1024;\\\n"
    "AMIN:44;7\nAMAX:725;o\nAFRT:384;6\nSCAN:600;e\n\n";
const char kPublishedVV[] =
    "VV\n00P\nVEND:Hokuyo Automatic Co.,Ltd.;[\nPROD:SOKUIKI Sensor URG-04LX;[\nFIRM:3.1.00(18/Jan./2007);`\n"
    "PROT:SCIP 2.0;N\nSERI:H0614967;V\n\n";

std::vector<ScipResponse> parse_all(ScipParser* p, const std::string& text, std::mt19937* rng = nullptr) {
  std::vector<ScipResponse> out;
  ScipResponse r;
  std::size_t off = 0;
  while (off < text.size()) {
    std::size_t chunk = rng ? 1 + (*rng)() % 97 : text.size() - off;
    if (chunk > text.size() - off) chunk = text.size() - off;
    std::size_t fed = 0;
    while (fed < chunk) {
      fed += p->feed(reinterpret_cast<const std::uint8_t*>(text.data() + off + fed), chunk - fed);
      while (p->next(&r)) out.push_back(r);
    }
    off += chunk;
  }
  return out;
}

TEST(Scip, SumAndEncodingAsPublished) {
  EXPECT_EQ(scip_sum("00", 2), 'P');
  EXPECT_EQ(scip_sum("99", 2), 'b');
  EXPECT_EQ(scip_sum("DMIN:20", 7), '4');
  // Sec. 6 examples: 1234 in two characters is "CB", 5432 in three is "1Dh".
  char c[4] = {0};
  scip_encode(1234, 2, c);
  EXPECT_STREQ(c, "CB");
  scip_encode(5432, 3, c);
  EXPECT_STREQ(c, "1Dh");
  std::uint32_t v = 0;
  ASSERT_TRUE(scip_decode("1Dh", 3, &v));
  EXPECT_EQ(v, 5432u);
  EXPECT_FALSE(scip_decode("1D~", 3, &v));  // '~' is outside 0x30..0x6F
}

TEST(Scip, PublishedParameterAndVersionAnswers) {
  ScipParser p;
  const auto rs = parse_all(&p, std::string(kPublishedPP) + kPublishedVV);
  ASSERT_EQ(rs.size(), 2u);
  EXPECT_EQ(p.stats().checksum_errors, 0u);
  ScipParameters pp;
  ASSERT_TRUE(decode_scip_parameters(rs[0], &pp).is_ok());
  EXPECT_STREQ(pp.model, "URG-04LX(Hokuyo Automatic Co.,Ltd.)");
  EXPECT_EQ(pp.dmin_mm, 20u);
  EXPECT_EQ(pp.dmax_mm, 5600u);
  EXPECT_EQ(pp.ares, 1024u);
  EXPECT_EQ(pp.amin, 44u);
  EXPECT_EQ(pp.amax, 725u);
  EXPECT_EQ(pp.afrt, 384u);
  EXPECT_EQ(pp.scan_rpm, 600u);
  char prod[40];
  ASSERT_TRUE(scip_info_value(rs[1], "PROD", prod, sizeof(prod)));
  EXPECT_STREQ(prod, "SOKUIKI Sensor URG-04LX");
  // The encoder writes the same bytes.
  const char* lines[] = {"MODL:URG-04LX(Hokuyo Automatic Co.,Ltd.)", "DMIN:20", "DMAX:5600", "ARES:1024",
                         "AMIN:44", "AMAX:725", "AFRT:384", "SCAN:600"};
  char buf[512];
  const std::size_t n = encode_scip_info("PP", lines, 8, buf, sizeof(buf));
  EXPECT_EQ(std::string(buf, n), std::string(kPublishedPP));
}

TEST(Scip, ParameterAnswerWithImpossibleGeometryIsAnError) {
  const char* lines[] = {"DMIN:20", "DMAX:5600", "ARES:0", "AMIN:44", "AMAX:725", "AFRT:384"};
  char buf[512];
  const std::size_t n = encode_scip_info("PP", lines, 6, buf, sizeof(buf));
  ScipParser p;
  const auto rs = parse_all(&p, std::string(buf, n));
  ASSERT_EQ(rs.size(), 1u);
  ScipParameters pp;
  const fw::Status s = decode_scip_parameters(rs[0], &pp);
  EXPECT_FALSE(s.is_ok());
  EXPECT_NE(std::string(s.message()).find("ARES 0"), std::string::npos) << s.message();
  const char* wide[] = {"DMIN:20", "DMAX:5600", "ARES:20000", "AMIN:0", "AMAX:10000", "AFRT:5000"};
  const std::size_t m = encode_scip_info("PP", wide, 6, buf, sizeof(buf));
  const auto ws = parse_all(&p, std::string(buf, m));
  ASSERT_EQ(ws.size(), 1u);
  EXPECT_FALSE(decode_scip_parameters(ws[0], &pp).is_ok());  // steps beyond the 4-digit MD fields
}

std::string scan_answer(const char* echo, std::uint32_t ts, const std::vector<std::uint32_t>& r,
                        const std::vector<std::uint32_t>* intensity, std::size_t chars) {
  std::vector<char> buf(20000);
  const std::size_t n = encode_scip_scan(echo, ts, r.data(), intensity ? intensity->data() : nullptr, r.size(), chars,
                                         buf.data(), buf.size());
  return std::string(buf.data(), n);
}

TEST(Scip, ScanAnswersRoundTripInRandomChunks) {
  std::mt19937 rng(5);
  std::vector<std::uint32_t> r(1081), in(1081);
  for (std::size_t i = 0; i < r.size(); ++i) {
    r[i] = static_cast<std::uint32_t>((i * 97 + 13) % 60000);
    in[i] = static_cast<std::uint32_t>(i * 31 % 20000);
  }
  std::vector<std::uint32_t> r_ms(r.begin(), r.begin() + 682);
  for (auto& x : r_ms) x %= 4096;
  std::string text = scan_answer("MD0000108001000", 1234, r, nullptr, 3) +
                     scan_answer("ME0000108001000", 0xFFFFFF, r, &in, 3) +
                     scan_answer("MS0044072501000;id7", 77, r_ms, nullptr, 2);
  ScipParser p;
  const auto rs = parse_all(&p, text, &rng);
  ASSERT_EQ(rs.size(), 3u);
  static ScipScan s;
  ASSERT_TRUE(decode_scip_scan(rs[0], &s).is_ok());
  EXPECT_EQ(s.count, 1081u);
  EXPECT_EQ(s.timestamp_ms, 1234u);
  EXPECT_FALSE(s.has_intensity);
  for (std::size_t i = 0; i < r.size(); ++i) ASSERT_EQ(s.ranges_mm[i], r[i]) << i;
  ASSERT_TRUE(decode_scip_scan(rs[1], &s).is_ok());
  EXPECT_TRUE(s.has_intensity);
  EXPECT_EQ(s.timestamp_ms, 0xFFFFFFu);
  for (std::size_t i = 0; i < r.size(); ++i) ASSERT_EQ(s.intensity[i], in[i]) << i;
  ASSERT_TRUE(decode_scip_scan(rs[2], &s).is_ok());
  EXPECT_EQ(s.count, 682u);
  EXPECT_EQ(s.echo.start, 44u);
  EXPECT_EQ(s.echo.end, 725u);
  for (std::size_t i = 0; i < r_ms.size(); ++i) ASSERT_EQ(s.ranges_mm[i], r_ms[i]) << i;
  EXPECT_EQ(p.stats().checksum_errors + p.stats().malformed + p.stats().truncated, 0u);
}

TEST(Scip, ClusteredScanCountsValuesPerCluster) {
  std::vector<std::uint32_t> r(341, 1500);  // steps 44..725 in clusters of 2 → 341 values
  ScipParser p;
  const auto rs = parse_all(&p, scan_answer("MD0044072502000", 5, r, nullptr, 3));
  ASSERT_EQ(rs.size(), 1u);
  static ScipScan s;
  ASSERT_TRUE(decode_scip_scan(rs[0], &s).is_ok());
  EXPECT_EQ(s.count, 341u);
  // One value too many for the echo: a length error that names the counts.
  r.push_back(1);
  const auto bad = parse_all(&p, scan_answer("MD0044072502000", 5, r, nullptr, 3));
  ASSERT_EQ(bad.size(), 1u);
  const fw::Status st = decode_scip_scan(bad[0], &s);
  ASSERT_FALSE(st.is_ok());
  EXPECT_NE(std::string(st.message()).find("341 values"), std::string::npos) << st.message();
}

TEST(Scip, DamageIsCountedAndTheNextAnswerSurvives) {
  std::vector<std::uint32_t> r(1081, 2000);
  const std::string good = scan_answer("MD0000108001000", 10, r, nullptr, 3);
  std::string corrupt = good;
  corrupt[100] = corrupt[100] == 'A' ? 'B' : 'A';  // inside a data line: its sum is wrong
  // The device reset in the middle: cut after 13 whole data lines (echo 16 + status 4 + time 6 + 13 x 66),
  // and cut inside a line (that line and the next answer's echo run together: both answers lost).
  const std::string cut_at_line = good.substr(0, 26 + 13 * 66);
  const std::string cut_mid_line = good.substr(0, 26 + 13 * 66 + 20);
  const std::string overlong = "MD0000108001000\n99b\n" + std::string(300, '0') + "\n\n";
  const std::string text = "\n\nXY\n\n" + good + corrupt + good + cut_at_line + good + overlong + good + cut_mid_line +
                           good + good;
  ScipParser p;
  const auto rs = parse_all(&p, text);
  static ScipScan s;
  int decoded = 0;
  for (const auto& a : rs) decoded += decode_scip_scan(a, &s).is_ok() ? 1 : 0;
  EXPECT_EQ(decoded, 5);
  EXPECT_EQ(static_cast<int>(rs.size()), decoded);  // nothing half-made is handed out
  EXPECT_EQ(p.stats().checksum_errors, 2u);         // the corrupt line, the run-together line
  EXPECT_EQ(p.stats().truncated, 1u);
  EXPECT_EQ(p.stats().malformed, 2u);               // "XY" without a status line, the overlong line
  EXPECT_EQ(p.stats().stray_lines, 2u);
}

TEST(Scip, StatusLineWithWrongSumDropsTheAnswer) {
  ScipParser p;
  const auto rs = parse_all(&p, "QT\n00Q\n\nBM\n00P\n\n");
  ASSERT_EQ(rs.size(), 1u);
  EXPECT_STREQ(rs[0].command, "BM");
  EXPECT_EQ(p.stats().checksum_errors, 1u);
}

}  // namespace
}  // namespace hal_serial
