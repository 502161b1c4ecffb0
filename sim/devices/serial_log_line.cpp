#include "sim/devices/serial_log_line.h"

#include <cstdio>
#include <sstream>

#include "hal_serial/serial_black_box.h"

namespace sim {
namespace {

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

// "(SEC.USEC)" as integer ns: a double loses the µs of an epoch-sized stamp.
bool parse_stamp(const std::string& s, std::uint64_t* ns) {
  unsigned long long sec = 0, usec = 0;
  int used = 0;
  if (s.size() < 2 || s[1] < '0' || s[1] > '9' || s.find('.') == std::string::npos || s.size() != s.find('.') + 8 || std::sscanf(s.c_str(), "(%llu.%6llu)%n", &sec, &usec, &used) != 2 ||
      used != static_cast<int>(s.size())) {
    return false;
  }
  *ns = (sec * 1000000ull + usec) * 1000ull;
  return true;
}

}  // namespace

bool is_serial_log_line(const std::string& line) {
  std::istringstream in(line);
  std::string a, b, c;
  // A candump line's third field is ID#DATA; a serial line's is its port.
  return static_cast<bool>(in >> a >> b >> c) && c.find('#') == std::string::npos;
}

bool parse_serial_log_line(const std::string& line, SerialLogLine* out, std::string* error) {
  std::istringstream in(line);
  std::string stamp, dir, port, hex, extra;
  in >> stamp >> dir >> port >> hex;
  if (!parse_stamp(stamp, &out->t_ns)) {
    *error = "bad time stamp '" + stamp + "' (expected (SEC.USEC) with 6 digits of µs)";
    return false;
  }
  if (dir != "rx" && dir != "tx") {
    *error = "direction '" + dir + "' (expected rx or tx)";
    return false;
  }
  if (port != "laser") {
    *error = "port '" + port + "' (expected laser; or a CAN line cut before its '#'?)";
    return false;
  }
  if (in >> extra) {
    *error = "unexpected field '" + extra + "' after the bytes";
    return false;
  }
  if (hex.empty() || hex.size() % 2 != 0 || hex.size() > 2 * hal_serial::SerialBlackBox::kChunkBytes) {
    *error = std::to_string(hex.size()) + " hex digits (expected an even number, 2.." +
             std::to_string(2 * hal_serial::SerialBlackBox::kChunkBytes) + "; a cut line?)";
    return false;
  }
  out->tx = dir == "tx";
  out->bytes.resize(hex.size() / 2);
  for (std::size_t i = 0; i < out->bytes.size(); ++i) {
    const int hi = hex_value(hex[2 * i]), lo = hex_value(hex[2 * i + 1]);
    if (hi < 0 || lo < 0) {
      *error = "'" + hex.substr(2 * i, 2) + "' at byte " + std::to_string(i) + " is not hex";
      return false;
    }
    out->bytes[i] = static_cast<std::uint8_t>(hi << 4 | lo);
  }
  return true;
}

}  // namespace sim
