#include "hal_serial/rplidar_protocol.h"

#include <cstring>

namespace hal_serial {

std::size_t encode_rplidar_request(std::uint8_t cmd, const std::uint8_t* payload, std::size_t n, std::uint8_t* out,
                                   std::size_t cap) {
  if (n > 255) return 0;
  const std::size_t total = n == 0 ? 2 : 3 + n + 1;
  if (cap < total) return 0;
  out[0] = kRplidarSync;
  out[1] = cmd;
  if (n == 0) return 2;
  out[2] = static_cast<std::uint8_t>(n);
  std::memcpy(out + 3, payload, n);
  std::uint8_t x = 0;
  for (std::size_t i = 0; i < 3 + n; ++i) x ^= out[i];
  out[3 + n] = x;
  return total;
}

void encode_rplidar_descriptor(std::uint32_t size, std::uint8_t mode, std::uint8_t type, std::uint8_t out[7]) {
  const std::uint32_t v = (size & 0x3FFFFFFFu) | (static_cast<std::uint32_t>(mode & 0x3) << 30);
  out[0] = kRplidarSync;
  out[1] = kRplidarSync2;
  out[2] = static_cast<std::uint8_t>(v);
  out[3] = static_cast<std::uint8_t>(v >> 8);
  out[4] = static_cast<std::uint8_t>(v >> 16);
  out[5] = static_cast<std::uint8_t>(v >> 24);
  out[6] = type;
}

bool decode_rplidar_sample(const std::uint8_t b[5], RplidarSample* out) {
  const bool s = (b[0] & 0x1) != 0;
  const bool not_s = (b[0] & 0x2) != 0;
  if (s == not_s || (b[1] & 0x1) == 0) return false;
  const std::uint16_t angle = static_cast<std::uint16_t>((b[1] >> 1) | (b[2] << 7));
  if (angle >= 360 * 64) return false;
  out->start = s;
  out->quality = static_cast<std::uint8_t>(b[0] >> 2);
  out->angle_q6 = angle;
  out->distance_q2 = static_cast<std::uint16_t>(b[3] | (b[4] << 8));
  return true;
}

void encode_rplidar_sample(const RplidarSample& s, std::uint8_t out[5]) {
  out[0] = static_cast<std::uint8_t>((s.quality << 2) | (s.start ? 0x1 : 0x2));
  out[1] = static_cast<std::uint8_t>(((s.angle_q6 & 0x7F) << 1) | 0x1);
  out[2] = static_cast<std::uint8_t>(s.angle_q6 >> 7);
  out[3] = static_cast<std::uint8_t>(s.distance_q2);
  out[4] = static_cast<std::uint8_t>(s.distance_q2 >> 8);
}

bool decode_rplidar_capsule(const std::uint8_t b[84], RplidarCapsule* out) {
  if ((b[0] >> 4) != 0xA || (b[1] >> 4) != 0x5) return false;
  const std::uint8_t want = static_cast<std::uint8_t>((b[0] & 0xF) | (b[1] << 4));
  std::uint8_t x = 0;
  for (std::size_t i = 2; i < kRplidarCapsuleSize; ++i) x ^= b[i];
  if (x != want) return false;
  const std::uint16_t sa = static_cast<std::uint16_t>(b[2] | (b[3] << 8));
  out->start = (sa & 0x8000) != 0;
  out->start_angle_q6 = sa & 0x7FFF;
  for (int c = 0; c < 16; ++c) {
    const std::uint8_t* p = b + 4 + 5 * c;
    const std::uint16_t d1 = static_cast<std::uint16_t>(p[0] | (p[1] << 8));
    const std::uint16_t d2 = static_cast<std::uint16_t>(p[2] | (p[3] << 8));
    out->distance_mm[2 * c] = static_cast<std::uint16_t>(d1 >> 2);
    out->distance_mm[2 * c + 1] = static_cast<std::uint16_t>(d2 >> 2);
    out->offset_q3[2 * c] = static_cast<std::uint8_t>((p[4] & 0xF) | ((d1 & 0x3) << 4));
    out->offset_q3[2 * c + 1] = static_cast<std::uint8_t>((p[4] >> 4) | ((d2 & 0x3) << 4));
  }
  return true;
}

void encode_rplidar_capsule(const RplidarCapsule& c, std::uint8_t out[84]) {
  const std::uint16_t sa = static_cast<std::uint16_t>((c.start_angle_q6 & 0x7FFF) | (c.start ? 0x8000 : 0));
  out[2] = static_cast<std::uint8_t>(sa);
  out[3] = static_cast<std::uint8_t>(sa >> 8);
  for (int k = 0; k < 16; ++k) {
    std::uint8_t* p = out + 4 + 5 * k;
    const std::uint8_t o1 = c.offset_q3[2 * k] & 0x3F, o2 = c.offset_q3[2 * k + 1] & 0x3F;
    const std::uint16_t d1 = static_cast<std::uint16_t>((c.distance_mm[2 * k] << 2) | (o1 >> 4));
    const std::uint16_t d2 = static_cast<std::uint16_t>((c.distance_mm[2 * k + 1] << 2) | (o2 >> 4));
    p[0] = static_cast<std::uint8_t>(d1);
    p[1] = static_cast<std::uint8_t>(d1 >> 8);
    p[2] = static_cast<std::uint8_t>(d2);
    p[3] = static_cast<std::uint8_t>(d2 >> 8);
    p[4] = static_cast<std::uint8_t>((o1 & 0xF) | ((o2 & 0xF) << 4));
  }
  std::uint8_t x = 0;
  for (std::size_t i = 2; i < kRplidarCapsuleSize; ++i) x ^= out[i];
  out[0] = static_cast<std::uint8_t>(0xA0 | (x & 0xF));
  out[1] = static_cast<std::uint8_t>(0x50 | (x >> 4));
}

// The SDK's _capsuleToNormal (rplidar_driver.cpp): angles in q16 between the two start angles,
// each sample's offset subtracted (the SDK reads the 6-bit offset unsigned although the protocol
// document calls its top bit a sign; we follow the SDK, which is what the devices are tested with).
std::size_t rplidar_capsule_samples(const RplidarCapsule& cur, const RplidarCapsule& next, RplidarSample out[32]) {
  const int cur_q8 = static_cast<int>(cur.start_angle_q6) << 2;
  const int next_q8 = static_cast<int>(next.start_angle_q6) << 2;
  int diff_q8 = next_q8 - cur_q8;
  if (cur_q8 > next_q8) diff_q8 += 360 << 8;
  const int inc_q16 = diff_q8 << 3;  // /32 samples, q8 → q16
  int angle_q16 = cur_q8 << 8;
  for (int k = 0; k < 32; ++k) {
    int a_q6 = (angle_q16 - (static_cast<int>(cur.offset_q3[k]) << 13)) >> 10;
    const bool sync = ((angle_q16 + inc_q16) % (360 << 16)) < inc_q16;
    angle_q16 += inc_q16;
    if (a_q6 < 0) a_q6 += 360 << 6;
    if (a_q6 >= 360 << 6) a_q6 -= 360 << 6;
    RplidarSample& s = out[k];
    s.start = sync;
    s.angle_q6 = static_cast<std::uint16_t>(a_q6);
    s.distance_q2 = static_cast<std::uint16_t>(cur.distance_mm[k] << 2);
    s.quality = cur.distance_mm[k] != 0 ? 0x2F : 0;  // the SDK's fixed quality for express samples
  }
  return 32;
}

// ------------------------------------------------------------------------------------------------

namespace {
bool sample_valid(const std::uint8_t* b) {
  RplidarSample s;
  return decode_rplidar_sample(b, &s);
}
bool capsule_valid(const std::uint8_t* b) {
  RplidarCapsule c;
  return decode_rplidar_capsule(b, &c);
}
}  // namespace

void RplidarParser::reset() {
  mode_ = Mode::kIdle;
  size_ = 0;
  have_prev_ = false;
  pending_n_ = pending_i_ = 0;
  in_sync_ = true;
}

void RplidarParser::expect(std::uint8_t answer_type) {
  awaited_ = answer_type;
  mode_ = Mode::kDescriptor;
  have_prev_ = false;
  pending_n_ = pending_i_ = 0;
  in_sync_ = true;
}

std::size_t RplidarParser::feed(const std::uint8_t* bytes, std::size_t n) {
  const std::size_t room = sizeof(buf_) - size_;
  const std::size_t take = n < room ? n : room;
  std::memcpy(buf_ + size_, bytes, take);
  size_ += take;
  return take;
}

void RplidarParser::drop_front(std::size_t n) {
  if (n >= size_) {
    size_ = 0;
    return;
  }
  std::memmove(buf_, buf_ + n, size_ - n);
  size_ -= n;
}

bool RplidarParser::next_descriptor(RplidarEvent* out) {
  std::uint8_t want[7];
  const bool stream = awaited_ == kRplidarAnsSample || awaited_ == kRplidarAnsCapsule;
  const std::uint32_t size = awaited_ == kRplidarAnsInfo     ? kRplidarInfoSize
                             : awaited_ == kRplidarAnsHealth ? kRplidarHealthSize
                             : awaited_ == kRplidarAnsSample ? kRplidarSampleSize
                                                             : kRplidarCapsuleSize;
  encode_rplidar_descriptor(size, stream ? 1 : 0, awaited_, want);
  std::size_t i = 0;
  while (i + kRplidarDescriptorSize <= size_ && std::memcmp(buf_ + i, want, kRplidarDescriptorSize) != 0) ++i;
  if (i + kRplidarDescriptorSize > size_) {
    // Keep a tail that may be the start of the descriptor.
    const std::size_t keep = size_ < kRplidarDescriptorSize - 1 ? size_ : kRplidarDescriptorSize - 1;
    stats_.skipped_bytes += static_cast<std::uint32_t>(size_ - keep);
    drop_front(size_ - keep);
    return false;
  }
  stats_.skipped_bytes += static_cast<std::uint32_t>(i);
  drop_front(i + kRplidarDescriptorSize);
  if (!stream) {
    mode_ = Mode::kSingle;
    return false;
  }
  mode_ = awaited_ == kRplidarAnsSample ? Mode::kSamples : Mode::kCapsules;
  in_sync_ = true;
  out->kind = RplidarEvent::Kind::kStreamStarted;
  return true;
}

bool RplidarParser::next_single(RplidarEvent* out) {
  const std::size_t need = awaited_ == kRplidarAnsInfo ? kRplidarInfoSize : kRplidarHealthSize;
  if (size_ < need) return false;
  if (awaited_ == kRplidarAnsInfo) {
    out->kind = RplidarEvent::Kind::kInfo;
    out->info.model = buf_[0];
    out->info.firmware_minor = buf_[1];
    out->info.firmware_major = buf_[2];
    out->info.hardware = buf_[3];
    std::memcpy(out->info.serial, buf_ + 4, 16);
  } else {
    out->kind = RplidarEvent::Kind::kHealth;
    out->health.status = buf_[0];
    out->health.error_code = static_cast<std::uint16_t>(buf_[1] | (buf_[2] << 8));
  }
  drop_front(need);
  mode_ = Mode::kIdle;
  ++stats_.answers;
  return true;
}

// Stream framing: in sync, one valid record is taken; after an error, three valid records in a
// row at this offset are needed (else slide one byte).
bool RplidarParser::framed(std::size_t record, bool (*valid)(const std::uint8_t*)) {
  for (;;) {
    const std::size_t need = in_sync_ ? record : 3 * record;
    if (size_ < need) return false;
    bool ok = true;
    for (std::size_t k = 0; ok && k * record < need; ++k) ok = valid(buf_ + k * record);
    if (ok) {
      in_sync_ = true;
      return true;
    }
    if (in_sync_) {
      // First bad record after good ones: it is the error; count it by kind.
      if (record == kRplidarCapsuleSize && (buf_[0] >> 4) == 0xA && (buf_[1] >> 4) == 0x5) {
        ++stats_.checksum_errors;
      } else {
        ++stats_.check_errors;
      }
      in_sync_ = false;
      have_prev_ = false;  // a capsule's samples need the next capsule's start angle: the chain broke
    }
    ++stats_.resync_bytes;
    drop_front(1);
  }
}

bool RplidarParser::next_sample(RplidarEvent* out) {
  if (!framed(kRplidarSampleSize, sample_valid)) return false;
  decode_rplidar_sample(buf_, &out->sample);
  out->kind = RplidarEvent::Kind::kSample;
  drop_front(kRplidarSampleSize);
  ++stats_.samples;
  return true;
}

bool RplidarParser::next_capsule(RplidarEvent* out) {
  for (;;) {
    if (pending_i_ < pending_n_) {
      out->kind = RplidarEvent::Kind::kSample;
      out->sample = pending_[pending_i_++];
      ++stats_.samples;
      return true;
    }
    if (!framed(kRplidarCapsuleSize, capsule_valid)) return false;
    RplidarCapsule c;
    decode_rplidar_capsule(buf_, &c);
    drop_front(kRplidarCapsuleSize);
    ++stats_.capsules;
    pending_n_ = pending_i_ = 0;
    if (have_prev_ && !c.start) pending_n_ = rplidar_capsule_samples(prev_, c, pending_);
    prev_ = c;
    have_prev_ = true;
  }
}

bool RplidarParser::next(RplidarEvent* out) {
  for (;;) {
    switch (mode_) {
      case Mode::kIdle:
        // Nothing awaited: bytes now are not ours (a reset banner, a stream after an error).
        stats_.skipped_bytes += static_cast<std::uint32_t>(size_);
        size_ = 0;
        return false;
      case Mode::kDescriptor:
        if (next_descriptor(out)) return true;
        if (mode_ == Mode::kDescriptor) return false;
        continue;
      case Mode::kSingle: return next_single(out);
      case Mode::kSamples: return next_sample(out);
      case Mode::kCapsules: return next_capsule(out);
    }
    return false;
  }
}

}  // namespace hal_serial
