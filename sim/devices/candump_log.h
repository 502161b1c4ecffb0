// can-utils log format (candump -L / canplayer): "(1700000000.123456) vcan0 123#DEADBEEF",
// CAN FD "123##<flags hex digit><data>", extended IDs with 8 hex digits, error frames with
// CAN_ERR_FLAG (0x20000000) in an 8-digit ID. Parse errors name the line.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "hal/can_bus.h"

namespace sim {

constexpr std::uint32_t kCanErrFlag = 0x20000000u;  // as in <linux/can.h>; error frames in logs
constexpr std::uint32_t kCanErrBusOff = 0x40u;      // CAN_ERR_BUSOFF

struct CanLogLine {
  double t = 0;
  std::string iface;
  hal::CanFrame frame;
  bool error_frame = false;  // frame.id then holds the error class bits (without the flag)
};

std::string format_candump_line(double t, const std::string& iface, const hal::CanFrame& f);
std::string format_error_frame_line(double t, const std::string& iface, std::uint32_t err_class);
bool parse_candump_line(const std::string& line, CanLogLine* out, std::string* error);
// Reads a whole log ("-" = stdin not supported); error "path:line: problem".
bool read_candump_log(const std::string& path, std::vector<CanLogLine>* out, std::string* error);

}  // namespace sim
