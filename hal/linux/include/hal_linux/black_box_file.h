// Writes the black box (hal_can/black_box.h, hal_serial/serial_black_box.h) as one log: to
// PATH.tmp, then renamed over PATH, so a reader never sees half a file and a failed write never
// destroys the last good dump. CAN frames are candump lines, serial chunks "... rx laser HEX"
// lines (hal/serial/README.md "Black box"); a board with a serial laser and CAN odometry writes both
// rings into the one file, merged by time (CAN first at equal times), so one file replays the run.
// No heap: lines are formatted into a fixed buffer and written with write(2). Errors name the path.
#pragma once

#include <cstddef>

#include "firmware/base/status.h"
#include "hal_can/black_box.h"
#include "hal_serial/serial_black_box.h"

namespace hal_linux {

// `written` (may be null): bytes of the file.
fw::Status write_black_box_file(const hal_can::BlackBox& box, const char* path, std::size_t* written);
// Both rings, merged by time; either may be null or empty.
fw::Status write_black_box_file(const hal_can::BlackBox* can, const hal_serial::SerialBlackBox* serial,
                                const char* path, std::size_t* written);

}  // namespace hal_linux
