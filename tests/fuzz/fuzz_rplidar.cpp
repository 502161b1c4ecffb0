// libFuzzer target: RPLIDAR parser (descriptors, samples, legacy capsules), revolution assembly
// and the RplidarLaser driver (handshake, reset, timeouts) over an in-memory byte stream
// (hal/serial, issue 59). Oracle beyond "no crash, no hang": every delivered scan is usable, the
// driver consumes all input in a bounded number of polls, and the parser alone never hands out a
// sample with wrong check bits or an angle of 360° or more.
#include <vector>

#include "hal_serial/rplidar_laser.h"
#include "hal_serial/rplidar_protocol.h"
#include "tests/fuzz/byte_reader.h"
#include "tests/fuzz/serial_fuzz_port.h"
#include "tests/fuzz/serial_lidar_fuzz_ops.h"

namespace {

constexpr const char* kTarget = "fuzz_rplidar";

void put(fuzz::StreamPort& port, const std::uint8_t* b, std::size_t n) {
  port.pending.insert(port.pending.end(), b, b + n);
}

void samples_op(fuzz::ByteReader& in, fuzz::StreamPort& port) {
  const int n = in.u8();
  for (int i = 0; i < n && !in.exhausted(); ++i) {
    const std::uint8_t flags = in.u8();
    hal_serial::RplidarSample s;
    s.start = (flags & 1) != 0;
    s.quality = static_cast<std::uint8_t>((flags >> 1) & 0x3F);
    s.angle_q6 = in.u16();
    s.distance_q2 = in.u16();
    std::uint8_t b[5];
    hal_serial::encode_rplidar_sample(s, b);
    if (flags & 0x80) b[0] = static_cast<std::uint8_t>((b[0] & 0xFC) | (flags & 0x3));  // raw flag bits
    put(port, b, 5);
  }
}

void capsule_op(fuzz::ByteReader& in, fuzz::StreamPort& port) {
  hal_serial::RplidarCapsule c;
  c.start = (in.u8() & 1) != 0;
  c.start_angle_q6 = in.u16();
  for (auto& d : c.distance_mm) d = in.u16() & 0x3FFF;
  for (auto& o : c.offset_q3) o = in.u8() & 0x3F;
  std::uint8_t raw[84];
  hal_serial::encode_rplidar_capsule(c, raw);
  put(port, raw, 84);
}

void parser_alone(const std::uint8_t* data, std::size_t size) {
  for (const std::uint8_t type : {hal_serial::kRplidarAnsSample, hal_serial::kRplidarAnsCapsule}) {
    hal_serial::RplidarParser p;
    p.expect(type);
    hal_serial::RplidarEvent e;
    std::size_t off = 0;
    while (off < size) {
      const std::size_t k = p.feed(data + off, size - off);
      off += k;
      bool any = false;
      while (p.next(&e)) {
        any = true;
        if (e.kind == hal_serial::RplidarEvent::Kind::kSample) {
          fuzz::serial_check(e.sample.angle_q6 < 360 * 64, kTarget, "sample angle of 360 degrees or more");
        }
      }
      if (k == 0 && !any) break;
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::ByteReader in(data, size);
  fuzz::StreamPort port;
  fuzz::InputClock clock;
  static hal_serial::RplidarLaser laser;
  hal_serial::RplidarOptions o;
  o.mode = static_cast<hal_serial::RplidarScanMode>(in.u8() % 3);
  o.revolution.beams = 1 + in.u16() % hal::LaserScan::kMaxBeams;
  o.revolution.min_samples = 1 + in.u8();
  laser.init(&port, &clock, o);
  laser.start();
  static hal::LaserScan scan;
  auto poll = [&] {
    if (laser.poll(&scan)) fuzz::check_delivered_scan(scan, kTarget);
  };
  while (!in.exhausted()) {
    std::uint8_t d[7];
    switch (in.u8() % fuzz::kRpNumOps) {
      case fuzz::kRpRaw: {
        const std::vector<std::uint8_t> b = in.blob();
        put(port, b.data(), b.size());
        break;
      }
      case fuzz::kRpDescriptor: {
        const std::uint32_t v = in.u32();
        hal_serial::encode_rplidar_descriptor(v & 0x3FFFFFFF, static_cast<std::uint8_t>(v >> 30), in.u8(), d);
        put(port, d, 7);
        break;
      }
      case fuzz::kRpHealth: {
        hal_serial::encode_rplidar_descriptor(3, 0, hal_serial::kRplidarAnsHealth, d);
        put(port, d, 7);
        std::uint8_t h[3] = {in.u8(), in.u8(), in.u8()};
        put(port, h, 3);
        break;
      }
      case fuzz::kRpInfo: {
        hal_serial::encode_rplidar_descriptor(20, 0, hal_serial::kRplidarAnsInfo, d);
        put(port, d, 7);
        std::uint8_t info[20];
        in.bytes(info, 20);
        put(port, info, 20);
        break;
      }
      case fuzz::kRpSamples: samples_op(in, port); break;
      case fuzz::kRpCapsule: capsule_op(in, port); break;
      case fuzz::kRpPoll:
        port.chunk = std::size_t(in.u8()) * 16 + 1;
        poll();
        break;
      case fuzz::kRpAdvance: clock.t += std::uint64_t(in.u16()) * 1'000'000; break;
      case fuzz::kRpReconnect:
        port.up = false;
        poll();
        fuzz::serial_check(laser.fault_bits() != 0, kTarget, "a disconnected port raises no fault");
        port.up = true;
        laser.restart();
        break;
    }
  }
  port.chunk = 1024;
  for (int i = 0; i < 256 && !port.pending.empty(); ++i) poll();
  fuzz::serial_check(port.pending.empty(), kTarget, "driver stopped consuming input");
  parser_alone(data, size);
  return 0;
}
