// Slamtec RPLIDAR serial protocol as a pure parser/encoder (no I/O), after "RPLIDAR Interface
// Protocol and Application Notes" (Slamtec, A1/A2 rev. 1.1 2018 and A3 2019; the same commands on
// S1/S2) and the public SDK (rplidar_cmd.h, rplidar_driver.cpp):
//   request:  A5 CMD [SIZE PAYLOAD... CHECKSUM]   (checksum: XOR of every byte before it)
//   answer:   A5 5A | 30-bit size + 2-bit send mode (u32 LE; mode 1 = "multiple response") | type
//             then `size` bytes once (single) or again and again (multiple) until the next request.
// Used here: STOP 0x25, RESET 0x40, SCAN 0x20, FORCE_SCAN 0x21, EXPRESS_SCAN 0x82 (legacy capsules,
// working mode 0), GET_INFO 0x50 (answer type 0x04, 20 bytes), GET_HEALTH 0x52 (0x06, 3 bytes),
// SET_MOTOR_PWM 0xF0 (A2/A3 motor speed; the A1's motor is switched by DTR, see rplidar_laser.h).
// SCAN sample (type 0x81, 5 bytes): quality(6) !S S | angle_q6[6:0] C=1 | angle_q6[14:7] |
// distance_q2 (u16 LE): S = first sample of a new revolution, C = check bit, angle in 1/64°
// clockwise, distance in 1/4 mm, 0 = no measurement.
// Express legacy capsule (type 0x82, 84 bytes): 0xA|sum[3:0], 0x5|sum[7:4], start_angle_q6 | S<<15,
// then 16 cabins of 5 bytes (two 14-bit distances in mm with the high bits of their angle offsets,
// then both offsets' low 4 bits; offsets in 1/8°); the checksum is the XOR of bytes 2..83. A
// capsule's 32 samples lie between its start angle and the next capsule's (SDK _capsuleToNormal).
//
// The parser is told which answer the driver waits for (expect()): it skips everything before
// that answer's exact 7-byte descriptor (the rest of a stream the STOP interrupted, a reset
// banner), so such bytes cannot be mistaken for an answer. In a stream, a sample whose check bits
// are wrong or a capsule whose sync or checksum is wrong is counted and the parser slides one byte
// until three records in a row are valid again (a stray byte shifts the framing for good; one
// valid-looking record is a 1-in-4 chance).
#pragma once

#include <cstddef>
#include <cstdint>

