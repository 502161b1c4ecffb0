// Hokuyo SCIP 2.0 as a pure line parser/encoder (no I/O), after "Communication Protocol
// Specification for SCIP2.0 Standard", Hokuyo C-42-03320B (2006-2008), sections 6-8:
//   host → sensor: COMMAND [parameters] [;string] LF
//   sensor → host: echo LF | status(2) sum LF | [lines, each ending in its sum] LF | LF
// A line's sum is ((Σ bytes) & 0x3F) + 0x30 over the line before it (Sec. 7); in the answers of
// VV / PP / II the lines are "KEY:value;S" and the ';' is not summed (the document's PP example:
// "DMIN:20;4", sum of "DMIN:20" = '4'). A measurement answer (MD/MS/ME, status "99") has a time
// stamp line (4-character encoding, ms, 24 bits, wraps after 4.66 h) and then the data in lines of
// at most 64 characters, each with its own sum; values straddle the line breaks (Sec. 8.1).
// Data characters carry 6 bits each, 0x30 added (Sec. 6: 2-, 3- and 4-character encodings).
//
// The parser assembles whole answers. A line with a wrong sum, a line longer than any SCIP line,
// or an answer cut short (a new echo line in the middle of another answer: the device reset or
// the bytes were lost) drops that answer and is counted; it never stalls: every LF ends a line and
// every empty line ends an answer.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/status.h"

namespace hal_serial {

constexpr std::size_t kScipMaxLine = 128;  // data 64 + sum; PP/VV/II lines are shorter than 100
constexpr std::size_t kScipMaxSteps = 1081;  // hal::LaserScan::kMaxBeams (UTM-30LX, UST-10/20LX: 1081 steps)
// ME: 3 characters of range and 3 of intensity per step.
constexpr std::size_t kScipMaxData = 6 * kScipMaxSteps;

// ((Σ bytes) & 0x3F) + 0x30 (SCIP 2.0 Sec. 7).
char scip_sum(const char* s, std::size_t n);
// n characters (1..4) of the SCIP encoding → value; false for a character outside 0x30..0x6F.
bool scip_decode(const char* s, std::size_t n, std::uint32_t* out);
// value (its low 6·n bits) → n characters.
void scip_encode(std::uint32_t value, std::size_t n, char* out);

// One complete answer.
struct ScipResponse {
  char command[3] = {0};             // first two characters of the echo: "MD", "PP", ...
  char echo[kScipMaxLine + 1] = {0};  // the echo line as received (no LF)
  std::size_t echo_len = 0;
  char status[3] = {0};              // two characters: "00" accepted, "99" scan data, others errors
  bool has_timestamp = false;
  std::uint32_t timestamp_ms = 0;    // 24-bit sensor time of a measurement answer
  // Measurement answers: the data characters without line sums, concatenated. VV/PP/II: each
  // "KEY:value" line (without ";S") followed by '\n'. Other commands: each line without its sum.
  char data[kScipMaxData + 1] = {0};
  std::size_t data_len = 0;
};

struct ScipParserStats {
  std::uint32_t responses = 0;          // complete answers handed out
  std::uint32_t checksum_errors = 0;    // lines whose sum is wrong (their answer is dropped)
  std::uint32_t malformed = 0;          // answers dropped for a bad status line, overlong line or data overflow
  std::uint32_t truncated = 0;          // answers cut short by the echo of the next one
  std::uint32_t stray_lines = 0;        // empty lines outside an answer (line noise, a resync)
};

class ScipParser {
 public:
  // Takes bytes until an answer is complete; returns how many were taken (less than n when an
  // answer is waiting: call next(), then feed the rest).
  std::size_t feed(const std::uint8_t* bytes, std::size_t n);
  // The next complete answer; false when none is complete yet.
  bool next(ScipResponse* out);
  const ScipParserStats& stats() const { return stats_; }
  // The last non-empty line received (printable, for start-up error messages).
  const char* last_line() const { return last_line_; }
  void reset();

 private:
  void on_line();
  void begin(const char* line, std::size_t n);
  void on_status_line(const char* line, std::size_t n);
  void on_body_line(const char* line, std::size_t n);
  void drop(std::uint32_t* counter);
  void append(const char* s, std::size_t n);

  char line_[kScipMaxLine + 1] = {0};
  std::size_t line_len_ = 0;
  bool line_overlong_ = false;
  ScipResponse cur_;
  int cur_lines_ = 0;     // lines of the current answer so far (0: between answers)
  bool cur_bad_ = false;  // the current answer is already lost (drained to its empty line)
  bool ready_ = false;    // cur_ is complete and waiting for next()
  char last_line_[64] = {0};
  ScipParserStats stats_;
};

// The echo of MD/MS/ME: start step (4), end step (4), cluster count (2), scan interval (1),
// number / remaining scans (2), then an optional ";string".
struct ScipScanEcho {
  std::uint32_t start = 0, end = 0, cluster = 1, interval = 0, scans = 0;
};
bool parse_scip_scan_echo(const ScipResponse& r, ScipScanEcho* out);

// A decoded measurement answer. ranges_mm are raw: values below the sensor's DMIN are error
// codes (no echo, too near, ...), left to the driver.
struct ScipScan {
  ScipScanEcho echo;
  std::uint32_t count = 0;           // values (steps / cluster count)
  bool has_intensity = false;        // ME
  std::uint32_t timestamp_ms = 0;
  std::uint32_t ranges_mm[kScipMaxSteps] = {};
  std::uint32_t intensity[kScipMaxSteps] = {};
};
// MD/MS/ME answer with status "99" → values; errors name what does not fit (count, length).
fw::Status decode_scip_scan(const ScipResponse& r, ScipScan* out);

// PP answer (Sec. 8.12): model, DMIN/DMAX [mm], ARES (steps in 360°), AMIN/AMAX (first/last
// measurable step), AFRT (step on the front axis), SCAN (motor speed, rpm).
struct ScipParameters {
  char model[64] = {0};
  std::uint32_t dmin_mm = 0, dmax_mm = 0, ares = 0, amin = 0, amax = 0, afrt = 0, scan_rpm = 0;
};
fw::Status decode_scip_parameters(const ScipResponse& r, ScipParameters* out);
// "KEY:value" of a VV/PP/II answer into out (cap bytes, NUL-terminated); false if absent.
bool scip_info_value(const ScipResponse& r, const char* key, char* out, std::size_t cap);

// Device side (the device model, tests): writes an answer. Each returns the bytes written, 0 if it
// does not fit. `echo` is the echo line (without LF).
std::size_t encode_scip_status(const char* echo, const char* status, char* out, std::size_t cap);
// KEY:value lines of VV/PP/II after the echo and status "00".
std::size_t encode_scip_info(const char* echo, const char* const* lines, std::size_t n_lines, char* out,
                             std::size_t cap);
// A measurement answer: echo, "99", time stamp, data in 64-character lines with sums, LF LF.
// chars 2 (MS) or 3 (MD; ME: intensity after each range).
std::size_t encode_scip_scan(const char* echo, std::uint32_t timestamp_ms, const std::uint32_t* ranges_mm,
                             const std::uint32_t* intensity, std::size_t count, std::size_t chars, char* out,
                             std::size_t cap);

}  // namespace hal_serial
