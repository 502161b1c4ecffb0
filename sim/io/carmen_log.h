// CARMEN laser-log reader and writer (host tool). Reads the record types present in the Radish /
// Freiburg benchmark logs (../shared/data/README.md): FLASER, RLASER, ROBOTLASER1, RAWLASER1..4,
// ODOM, PARAM, NEFF (counted only), '#' comments; other message names (SYNC, TRUEPOS, GPS…) are
// counted in `other_records` and otherwise ignored. Plain text or gzip (zlib; detected by magic).
//
// Strict by default: a malformed line (wrong field count for the beam count it declares, non-numeric
// or non-finite number, negative range, truncated line) makes read_carmen_log return false with an
// error "path:line: problem" (also: a line longer than max_line_bytes, a value outside the plausible
// bounds below, an angular resolution ≤ 0 or a scan spanning more than a full turn). With
// skip_bad_lines the line is dropped, counted in bad_lines and its message kept in bad_line_messages
// (first 100). A missing file, a path that is not a regular file, a corrupt gzip stream, trailing bytes
// after it and more than max_bytes of data are always errors.
//
// Scan geometry: ROBOTLASER1 / RAWLASER carry start angle, resolution and maximum range. FLASER /
// RLASER carry none, so it follows from the beam count n (README): n even → spacing π/n from -π/2
// (180 → 1°, 360 → 0.5°), n odd → spacing π/(n-1) from -π/2 to +π/2 inclusive (181, 361). Their
// max_range is the PARAM robot_front_laser_max / robot_rear_laser_max when the log has it, else the
// largest reading of that record type in the log (the loggers store "no return" as the sensor
// maximum: 81.83 m intel, 81.91 m fr079, 50.0 m aces).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "firmware/base/se2.h"
#include "hal/msg/laser_scan.h"

namespace sim {

struct CarmenScan {
  size_t line = 0;   // 1-based line number in the file
  size_t index = 0;  // 0-based among scan records of the file (= flaser_index of *.corrected-poses.txt);
                     // malformed scan lines dropped by skip_bad_lines still count, so indices of the
                     // following scans keep matching flaser_index (scans[i].index == i unless lines were dropped)
  std::string type;  // "FLASER", "RLASER", "ROBOTLASER1", "RAWLASER1".."RAWLASER4"
  double ipc_timestamp = 0, logger_timestamp = 0;
  float angle_min = 0, angle_increment = 0, max_range = 0;
  std::vector<float> ranges;
  fw::Se2d pose;  // FLASER/RLASER: first triple; ROBOTLASER1: laser pose; RAWLASER: zero
  fw::Se2d odom;  // FLASER/RLASER: odom triple; ROBOTLASER1: robot pose; RAWLASER: zero
};

struct CarmenOdom {
  size_t line = 0;
  fw::Se2d pose;
  double tv = 0, rv = 0, ipc_timestamp = 0, logger_timestamp = 0;
};

struct CarmenLog {
  std::string path;
  std::vector<CarmenScan> scans;
  std::vector<CarmenOdom> odom;
  std::vector<std::pair<std::string, std::string>> params;
  size_t bad_lines = 0;
  std::vector<std::string> bad_line_messages;
  // Additional counters (beyond interfaces.md §1).
  size_t lines = 0;          // lines read
  size_t comment_lines = 0;  // lines starting with '#'
  size_t neff_records = 0;   // NEFF lines (corrected logs)
  size_t other_records = 0;  // well-formed lines of message types not listed above
  size_t count(const std::string& type) const;  // scan records of that type ("FLASER", …)
};

// Caps against hostile or broken files (the logs of ../shared/data inflate to ≤ 18 MB with lines of
// ≤ 2.3 kB). Over the byte cap the read fails with a message naming the file and the cap; a longer line
// is a malformed line (file:line).
constexpr std::uint64_t kDefaultMaxLogBytes = std::uint64_t(512) << 20;  // inflated (or plain) size
constexpr size_t kDefaultMaxLineBytes = size_t(1) << 20;

// Plausible values: a field beyond them is malformed (file:line, field), even though finite — a
// maximum range of 1e300 m would become an infinite float, a timestamp of 1e300 s a replay that never
// ends. The bounds are far outside anything real (Unix time in 2286, 1000 km, a 1 km laser).
constexpr double kMaxAbsTimestampS = 1e10;
constexpr double kMaxAbsPositionM = 1e6;
constexpr double kMaxAbsAngleRad = 1e4;
constexpr double kMaxLaserRangeM = 1000.0;
constexpr double kMaxAbsSpeed = 1000.0;  // ODOM tv (m/s), rv (rad/s)

struct CarmenReadOptions {
  bool skip_bad_lines = false;
  size_t max_scans = 0;  // 0 = all; reading stops after this many scan records
  std::uint64_t max_bytes = kDefaultMaxLogBytes;  // file size, and inflated size of a .gz
  size_t max_line_bytes = kDefaultMaxLineBytes;
};

// Reads a CARMEN log (plain or .gz). On failure returns false and sets *error to "path:line: …"
// (or "path: …" for file-level problems); *out then holds what was read before the error.
bool read_carmen_log(const std::string& path, const CarmenReadOptions& options, CarmenLog* out,
                     std::string* error);

// Parses a whole log already in memory (same rules; `name` is used in messages).
bool parse_carmen_log(const std::string& name, const char* data, size_t size, const CarmenReadOptions& options,
                      CarmenLog* out, std::string* error);

// Converts to the HAL message. Readings at/above max_range are "no return" (range_max = max_range),
// range_min = 0.01 m (the logs' resolution; 0 means "no reading" on SICK). Beams beyond
// hal::LaserScan::kMaxBeams are dropped (none of the logs in ../shared/data exceed 361). scan_id = index.
hal::LaserScan to_laser_scan(const CarmenScan& scan, uint64_t timestamp_ns);

// Writer for replay tools: FLASER and ODOM lines in the classic format (ranges with 3 decimals,
// poses with 6, timestamps with 6 decimals), "#" header, PARAMs first. Records are written in
// timestamp-agnostic file order: all scans and odometry merged by line number (so a log read and
// written keeps its order). Returns false with a message naming the path on I/O failure.
struct CarmenWriteOptions {
  bool gzip = false;        // also implied by a path ending in ".gz"
  std::string hostname = "nohost";
};
bool write_carmen_log(const std::string& path, const CarmenLog& log, const CarmenWriteOptions& options,
                      std::string* error);

// Reads a whole regular file (plain or gzip, detected by the 1f 8b magic; every gzip member, and an
// error for anything after the last) into memory; at most max_bytes (default kDefaultMaxLogBytes) of
// file and of inflated data.
bool read_file_maybe_gz(const std::string& path, std::string* data, std::string* error);
bool read_file_maybe_gz(const std::string& path, std::uint64_t max_bytes, std::string* data, std::string* error);

}  // namespace sim
