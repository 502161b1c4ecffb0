// The CAN decoder fuzz input: a sequence of operations, shared by the harness (fuzz_can_decoder.cpp)
// and the seed generator (fuzz_seeds.cpp). The "synthetic scan" operation lets the fuzzer reach the
// decoder past the end-of-scan CRC: the harness cuts the fuzzed start payload and readings into
// frames and computes the CRC the sender would, so impossible content arrives intact and must be
// refused by the geometry checks, not by luck of a CRC mismatch.
#pragma once

#include <cstdint>

namespace fuzz {

enum CanOp : std::uint8_t {
  kCanRawFrame = 0,   // u16 id, u8 flags (1 fd, 2 extended, 4 brs), u8 len, len bytes, u16 dt_us
  kCanScan = 1,       // u8 flags (1 fd, bits 1..3 mutation), u8 mutation arg, 28 start bytes,
                      // beams × u16 range codes (beams = start[2..3], at most kMaxBeams + 8)
  kCanOdometry = 2,   // 5 × f32 (x y theta v omega), u8 tag, u8 fd
  kCanHealth = 3,     // u32 uptime, u16 crc_errors, u32 fault_bits, u8 tag, u8 fd
  kCanTimeout = 4,    // u32 ms: advance the clock and call check_timeout
  kCanNumOps = 5,
};

enum CanScanMutation : std::uint8_t {
  kMutNone = 0, kMutDropFrame, kMutDuplicateFrame, kMutSwapFrames, kMutFlipByte, kMutEndSegments,
  kMutEndScanId, kMutSlowFrames, kCanNumMutations
};

}  // namespace fuzz
