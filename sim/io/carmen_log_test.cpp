// Unit tests of the CARMEN reader/writer on small in-memory / temporary files: every record type,
// strict errors naming file:line, skip_bad_lines, gzip (incl. corrupt), exact write/read round trip.
#include "sim/io/carmen_log.h"
#include "sim/io/test_files.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>

namespace sim {
namespace {

using test_files::temp_path;
using test_files::write_text;

void write_gz(const std::string& path, const std::string& text) {
  gzFile f = gzopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  ASSERT_EQ(gzwrite(f, text.data(), static_cast<unsigned>(text.size())), static_cast<int>(text.size()));
  ASSERT_EQ(gzclose(f), Z_OK);
}

std::string flaser_line(int n, const std::string& range = "1.5") {
  std::string s = "FLASER " + std::to_string(n);
  for (int i = 0; i < n; ++i) s += " " + range;
  s += " 1.0 2.0 0.5 1.1 2.1 0.6 100.25 host 0.25\n";
  return s;
}

const char* kRobotLaser =
    "ROBOTLASER1 0 -1.570796 3.141593 0.017453 81.900000 0.010000 0 3 1.0 2.0 81.910 0 "
    "0.1 0.2 0.3 1.1 1.2 1.3 0.0 0.0 0.0 0.0 0.0 1232658478.161285 zoidberg2 -0.055208\n";

// kRobotLaser with the first occurrence of `field` replaced by `value`.
std::string robot_laser(const std::string& field, const std::string& value) {
  std::string s = kRobotLaser;
  const size_t at = s.find(" " + field + " ");
  if (at != std::string::npos) s.replace(at + 1, field.size(), value);
  return s;
}

bool parse(const std::string& text, CarmenLog* log, std::string* err, bool skip = false) {
  CarmenReadOptions o;
  o.skip_bad_lines = skip;
  o.max_line_bytes = 4096;
  return parse_carmen_log("mem.clf", text.data(), text.size(), o, log, err);
}

TEST(CarmenLog, ParsesAllRecordTypes) {
  std::string text =
      "# comment\n"
      "PARAM robot_front_laser_max 80.99 1071078718.462518 merci 1071078718.462517\n"
      "PARAM robot_use_laser on nohost 0\n"
      "ODOM 0.5 -0.25 0.1 0.3 0.02 0 976052857.337284 nohost 0.000000\n" +
      flaser_line(180) + flaser_line(361) + std::string(kRobotLaser) +
      "RAWLASER2 0 -2.0 4.0 0.5 30.0 0.01 0 4 1 2 3 4 2 7 8 55.5 host 1.5\n"
      "NEFF 29.5\n"
      "SYNC tag 1.0 host 1.0\n"
      "\n"
      "RLASER 2 3.0 4.0 0 0 0 0 0 0 10 h 11\n";
  CarmenLog log;
  std::string err;
  ASSERT_TRUE(parse(text, &log, &err)) << err;
  ASSERT_EQ(log.scans.size(), 5u);
  EXPECT_EQ(log.count("FLASER"), 2u);
  EXPECT_EQ(log.count("ROBOTLASER1"), 1u);
  EXPECT_EQ(log.count("RAWLASER2"), 1u);
  EXPECT_EQ(log.count("RLASER"), 1u);
  EXPECT_EQ(log.odom.size(), 1u);
  EXPECT_EQ(log.params.size(), 2u);
  EXPECT_EQ(log.params[0].first, "robot_front_laser_max");
  EXPECT_EQ(log.params[0].second, "80.99");
  EXPECT_EQ(log.params[1].second, "on");
  EXPECT_EQ(log.neff_records, 1u);
  EXPECT_EQ(log.other_records, 1u);
  EXPECT_EQ(log.comment_lines, 1u);
  EXPECT_EQ(log.lines, 12u);  // the blank line counts, the final newline does not start a line

  const CarmenOdom& o = log.odom[0];
  EXPECT_EQ(o.line, 4u);
  EXPECT_DOUBLE_EQ(o.pose.x, 0.5);
  EXPECT_DOUBLE_EQ(o.pose.y, -0.25);
  EXPECT_DOUBLE_EQ(o.tv, 0.3);
  EXPECT_DOUBLE_EQ(o.rv, 0.02);
  EXPECT_DOUBLE_EQ(o.ipc_timestamp, 976052857.337284);

  const CarmenScan& f = log.scans[0];
  EXPECT_EQ(f.line, 5u);
  EXPECT_EQ(f.index, 0u);
  EXPECT_EQ(f.ranges.size(), 180u);
  EXPECT_FLOAT_EQ(f.ranges[17], 1.5f);
  EXPECT_NEAR(f.angle_min, -M_PI / 2, 1e-6);
  EXPECT_NEAR(f.angle_increment, M_PI / 180, 1e-7);
  EXPECT_FLOAT_EQ(f.max_range, 80.99f);  // from PARAM robot_front_laser_max
  EXPECT_DOUBLE_EQ(f.pose.theta, 0.5);
  EXPECT_DOUBLE_EQ(f.odom.x, 1.1);
  EXPECT_DOUBLE_EQ(f.ipc_timestamp, 100.25);
  EXPECT_DOUBLE_EQ(f.logger_timestamp, 0.25);
  // 361 readings: 0.5° from -90° to +90° inclusive.
  EXPECT_NEAR(log.scans[1].angle_increment, M_PI / 360, 1e-7);
  EXPECT_NEAR(log.scans[1].angle_min + 360 * log.scans[1].angle_increment, M_PI / 2, 1e-5);

  const CarmenScan& r = log.scans[2];
  EXPECT_EQ(r.type, "ROBOTLASER1");
  EXPECT_EQ(r.index, 2u);
  ASSERT_EQ(r.ranges.size(), 3u);
  EXPECT_FLOAT_EQ(r.ranges[2], 81.91f);
  EXPECT_FLOAT_EQ(r.angle_min, -1.570796f);
  EXPECT_FLOAT_EQ(r.angle_increment, 0.017453f);
  EXPECT_FLOAT_EQ(r.max_range, 81.9f);
  EXPECT_DOUBLE_EQ(r.pose.x, 0.1);    // laser pose
  EXPECT_DOUBLE_EQ(r.odom.theta, 1.3);  // robot pose
  EXPECT_DOUBLE_EQ(r.logger_timestamp, -0.055208);

  const CarmenScan& raw = log.scans[3];
  ASSERT_EQ(raw.ranges.size(), 4u);
  EXPECT_FLOAT_EQ(raw.angle_min, -2.0f);
  EXPECT_FLOAT_EQ(raw.max_range, 30.0f);
  EXPECT_DOUBLE_EQ(raw.ipc_timestamp, 55.5);

  // RLASER without PARAM robot_rear_laser_max: the largest RLASER reading.
  EXPECT_FLOAT_EQ(log.scans[4].max_range, 4.0f);
}

TEST(CarmenLog, ToLaserScan) {
  CarmenLog log;
  std::string err;
  ASSERT_TRUE(parse(kRobotLaser, &log, &err)) << err;
  const hal::LaserScan m = to_laser_scan(log.scans[0], 123456789ull);
  EXPECT_EQ(m.timestamp_ns, 123456789ull);
  EXPECT_EQ(m.beam_count, 3u);
  EXPECT_FLOAT_EQ(m.ranges[1], 2.0f);
  EXPECT_FLOAT_EQ(m.angle_min, -1.570796f);
  EXPECT_FLOAT_EQ(m.range_max, 81.9f);
  EXPECT_GE(m.ranges[2], m.range_max);  // stored "no return" reads as no return
}

struct BadCase {
  const char* name;
  std::string text;
  const char* expect;  // substring of the error
};

TEST(CarmenLog, MalformedLinesAreErrorsNamingFileAndLine) {
  std::string truncated = flaser_line(180);
  truncated.resize(truncated.size() / 2);
  truncated += "\n";
  std::string extra_beam = "FLASER 180";
  for (int i = 0; i < 181; ++i) extra_beam += " 1.0";
  extra_beam += " 0 0 0 0 0 0 1.0 h 1.0\n";
  std::string few_beams = "FLASER 180";
  for (int i = 0; i < 179; ++i) few_beams += " 1.0";
  few_beams += " 0 0 0 0 0 0 1.0 h 1.0\n";
  const BadCase cases[] = {
      {"truncated line", truncated, "truncated"},
      {"one beam too many", extra_beam, "expected 191 fields, found 192"},
      {"one beam too few", few_beams, "expected 191 fields, found 190"},
      {"non-numeric range", flaser_line(180, "1.5x"), "not a finite number"},
      {"NaN range", flaser_line(180, "nan"), "not a finite number"},
      {"inf range", flaser_line(180, "inf"), "not a finite number"},
      {"negative range", flaser_line(180, "-1.0"), "negative"},
      {"non-numeric count", "FLASER abc 1 2\n", "num_readings"},
      {"negative count", "FLASER -5 1 2\n", "num_readings"},
      {"ODOM too short", "ODOM 1 2 3 0 0 0 5.0 host\n", "ODOM: expected 10 fields, found 9"},
      {"ODOM NaN", "ODOM 1 nan 3 0 0 0 5.0 host 5.0\n", "not a finite number"},
      {"ODOM bad timestamp", "ODOM 1 2 3 0 0 0 5.0.1 host 5.0\n", "ipc_timestamp"},
      {"ROBOTLASER1 truncated", "ROBOTLASER1 0 -1.5 3.14 0.017 81.9 0.01 0 3 1.0 2.0\n", "truncated"},
      {"ROBOTLASER1 zero max range", "ROBOTLASER1 0 -1.5 3.14 0.017 0 0.01 0 1 1.0 0 0 0 0 0 0 0 0 0 0 0 0 1 h 1\n",
       "maximum_range"},
      {"RAWLASER remission count", "RAWLASER1 0 -1 2 0.5 30 0.01 0 2 1 2 5 1 1 h 1\n", "remissions"},
      {"garbage", "12 34 56\n", "not a CARMEN message"},
      {"binary", std::string("FLA\x01\x02" "SER 3\n"), "not a CARMEN message"},
      {"PARAM without value", "PARAM lonely\n", "PARAM"},
      {"NEFF non-numeric", "NEFF x\n", "NEFF"},
      // Issue 13: finite but impossible values were accepted (1e300 m became an infinite float range,
      // resolution 0 put every beam on one bearing, 1e300 s timestamps replayed forever).
      {"ROBOTLASER1 max range 1e300", robot_laser("81.900000", "1e300"), "field 6 (maximum_range) is '1e300'"},
      {"ROBOTLASER1 max range 5 km", robot_laser("81.900000", "5000"), "beyond the plausible 1000 m"},
      {"ROBOTLASER1 zero resolution", robot_laser("0.017453", "0"), "field 5 (angular_resolution) is '0': must be positive"},
      {"ROBOTLASER1 negative resolution", robot_laser("0.017453", "-0.017453"), "angular_resolution"},
      {"ROBOTLASER1 beams over a turn", robot_laser("0.017453", "4.0"), "span more than a full turn"},
      {"ROBOTLASER1 start angle", robot_laser("-1.570796", "-100"), "field 3 (start_angle)"},
      {"ROBOTLASER1 timestamp 1e300", robot_laser("1232658478.161285", "1e300"), "(ipc_timestamp) is '1e300' s"},
      {"FLASER logger timestamp 1e300", flaser_line(180).replace(flaser_line(180).size() - 5, 4, "1e300"),
       "(logger_timestamp) is '1e300' s, outside the plausible ±1e+10 s"},
      {"FLASER range 2 km", flaser_line(180, "2000"), "beyond the plausible 1000 m"},
      {"FLASER pose 1e300", "FLASER 1 1.0 1e300 2.0 0.5 1.1 2.1 0.6 100.25 host 0.25\n", "(x y theta) is '1e300' m"},
      {"ODOM tv 1e300", "ODOM 1 2 3 1e300 0 0 5.0 host 5.0\n", "(tv) is '1e300' m/s"},
      {"PARAM laser max 1e300", "PARAM robot_front_laser_max 1e300 host 0.5\n",
       "robot_front_laser_max '1e300' is not a plausible maximum range"},
      {"line over the cap", "FLASER 3 " + std::string(5000, ' ') + "1 2 3 0 0 0 0 0 0 1 h 1\n",
       "bytes, longer than the limit of 4096"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string text = "# header\n" + flaser_line(180) + c.text + flaser_line(180);
    CarmenLog log;
    std::string err;
    EXPECT_FALSE(parse(text, &log, &err));
    EXPECT_NE(err.find("mem.clf:3: "), std::string::npos) << err;
    EXPECT_NE(err.find(c.expect), std::string::npos) << err;
    EXPECT_EQ(log.scans.size(), 1u);  // what was read before the bad line

    // skip_bad_lines: the line is counted and reported, the rest is read.
    CarmenLog skipped;
    std::string err2;
    EXPECT_TRUE(parse(text, &skipped, &err2, /*skip=*/true)) << err2;
    EXPECT_EQ(skipped.bad_lines, 1u);
    ASSERT_EQ(skipped.bad_line_messages.size(), 1u);
    EXPECT_EQ(skipped.bad_line_messages[0], err);
    EXPECT_EQ(skipped.scans.size(), 2u);
    EXPECT_EQ(skipped.scans[1].line, 4u);
    // A dropped scan line still counts, so indices keep matching the file's scan ordinals.
    const bool bad_was_scan = std::string(c.text).rfind("FLASER", 0) == 0 || std::string(c.text).rfind("ROBOTLASER1", 0) == 0 ||
                              std::string(c.text).rfind("RAWLASER", 0) == 0;
    EXPECT_EQ(skipped.scans[1].index, bad_was_scan ? 2u : 1u);
  }
}

// Random byte-level corruption (flips, deletions, insertions, truncation) of a valid log: the reader
// never crashes or hangs, and either succeeds or names the file and a line that exists.
TEST(CarmenLog, RandomCorruptionIsAnErrorOrParses) {
  const std::string good = "# h\nPARAM a 1 0 h 0\nODOM 1 2 3 0 0 0 5.0 h 5.0\n" + flaser_line(10) +
                           std::string(kRobotLaser) + "RAWLASER1 0 -1 2 0.5 30 0.01 0 2 1 2 1 7 55.5 host 1.5\n" +
                           flaser_line(12);
  const size_t good_lines = 7;
  std::mt19937 rng(12345);
  const char alphabet[] = " \n\t.-+0123456789eEnaFLSRODMx#\0\xff";
  size_t failures = 0;
  for (int iter = 0; iter < 3000; ++iter) {
    std::string t = good;
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int k = 0; k < edits; ++k) {
      const size_t pos = rng() % t.size();
      const char c = alphabet[rng() % (sizeof(alphabet) - 1)];
      switch (rng() % 4) {
        case 0: t[pos] = c; break;
        case 1: t.erase(pos, 1 + rng() % 8); break;
        case 2: t.insert(pos, 1, c); break;
        default: t.resize(pos); break;
      }
      if (t.empty()) t = "x";
    }
    CarmenLog log;
    std::string err;
    if (!parse(t, &log, &err)) {
      ++failures;
      ASSERT_EQ(err.rfind("mem.clf:", 0), 0u) << err;
      const size_t line = std::stoul(err.substr(8));
      ASSERT_GE(line, 1u);
      ASSERT_LE(line, good_lines + 40) << err;
    } else {
      for (const auto& sc : log.scans) {
        for (float r : sc.ranges) ASSERT_TRUE(std::isfinite(r) && r >= 0.0f);
      }
    }
    CarmenLog skipped;
    ASSERT_TRUE(parse(t, &skipped, &err, /*skip=*/true)) << err;
  }
  EXPECT_GT(failures, 1000u);  // most corruptions are detected
}

TEST(CarmenLog, MaxScansStopsEarly) {
  std::string text;
  for (int i = 0; i < 10; ++i) text += flaser_line(4);
  CarmenLog log;
  std::string err;
  CarmenReadOptions o;
  o.max_scans = 3;
  ASSERT_TRUE(parse_carmen_log("m", text.data(), text.size(), o, &log, &err)) << err;
  EXPECT_EQ(log.scans.size(), 3u);
}

TEST(CarmenLog, MissingFileIsAnError) {
  CarmenLog log;
  std::string err;
  EXPECT_FALSE(read_carmen_log("/nonexistent/dir/x.clf", {}, &log, &err));
  EXPECT_NE(err.find("/nonexistent/dir/x.clf"), std::string::npos) << err;
  EXPECT_NE(err.find("cannot open"), std::string::npos) << err;
  const std::string dir = ::testing::TempDir();
  EXPECT_FALSE(read_carmen_log(dir, {}, &log, &err));
  EXPECT_NE(err.find("not a regular file"), std::string::npos) << err;
  // An empty file is a valid, empty log; a bare gzip magic is a corrupt stream.
  const std::string empty = temp_path("carmen", "empty.clf"), magic = temp_path("carmen", "magic.gz");
  write_text(empty, "");
  write_text(magic, "\x1f\x8b");
  EXPECT_TRUE(read_carmen_log(empty, {}, &log, &err)) << err;
  EXPECT_TRUE(log.scans.empty());
  EXPECT_FALSE(read_carmen_log(magic, {}, &log, &err));
  EXPECT_NE(err.find("gzip"), std::string::npos) << err;
  std::remove(empty.c_str());
  std::remove(magic.c_str());
}

TEST(CarmenLog, PlainAndGzipReadAlike) {
  const std::string text = "# t\n" + flaser_line(180) + "ODOM 1 2 3 0 0 0 5.0 host 5.0\n" + flaser_line(360);
  const std::string plain = temp_path("carmen", "a.clf"), gz = temp_path("carmen", "a.clf.gz");
  write_text(plain, text);
  write_gz(gz, text);
  CarmenLog a, b;
  std::string err;
  ASSERT_TRUE(read_carmen_log(plain, {}, &a, &err)) << err;
  ASSERT_TRUE(read_carmen_log(gz, {}, &b, &err)) << err;
  ASSERT_EQ(a.scans.size(), 2u);
  ASSERT_EQ(b.scans.size(), 2u);
  EXPECT_EQ(a.scans[1].ranges, b.scans[1].ranges);
  EXPECT_EQ(b.odom.size(), 1u);
  EXPECT_EQ(b.path, gz);
  std::remove(plain.c_str());
  std::remove(gz.c_str());
}

TEST(CarmenLog, CorruptGzipIsAnError) {
  std::string text;
  for (int i = 0; i < 200; ++i) text += flaser_line(180, std::to_string(i * 0.01));
  const std::string gz = temp_path("carmen", "c.clf.gz");
  write_gz(gz, text);
  std::string bytes;
  {
    std::ifstream f(gz, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(f), {});
  }
  ASSERT_GT(bytes.size(), 200u);
  {  // truncated stream
    write_text(gz, bytes.substr(0, bytes.size() / 2));
    CarmenLog log;
    std::string err;
    EXPECT_FALSE(read_carmen_log(gz, {}, &log, &err));
    EXPECT_NE(err.find(gz), std::string::npos) << err;
    EXPECT_NE(err.find("gzip"), std::string::npos) << err;
  }
  {  // flipped bytes in the deflate data
    std::string bad = bytes;
    for (size_t i = 100; i < 140; ++i) bad[i] = static_cast<char>(bad[i] ^ 0x5a);
    write_text(gz, bad);
    CarmenLog log;
    std::string err;
    EXPECT_FALSE(read_carmen_log(gz, {}, &log, &err));
    EXPECT_NE(err.find(gz), std::string::npos) << err;
  }
  {  // CRC of the trailer wrong
    std::string bad = bytes;
    bad[bad.size() - 6] = static_cast<char>(bad[bad.size() - 6] ^ 0xff);
    write_text(gz, bad);
    CarmenLog log;
    std::string err;
    EXPECT_FALSE(read_carmen_log(gz, {}, &log, &err));
    EXPECT_NE(err.find("gzip"), std::string::npos) << err;
  }
  std::remove(gz.c_str());
}

// gzip of `repeat` copies of `chunk`, compressed in memory (a bomb when the chunk is newlines).
std::string gzip_of(const std::string& chunk, size_t repeat = 1) {
  z_stream zs{};
  EXPECT_EQ(deflateInit2(&zs, 9, Z_DEFLATED, 15 + 16, 9, Z_DEFAULT_STRATEGY), Z_OK);
  std::string out;
  char buf[1 << 16];
  for (size_t i = 0; i <= repeat; ++i) {
    const bool last = i == repeat;
    zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(chunk.data()));
    zs.avail_in = last ? 0 : static_cast<uInt>(chunk.size());
    do {
      zs.next_out = reinterpret_cast<Bytef*>(buf);
      zs.avail_out = sizeof(buf);
      deflate(&zs, last ? Z_FINISH : Z_NO_FLUSH);
      out.append(buf, sizeof(buf) - zs.avail_out);
    } while (zs.avail_out == 0);
  }
  deflateEnd(&zs);
  return out;
}

// Issue 13: a 13 MB gzip of 3 GB of newlines was inflated whole. Here 64 MiB of newlines (about 64 KB
// compressed) against an 8 MiB cap: the read stops at the cap with a message naming the file and the
// limit, quickly and without holding the 64 MiB.
TEST(CarmenLog, GzipBombIsStoppedAtTheCap) {
  const std::string bomb = gzip_of(std::string(1 << 20, '\n'), 64);
  ASSERT_LT(bomb.size(), 1u << 20);
  const std::string gz = temp_path("carmen", "bomb.clf.gz");
  write_text(gz, bomb);
  CarmenReadOptions o;
  o.max_bytes = 8u << 20;
  CarmenLog log;
  std::string err;
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(read_carmen_log(gz, o, &log, &err));
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 10.0);
  EXPECT_NE(err.find(gz + ": inflates to more than 8 MiB"), std::string::npos) << err;
  EXPECT_NE(err.find("--max-log-mib"), std::string::npos) << err;
  // The default cap is finite and above every real log (≤ 18 MB inflated).
  EXPECT_EQ(CarmenReadOptions{}.max_bytes, kDefaultMaxLogBytes);
  EXPECT_GE(kDefaultMaxLogBytes, 256u << 20);
  EXPECT_LT(kDefaultMaxLogBytes, 4ull << 30);
  // A plain file over the cap is refused by its size, before it is read.
  const std::string plain = temp_path("carmen", "big.clf");
  write_text(plain, std::string(2 << 20, '\n'));
  o.max_bytes = 1u << 20;
  EXPECT_FALSE(read_carmen_log(plain, o, &log, &err));
  EXPECT_NE(err.find("more than the limit of 1048576 bytes (1 MiB)"), std::string::npos) << err;
  std::remove(gz.c_str());
  std::remove(plain.c_str());
}

