// Inside hal/can: the record framing shared by the encoders of codec.cpp and command_codec.cpp.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/status.h"
#include "hal/can_bus.h"

namespace hal_can {

// Cuts a record payload of `parts` 7-byte parts into classic frames base_id+k = [tag][7 bytes] or
// one FD frame base_id|0x400 = [tag][payload]; errors name `what` and the capacity needed.
fw::Status emit_record(std::uint32_t base_id, std::size_t parts, std::uint8_t tag, const std::uint8_t* payload, bool fd,
                       hal::CanFrame* out, std::size_t capacity, std::size_t* count, const char* what);

}  // namespace hal_can
