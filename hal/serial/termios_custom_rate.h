// A bit rate without a Bxxx constant (RPLIDAR A3/S1: 256000 Bd) set through the kernel's termios2
// interface (BOTHER + c_ispeed/c_ospeed). <asm/termbits.h> clashes with glibc's <termios.h>, so
// this lives in its own translation unit, kept out of the unity build (CMakeLists.txt).
#pragma once

#include <cstdint>

namespace hal_serial {

// 0 on success, else the errno of the refusal; *actual receives the rate read back.
int set_custom_rate(int fd, std::uint32_t baud, std::uint32_t* actual);

}  // namespace hal_serial