// Issue 13: bytes after the end of the gzip stream were silently ignored (zlib's gzread). Further
// gzip members are data (gzip -d concatenates them); anything else is an error.
TEST(CarmenLog, TrailingGarbageAfterGzipIsAnError) {
  const std::string a = flaser_line(180), b = "ODOM 1 2 3 0 0 0 5.0 host 5.0\n";
  const std::string gz = temp_path("carmen", "t.clf.gz");
  CarmenLog log;
  std::string err;
  write_text(gz, gzip_of(a) + gzip_of(b));
  ASSERT_TRUE(read_carmen_log(gz, {}, &log, &err)) << err;
  EXPECT_EQ(log.scans.size(), 1u);
  EXPECT_EQ(log.odom.size(), 1u);
  const std::string good = gzip_of(a);
  for (const std::string& tail : {std::string("garbage\n"), std::string(1, '\0'), std::string("\x1f")}) {
    write_text(gz, good + tail);
    EXPECT_FALSE(read_carmen_log(gz, {}, &log, &err)) << tail.size();
    EXPECT_NE(err.find(gz + ": " + std::to_string(tail.size()) + " bytes of trailing garbage after the gzip stream"),
              std::string::npos)
        << err;
    EXPECT_NE(err.find("from byte " + std::to_string(good.size())), std::string::npos) << err;
  }
  std::remove(gz.c_str());
}