namespace hal_serial {

constexpr std::uint8_t kRplidarSync = 0xA5;
constexpr std::uint8_t kRplidarSync2 = 0x5A;
constexpr std::uint8_t kRplidarCmdStop = 0x25, kRplidarCmdReset = 0x40, kRplidarCmdScan = 0x20,
                       kRplidarCmdForceScan = 0x21, kRplidarCmdExpressScan = 0x82, kRplidarCmdGetInfo = 0x50,
                       kRplidarCmdGetHealth = 0x52, kRplidarCmdSetMotorPwm = 0xF0;
constexpr std::uint8_t kRplidarAnsInfo = 0x04, kRplidarAnsHealth = 0x06, kRplidarAnsSample = 0x81,
                       kRplidarAnsCapsule = 0x82;
constexpr std::size_t kRplidarInfoSize = 20, kRplidarHealthSize = 3, kRplidarSampleSize = 5, kRplidarCapsuleSize = 84;
constexpr std::size_t kRplidarDescriptorSize = 7;
constexpr std::uint8_t kRplidarHealthGood = 0, kRplidarHealthWarning = 1, kRplidarHealthError = 2;

// The request bytes; 0 if it does not fit (payload ≤ 255 bytes).
std::size_t encode_rplidar_request(std::uint8_t cmd, const std::uint8_t* payload, std::size_t n, std::uint8_t* out,
                                   std::size_t cap);
// An answer descriptor: A5 5A, size | mode << 30 (LE), type.
void encode_rplidar_descriptor(std::uint32_t size, std::uint8_t mode, std::uint8_t type, std::uint8_t out[7]);

struct RplidarSample {
  bool start = false;          // first sample of a new revolution
  std::uint8_t quality = 0;    // 0..63
  std::uint16_t angle_q6 = 0;  // 1/64°, clockwise from the front
  std::uint16_t distance_q2 = 0;  // 1/4 mm; 0 = no measurement
};
// False when the check bits are wrong (S == !S, C != 1) or the angle is 360° or more.
bool decode_rplidar_sample(const std::uint8_t b[5], RplidarSample* out);
void encode_rplidar_sample(const RplidarSample& s, std::uint8_t out[5]);

struct RplidarInfo {
  std::uint8_t model = 0, firmware_minor = 0, firmware_major = 0, hardware = 0;
  std::uint8_t serial[16] = {};
};
struct RplidarHealth {
  std::uint8_t status = 0;  // 0 good, 1 warning, 2 error (the device wants a RESET)
  std::uint16_t error_code = 0;
};

// One legacy express capsule.
struct RplidarCapsule {
  bool start = false;
  std::uint16_t start_angle_q6 = 0;
  std::uint16_t distance_mm[32] = {};  // sample k of cabin k/2
  std::uint8_t offset_q3[32] = {};     // 6-bit angle offsets, 1/8°
};
// False when the sync nibbles or the checksum are wrong.
bool decode_rplidar_capsule(const std::uint8_t b[84], RplidarCapsule* out);
void encode_rplidar_capsule(const RplidarCapsule& c, std::uint8_t out[84]);
// The 32 samples of `cur` (angles between its start angle and `next`'s), as the SDK computes them;
// `start` marks the sample where the angle passed 0°. Returns 32.
std::size_t rplidar_capsule_samples(const RplidarCapsule& cur, const RplidarCapsule& next, RplidarSample out[32]);

struct RplidarParserStats {
  std::uint32_t answers = 0;          // single answers (info, health) handed out
  std::uint32_t samples = 0;          // stream samples handed out
  std::uint32_t capsules = 0;
  std::uint32_t check_errors = 0;     // samples with wrong check bits, capsules with a wrong sync
  std::uint32_t checksum_errors = 0;  // capsules with the right sync but a wrong checksum
  std::uint32_t skipped_bytes = 0;    // bytes before the awaited descriptor
  std::uint32_t resync_bytes = 0;     // bytes slid over while finding the stream's framing again
};

struct RplidarEvent {
  enum class Kind : std::uint8_t { kInfo, kHealth, kStreamStarted, kSample };
  Kind kind = Kind::kSample;
  RplidarInfo info;
  RplidarHealth health;
  RplidarSample sample;
};

class RplidarParser {
 public:
  // The answer type awaited next (kRplidarAns*): its descriptor ends everything before it.
  void expect(std::uint8_t answer_type);
  std::size_t feed(const std::uint8_t* bytes, std::size_t n);
  bool next(RplidarEvent* out);
  const RplidarParserStats& stats() const { return stats_; }
  void reset();

 private:
  enum class Mode : std::uint8_t { kIdle, kDescriptor, kSingle, kSamples, kCapsules };
  bool next_descriptor(RplidarEvent* out);
  bool next_single(RplidarEvent* out);
  bool next_sample(RplidarEvent* out);
  bool next_capsule(RplidarEvent* out);
  bool framed(std::size_t record, bool (*valid)(const std::uint8_t*));
  void drop_front(std::size_t n);

  Mode mode_ = Mode::kIdle;
  std::uint8_t awaited_ = 0;
  bool in_sync_ = true;       // stream framing confirmed (false after an error until 3 valid records)
  bool have_prev_ = false;    // a capsule waits for the next one's start angle
  RplidarCapsule prev_;
  RplidarSample pending_[32];
  std::size_t pending_n_ = 0, pending_i_ = 0;
  std::uint8_t buf_[512] = {};
  std::size_t size_ = 0;
  RplidarParserStats stats_;
};

}  // namespace hal_serial
