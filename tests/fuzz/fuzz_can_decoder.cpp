// libFuzzer target: the CAN decoder (hal/can/codec.*) fed any frame sequence, including complete
// scans with a correct CRC-32 and fuzzed content (can_fuzz_ops.h). Oracle beyond "no crash, no
// sanitizer report": every scan the decoder delivers must satisfy the geometry it promises
// (scan_geometry_defect == kNone, readings finite and not beyond range_max).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <utility>
#include <vector>

#include "hal_can/codec.h"
#include "tests/fuzz/byte_reader.h"
#include "tests/fuzz/can_fuzz_ops.h"

namespace {

void check(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "fuzz_can_decoder: delivered scan violates: %s\n", what);
    std::abort();
  }
}

void check_delivered_scan(const hal::LaserScan& s, std::uint32_t unit_um) {
  check(s.beam_count >= 1 && s.beam_count <= hal::LaserScan::kMaxBeams, "beam count");
  check(hal_can::scan_geometry_defect(s) == hal_can::ScanDefect::kNone, "geometry");
  const float beyond = s.range_max + static_cast<float>(unit_um * 1e-6) + 0.01f;
  for (std::uint32_t i = 0; i < s.beam_count; ++i) {
    check(std::isfinite(s.ranges[i]) && s.ranges[i] >= 0.0f && s.ranges[i] <= beyond, "reading range");
  }
}

// Issue 60: an operator command the decoder delivers is one the runtime can check: a known kind, a
// hint's numbers finite and its σ not negative; a reply's codes within their enums.
void check_delivered_command(const hal::Command& c) {
  check(c.kind == hal::CommandKind::kSetPoseHint || c.kind == hal::CommandKind::kSelectMap ||
            c.kind == hal::CommandKind::kDumpLog,
        "command kind");
  if (c.has_hint) {
    check(std::isfinite(c.hint.x) && std::isfinite(c.hint.y) && std::isfinite(c.hint.theta), "hint finite");
    check(c.hint.sigma_xy_m >= 0.0f && c.hint.sigma_theta_rad >= 0.0f, "hint sigma");
  }
}

struct Feeder {
  hal_can::Decoder decoder;
  std::uint64_t now_ns = 1'000'000'000;
  std::uint32_t last_unit_um = 1000;
  void feed(hal::CanFrame f) {
    f.timestamp_ns = now_ns;
    const hal_can::Decoded d = decoder.feed(f);
    if (d == hal_can::Decoded::kScan) check_delivered_scan(decoder.scan(), last_unit_um);
    if (d == hal_can::Decoded::kCommand) check_delivered_command(decoder.command());
    if (d == hal_can::Decoded::kReply) {
      check(static_cast<std::uint8_t>(decoder.reply().result) < hal::kCommandResultCount, "reply result");
    }
  }
};

// Frames of one scan exactly as a sender would cut them (hal/can/protocol.h), CRC over the content.
std::vector<hal::CanFrame> scan_frames(const std::uint8_t* start, std::uint8_t tag, bool fd,
                                       const std::vector<std::uint16_t>& codes, std::uint32_t* crc_out) {
  using namespace hal_can;
  std::vector<hal::CanFrame> frames;
  if (fd) {
    hal::CanFrame f;
    f.id = kScanStartId | kFdIdFlag;
    f.fd = f.brs = true;
    f.data[0] = tag;
    std::memcpy(f.data + 1, start, kScanStartParts * kPartBytes);
    f.len = fd_length_for(1 + kScanStartParts * kPartBytes);
    frames.push_back(f);
  } else {
    for (std::size_t k = 0; k < kScanStartParts; ++k) {
      hal::CanFrame f;
      f.id = static_cast<std::uint32_t>(kScanStartId + k);
      f.len = 8;
      f.data[0] = tag;
      std::memcpy(f.data + 1, start + k * kPartBytes, kPartBytes);
      frames.push_back(f);
    }
  }
  std::uint32_t crc = crc32_update(crc32_begin(), start, kScanStartParts * kPartBytes);
  const std::size_t per = fd ? kFdRangesPerSegment : kClassicRangesPerSegment;
  const std::uint16_t scan_id = get_u16(start);
  for (std::size_t s = 0, b0 = 0; b0 < codes.size(); ++s, b0 += per) {
    hal::CanFrame f;
    f.id = kScanDataId | (fd ? kFdIdFlag : 0);
    f.fd = f.brs = fd;
    put_u16(f.data, static_cast<std::uint16_t>((s & 0xFFF) | ((scan_id & 0xF) << 12)));
    const std::size_t nb = codes.size() - b0 < per ? codes.size() - b0 : per;
    for (std::size_t i = 0; i < nb; ++i) put_u16(f.data + 2 + 2 * i, codes[b0 + i]);
    crc = crc32_update(crc, f.data + 2, 2 * nb);
    f.len = fd ? fd_length_for(2 + 2 * nb) : static_cast<std::uint8_t>(2 + 2 * nb);
    frames.push_back(f);
  }
  *crc_out = crc32_end(crc);
  return frames;
}