TEST(CarmenLog, FifoAndDeviceAreRefusedWithoutBlocking) {
  const std::string fifo = temp_path("carmen", "fifo.clf");
  std::remove(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  CarmenLog log;
  std::string err;
  EXPECT_FALSE(read_carmen_log(fifo, {}, &log, &err));
  EXPECT_NE(err.find(fifo + ": not a regular file (a FIFO)"), std::string::npos) << err;
  EXPECT_FALSE(read_carmen_log("/dev/zero", {}, &log, &err));
  EXPECT_NE(err.find("character device"), std::string::npos) << err;
  std::remove(fifo.c_str());
}

TEST(CarmenLog, WriteReadRoundTripIsExact) {
  CarmenLog log;
  log.params = {{"robot_front_laser_max", "81.83"}, {"robot_use_laser", "on"}};
  for (int i = 0; i < 5; ++i) {
    CarmenOdom o;
    o.pose = fw::Se2d(0.1 * i + 1e-7, -0.3 * i, 0.123456789 * i);
    o.tv = 0.25;
    o.rv = -0.01;
    o.ipc_timestamp = 976052857.337284 + i;
    o.logger_timestamp = 0.000246 + i;
    log.odom.push_back(o);
    CarmenScan s;
    s.type = "FLASER";
    s.ranges.resize(180);
    for (int k = 0; k < 180; ++k) s.ranges[k] = 0.01f * static_cast<float>(k + i) + 1.0f / 3.0f;
    s.pose = fw::Se2d(1.0 / 3.0, 2.0, -3.0);
    s.odom = fw::Se2d(1.0 / 7.0, -2.5, 3.1);
    s.ipc_timestamp = 976052857.5 + i;
    s.logger_timestamp = 0.5 + i;
    log.scans.push_back(s);
  }
  CarmenScan rl;  // a ROBOTLASER1 record too
  rl.type = "ROBOTLASER1";
  rl.angle_min = -1.570796f;
  rl.angle_increment = 0.017453f;
  rl.max_range = 81.9f;
  rl.ranges = {1.0f, 2.5f, 81.91f};
  rl.pose = fw::Se2d(1, 2, 3);
  rl.odom = fw::Se2d(4, 5, 6);
  rl.ipc_timestamp = 1232658478.161285;
  rl.logger_timestamp = -0.055208;
  log.scans.push_back(rl);
  for (const char* ext : {".clf", ".clf.gz"}) {
    SCOPED_TRACE(ext);
    const std::string path = temp_path("carmen", std::string("rt") + ext);
    std::string err;
    ASSERT_TRUE(write_carmen_log(path, log, {}, &err)) << err;
    CarmenLog back;
    ASSERT_TRUE(read_carmen_log(path, {}, &back, &err)) << err;
    ASSERT_EQ(back.scans.size(), log.scans.size());
    ASSERT_EQ(back.odom.size(), log.odom.size());
    EXPECT_EQ(back.params, log.params);
    for (size_t i = 0; i < log.scans.size(); ++i) {
      EXPECT_EQ(back.scans[i].type, log.scans[i].type);
      EXPECT_EQ(back.scans[i].ranges, log.scans[i].ranges);  // bit-exact
      EXPECT_EQ(back.scans[i].pose.x, log.scans[i].pose.x);
      EXPECT_EQ(back.scans[i].odom.theta, log.scans[i].odom.theta);
      EXPECT_EQ(back.scans[i].ipc_timestamp, log.scans[i].ipc_timestamp);
      EXPECT_EQ(back.scans[i].logger_timestamp, log.scans[i].logger_timestamp);
    }
    EXPECT_EQ(back.scans.back().angle_min, rl.angle_min);
    EXPECT_EQ(back.scans.back().angle_increment, rl.angle_increment);
    EXPECT_EQ(back.scans.back().max_range, rl.max_range);
    EXPECT_EQ(back.scans.back().pose.theta, 3.0);
    for (size_t i = 0; i < log.odom.size(); ++i) {
      EXPECT_EQ(back.odom[i].pose.x, log.odom[i].pose.x);
      EXPECT_EQ(back.odom[i].pose.theta, log.odom[i].pose.theta);
      EXPECT_EQ(back.odom[i].tv, log.odom[i].tv);
      EXPECT_EQ(back.odom[i].ipc_timestamp, log.odom[i].ipc_timestamp);
    }
    // Odometry and scans interleaved by timestamp (records created in memory have line 0).
    EXPECT_LT(back.odom[1].line, back.scans[1].line);
    EXPECT_GT(back.odom[1].line, back.scans[0].line);
    std::remove(path.c_str());
  }
}

TEST(CarmenLog, WriteToBadPathIsAnError) {
  CarmenLog log;
  std::string err;
  EXPECT_FALSE(write_carmen_log("/nonexistent/dir/out.clf", log, {}, &err));
  EXPECT_NE(err.find("/nonexistent/dir/out.clf"), std::string::npos);
}

}  // namespace
}  // namespace sim
