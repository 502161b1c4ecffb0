// Writes the black box (hal_can/black_box.h) as a candump log: to PATH.tmp, then renamed over PATH,
// so a reader never sees half a file and a failed write never destroys the last good dump. No
// heap: lines are formatted into a fixed buffer and written with write(2). Errors name the path.
#pragma once

#include <cstddef>

#include "firmware/base/status.h"
#include "hal_can/black_box.h"

namespace hal_linux {

// `written` (may be null): bytes of the file.
fw::Status write_black_box_file(const hal_can::BlackBox& box, const char* path, std::size_t* written);

}  // namespace hal_linux
