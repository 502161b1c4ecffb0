// The Hokuyo (SCIP 2.0) and RPLIDAR fuzz inputs: operations on the byte stream a device sends and
// on the clock (shared by fuzz_scip.cpp / fuzz_rplidar.cpp and the seed generator). Answer
// operations are encoded by the harness with valid sums / check bits, so impossible content
// (geometry, counts, angles) reaches the decoders and the drivers, not only the framing.
#pragma once

#include <cstdint>

namespace fuzz {

enum ScipOp : std::uint8_t {
  kScipRaw = 0,        // blob: raw bytes
  kScipStatus = 1,     // blob echo, u8 u8 status: echo + status line with its sum + LF
  kScipInfo = 2,       // blob echo, blob lines ('\n'-separated "KEY:value"): an info answer, status 00
  kScipScan = 3,       // u8 kind (MD/ME/MS), u16 start, u16 end, u8 cluster, u32 time, u16 n, n × u32: a "99" answer
  kScipPoll = 4,       // u8 chunk: at most chunk+1 bytes per read; poll once
  kScipAdvance = 5,    // u16 ms: the clock moves (answer timeouts, silence restarts)
  kScipReconnect = 6,  // the port closes and returns: restart()
  kScipNumOps = 7,
};

enum RplidarOp : std::uint8_t {
  kRpRaw = 0,        // blob: raw bytes
  kRpDescriptor = 1, // u32 size | mode << 30, u8 type
  kRpHealth = 2,     // u8 status, u16 code: descriptor + answer
  kRpInfo = 3,       // 20 bytes: descriptor + answer
  kRpSamples = 4,    // u8 n, n × (u8 flags, u16 angle_q6, u16 distance_q2): samples with valid check bits
                     // unless flags bit 7 (then the raw flag bits)
  kRpCapsule = 5,    // u8 start, u16 start angle, 32 × u16 mm, 32 × u8 offset: a capsule with its checksum
  kRpPoll = 6,       // u8 chunk
  kRpAdvance = 7,    // u16 ms
  kRpReconnect = 8,
  kRpNumOps = 9,
};

}  // namespace fuzz
