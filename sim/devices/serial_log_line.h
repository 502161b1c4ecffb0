// The serial lines of a black box (issue 60; hal_serial/serial_black_box.h, hal/serial/README.md
// "Black box"): "(SEC.USEC) rx|tx laser HEX" — a chunk the firmware read from / wrote to its laser
// port. A black box file mixes them with candump lines (the CAN ring of the same board);
// is_serial_log_line() tells them apart by the third field (a port, not ID#DATA).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace sim {

struct SerialLogLine {
  std::uint64_t t_ns = 0;  // exact to the µs
  bool tx = false;
  std::vector<std::uint8_t> bytes;
};

// A line whose third field is not a frame ("(T) rx laser ..."): a serial line, for parse_serial_log_line.
bool is_serial_log_line(const std::string& line);
// false with *error naming the problem (the caller adds file and line): a bad stamp, direction or
// port, odd or non-hex digits, no bytes or more than one ring entry's (64), trailing fields.
bool parse_serial_log_line(const std::string& line, SerialLogLine* out, std::string* error);

}  // namespace sim
