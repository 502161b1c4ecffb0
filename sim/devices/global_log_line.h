// The global search's lines of a black box (issue 60; hal_can/black_box.h, hal/can/README.md
// "Black box"): "(SEC.USEC) global take|drop SEC.USEC ROUNDS" — a robot with global_context =
// thread took (or dropped) the result of the job submitted at the second time, at the scan of the
// first, after ROUNDS pRANSAM rounds when its deadline stopped the search (0: not stopped).
#pragma once

#include <string>

#include "hal/msg/global_record.h"

namespace sim {

// A line whose second field is "global": for parse_global_log_line.
bool is_global_log_line(const std::string& line);
// false with *error naming the problem (the caller adds file and line): a bad stamp, verb or
// rounds, a field missing (a cut line) or one too many.
bool parse_global_log_line(const std::string& line, hal::GlobalRecord* out, std::string* error);

}  // namespace sim
