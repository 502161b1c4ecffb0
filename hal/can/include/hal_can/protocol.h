// The mmlfw CAN message set (documented frame by frame in hal/can/mmlfw.dbc and hal/can/README.md).
// Pure encode/decode: no sockets, no <linux/can.h>; frames are hal::CanFrame.
//
// Records (odometry, scan start, pose, health) are fixed little-endian payloads cut into 7-byte
// parts. On classic CAN part k travels at ID base+k as [tag][7 payload bytes]; on CAN FD the whole
// record travels in one frame at ID base|0x400 as [tag][payload], padded to an FD length. The tag
// is a per-record-type sequence number that ties the parts of one record together; fields never
// straddle a part boundary so the DBC can describe every classic part.
//
// A laser scan is a segmented transfer: SCAN_START record, SCAN_DATA segments
// [u16 header: segment index (bits 0..11) | scan_id & 0xF (bits 12..15)][u16 ranges...]
// (3 ranges per classic frame, 31 per FD frame), then SCAN_END [scan_id u16][segments u16][crc32]
// where the CRC-32 (IEEE 802.3) covers the 28-byte start payload followed by all range bytes.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/crc32.h"

namespace hal_can {

constexpr std::uint32_t kFdIdFlag = 0x400;  // FD variant of a record / data frame: base | 0x400

// Base identifiers (11-bit). Lower ID wins arbitration: odometry first, health last.
constexpr std::uint32_t kOdomId = 0x100;       // 4 parts 0x100..0x103; FD 0x500
constexpr std::uint32_t kScanStartId = 0x110;  // 4 parts 0x110..0x113; FD 0x510
constexpr std::uint32_t kScanDataId = 0x118;   // classic; FD 0x518
constexpr std::uint32_t kScanEndId = 0x119;    // 8 bytes on both buses
constexpr std::uint32_t kPoseId = 0x120;       // 6 parts 0x120..0x125; FD 0x520
constexpr std::uint32_t kHealthId = 0x130;     // 5 parts 0x130..0x134; FD 0x530
// Operator commands (issue 60; hal/msg/command.h), after everything the localization needs.
constexpr std::uint32_t kPoseHintId = 0x140;      // SET_POSE_HINT: 3 parts 0x140..0x142; FD 0x540 (24 B)
constexpr std::uint32_t kSelectMapId = 0x148;     // SELECT_MAP: [seq u8][map id u8][flags u8] (3 bytes; 2 from older senders)
constexpr std::uint32_t kDumpLogId = 0x149;       // DUMP_LOG: [seq u8] (1 byte)
constexpr std::uint32_t kCommandReplyId = 0x14F;  // COMMAND_REPLY (fw → robot): [seq][command][result][detail]

constexpr std::size_t kPartBytes = 7;
constexpr std::size_t kOdomParts = 4, kScanStartParts = 4, kPoseParts = 6, kHealthParts = 5;
constexpr std::size_t kPoseHintParts = 3;
constexpr std::size_t kMaxParts = 6;
constexpr std::size_t kMaxRecordBytes = kMaxParts * kPartBytes;  // 42

// POSE layout byte (payload offset 34, reserved and 0 before protection levels existed). Layouts
// only append: layout 0 = the original 5-part record (parts 0x120..0x124), layout 1 adds part 5
// (0x125) with the protection level and unsupported_steps, layout 2 fills part 5's last byte
// (payload 41, reserved 0 before) with the status reason (hal::StatusReason). Receivers accept
// all three; a layout-0 record decodes with protection 0 (= no bound) and unsupported_steps 0,
// a layout < 2 with reason kNone (not stated).
constexpr std::size_t kPoseLayoutOffset = 34;
constexpr std::uint8_t kPoseLayout = 2;
constexpr std::size_t kPoseReasonOffset = 41;
constexpr std::size_t kPoseLegacyParts = 5;  // layout 0
// HEALTH payload byte 34 (the last byte of part 4, reserved 0 before): the last pose hint's
// verification (hal::HintStatus). SET_POSE_HINT flags bit 0: select the hint's map first (SELECT_MAP
// with a hint).
constexpr std::size_t kHealthHintOffset = 34;
constexpr std::uint8_t kHintFlagSelectMap = 0x01;
// SET_POSE_HINT flags bit 1 (with bit 0 only): reload the map's image from disk before selecting it.
constexpr std::uint8_t kHintFlagReload = 0x02;
// SELECT_MAP byte 2 (optional: a 2-byte frame is flags 0): bit 0 reload the map's image from disk.
constexpr std::uint8_t kSelectMapFlagReload = 0x01;

// Protection level on the wire (POSE part 5): u16, rounded *up* (a bound must not shrink);
// 0 = no bound, kProtectionSaturated = "at least the largest code" (decodes as +infinity).
constexpr double kProtectionXyPerMetre = 1000.0;     // 1 mm LSB, up to 65.534 m
constexpr double kProtectionThetaPerRad = 10000.0;   // 1e-4 rad LSB, up to 6.5534 rad
constexpr std::uint16_t kProtectionSaturated = 0xFFFF;

constexpr std::size_t kClassicRangesPerSegment = 3;
constexpr std::size_t kFdRangesPerSegment = 31;
constexpr std::uint32_t kMaxSegments = 4096;  // 12-bit segment index
constexpr std::uint16_t kNoReturn = 0xFFFF;   // range code: no return / not representable

// Smallest valid CAN FD data length >= n (0..8, 12, 16, 20, 24, 32, 48, 64).
std::uint8_t fd_length_for(std::size_t n);

// Little-endian field access (payloads are byte arrays; no alignment assumptions).
inline void put_u16(std::uint8_t* p, std::uint16_t v) { p[0] = v & 0xFF; p[1] = (v >> 8) & 0xFF; }
inline void put_u32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = (v >> (8 * i)) & 0xFF;
}
inline void put_u48(std::uint8_t* p, std::uint64_t v) {
  for (int i = 0; i < 6; ++i) p[i] = (v >> (8 * i)) & 0xFF;
}
inline std::uint16_t get_u16(const std::uint8_t* p) { return static_cast<std::uint16_t>(p[0] | (p[1] << 8)); }
inline std::uint32_t get_u32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}
inline std::uint64_t get_u48(const std::uint8_t* p) {
  std::uint64_t v = 0;
  for (int i = 5; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

// CRC-32 (IEEE 802.3, reflected, init/xorout 0xFFFFFFFF; same as zlib's crc32): the one
// implementation of the common layer (firmware/base/crc32.h), also used by the map image. The
// running value is zlib's (already finalised), so begin is 0 and end is the identity.
inline std::uint32_t crc32_begin() { return 0u; }
inline std::uint32_t crc32_update(std::uint32_t crc, const std::uint8_t* data, std::size_t len) {
  return fw::crc32_update(crc, data, len);
}
inline std::uint32_t crc32_end(std::uint32_t crc) { return crc; }
inline std::uint32_t crc32(const std::uint8_t* data, std::size_t len) { return fw::crc32(data, len); }

}  // namespace hal_can