void synthetic_scan(fuzz::ByteReader& in, Feeder& feeder) {
  using namespace hal_can;
  const std::uint8_t flags = in.u8();
  const std::uint8_t arg = in.u8();
  std::uint8_t start[kScanStartParts * kPartBytes];
  in.bytes(start, sizeof start);
  const bool fd = flags & 1;
  const int mutation = ((flags >> 1) & 7) % fuzz::kCanNumMutations;
  std::uint32_t beams = get_u16(start + 2);
  if (beams > hal::LaserScan::kMaxBeams + 8) beams = hal::LaserScan::kMaxBeams + 8;
  std::vector<std::uint16_t> codes(beams);
  for (auto& c : codes) c = in.u16();
  const std::uint32_t unit = get_u16(start + 4);
  if (unit != 0) feeder.last_unit_um = unit;
  std::uint32_t crc = 0;
  std::vector<hal::CanFrame> frames = scan_frames(start, static_cast<std::uint8_t>(get_u16(start)), fd, codes, &crc);
  hal::CanFrame end;
  end.id = kScanEndId;
  end.len = 8;
  std::uint16_t segments = static_cast<std::uint16_t>(frames.size() - (fd ? 1 : kScanStartParts));
  std::uint16_t scan_id = get_u16(start);
  const std::size_t i = frames.empty() ? 0 : arg % frames.size();
  switch (mutation) {
    case fuzz::kMutDropFrame: frames.erase(frames.begin() + static_cast<long>(i)); break;
    case fuzz::kMutDuplicateFrame: frames.insert(frames.begin() + static_cast<long>(i), frames[i]); break;
    case fuzz::kMutSwapFrames:
      if (i + 1 < frames.size()) std::swap(frames[i], frames[i + 1]);
      break;
    case fuzz::kMutFlipByte: frames[i].data[arg % (frames[i].len ? frames[i].len : 1)] ^= 0x5A; break;
    case fuzz::kMutEndSegments: segments = static_cast<std::uint16_t>(segments + (arg % 5) - 2); break;
    case fuzz::kMutEndScanId: scan_id = static_cast<std::uint16_t>(scan_id + 1 + arg); break;
    default: break;
  }
  put_u16(end.data, scan_id);
  put_u16(end.data + 2, segments);
  put_u32(end.data + 4, crc);
  frames.push_back(end);
  for (const hal::CanFrame& f : frames) {
    feeder.feed(f);
    // A slow sender: the transfer may exceed the decoder's timeout half way.
    if (mutation == fuzz::kMutSlowFrames) feeder.now_ns += std::uint64_t(arg) * 1'000'000;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::ByteReader in(data, size);
  Feeder feeder;
  hal::CanFrame frames[hal_can::kMaxParts];
  while (!in.exhausted()) {
    switch (in.u8() % fuzz::kCanNumOps) {
      case fuzz::kCanRawFrame: {
        hal::CanFrame f;
        f.id = in.u16() & 0x7FF;
        const std::uint8_t flags = in.u8();
        f.fd = flags & 1;
        f.extended = flags & 2;
        f.brs = flags & 4;
        if (f.extended) f.id |= static_cast<std::uint32_t>(in.u16()) << 11;
        f.len = in.u8() % (hal::CanFrame::kMaxData + 1);
        in.bytes(f.data, f.len);
        feeder.now_ns += in.u16() * 1000ull;
        feeder.feed(f);
        break;
      }
      case fuzz::kCanScan: synthetic_scan(in, feeder); break;
      case fuzz::kCanOdometry: {
        hal::Odometry o;
        o.x = in.f32(); o.y = in.f32(); o.theta = in.f32(); o.v = in.f32(); o.omega = in.f32();
        o.timestamp_ns = feeder.now_ns;
        const std::uint8_t tag = in.u8();
        std::size_t n = 0;
        if (hal_can::encode_odometry(o, tag, in.u8() & 1, frames, hal_can::kMaxParts, &n).is_ok()) {
          for (std::size_t k = 0; k < n; ++k) feeder.feed(frames[k]);
        }
        break;
      }
      case fuzz::kCanHealth: {
        hal_can::HealthRecord h;
        h.uptime_ms = in.u32();
        h.crc_errors = in.u16();
        h.fault_bits = in.u32();
        const std::uint8_t tag = in.u8();
        std::size_t n = 0;
        if (hal_can::encode_health(h, tag, in.u8() & 1, frames, hal_can::kMaxParts, &n).is_ok()) {
          for (std::size_t k = 0; k < n; ++k) feeder.feed(frames[k]);
        }
        break;
      }
      case fuzz::kCanTimeout:
        feeder.now_ns += in.u32() * 1'000'000ull;
        feeder.decoder.check_timeout(feeder.now_ns);
        break;
    }
  }
  return 0;
}
