// libFuzzer target: SICK LMS2xx telegram parser, measured-values decoder and the SickLaser driver
// over an in-memory byte stream (hal/serial). Oracle beyond "no crash, no hang": every scan the
// driver delivers is one the localizer can use (beam count within capacity, finite geometry,
// readings within [0, range_max]), and the parser never reports a telegram with a wrong CRC.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "hal_serial/sick_laser.h"
#include "hal_serial/sick_telegram.h"
#include "tests/fuzz/byte_reader.h"
#include "tests/fuzz/sick_fuzz_ops.h"

namespace {

void check(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "fuzz_sick_telegram: %s\n", what);
    std::abort();
  }
}

// The byte stream of the fuzz input, handed out in chunks as a serial port would.
class StreamPort final : public hal::SerialPort {
 public:
  std::vector<std::uint8_t> pending;
  std::size_t chunk = 64;
  bool up = true;
  long read(std::uint8_t* buf, std::size_t len) override {
    std::size_t n = pending.size() < len ? pending.size() : len;
    if (n > chunk) n = chunk;
    std::copy(pending.begin(), pending.begin() + static_cast<long>(n), buf);
    pending.erase(pending.begin(), pending.begin() + static_cast<long>(n));
    return static_cast<long>(n);
  }
  long write(const std::uint8_t*, std::size_t len) override { return static_cast<long>(len); }
  bool connected() const override { return up; }
};

class FixedClock final : public hal::Clock {
 public:
  std::uint64_t now_ns() const override { return 1'000'000'000; }
};

void check_scan(const hal::LaserScan& s) {
  check(s.beam_count >= 1 && s.beam_count <= hal::LaserScan::kMaxBeams, "delivered scan: beam count");
  check(std::isfinite(s.angle_min) && std::isfinite(s.angle_increment) && s.angle_increment > 0.0f,
        "delivered scan: angles");
  check(std::isfinite(s.range_max) && s.range_max > s.range_min && s.range_min >= 0.0f, "delivered scan: limits");
  for (std::uint32_t i = 0; i < s.beam_count; ++i) {
    check(std::isfinite(s.ranges[i]) && s.ranges[i] >= 0.0f && s.ranges[i] <= s.range_max, "delivered scan: reading");
  }
}

void append_telegram(StreamPort& port, std::uint8_t address, const std::vector<std::uint8_t>& payload) {
  std::uint8_t buf[hal_serial::kMaxTelegramBytes + 16];
  const std::size_t n = hal_serial::encode_sick_telegram(address, payload.data(), payload.size(), buf, sizeof buf);
  port.pending.insert(port.pending.end(), buf, buf + n);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::ByteReader in(data, size);
  StreamPort port;
  FixedClock clock;
  hal_serial::SickLaser laser;
  laser.init(&port, &clock, hal_serial::SickLaserOptions{});
  hal::LaserScan scan;
  auto poll = [&] {
    if (laser.poll(&scan)) check_scan(scan);
  };
  while (!in.exhausted()) {
    switch (in.u8() % fuzz::kSickNumOps) {
      case fuzz::kSickRaw: {
        const std::vector<std::uint8_t> b = in.blob();
        port.pending.insert(port.pending.end(), b.begin(), b.end());
        break;
      }
      case fuzz::kSickTelegram: {
        const std::uint8_t address = in.u8();
        append_telegram(port, address, in.blob());
        break;
      }
      case fuzz::kSickMeasured: {
        const std::uint8_t address = in.u8();
        const std::uint16_t word = in.u16();
        std::vector<std::uint8_t> p = {hal_serial::kRespMeasuredValues, static_cast<std::uint8_t>(word & 0xFF),
                                       static_cast<std::uint8_t>(word >> 8)};
        const std::size_t n = (word & 0x3FF) > 410 ? 410 : (word & 0x3FF);
        for (std::size_t i = 0; i < 2 * n; ++i) p.push_back(in.u8());
        p.push_back(in.u8());  // status
        append_telegram(port, address, p);
        break;
      }
      case fuzz::kSickPoll:
        port.chunk = std::size_t(in.u8()) + 1;
        poll();
        break;
      case fuzz::kSickReconnect:
        port.up = false;
        poll();  // a gone port is not read
        check(laser.fault_bits() != 0, "a disconnected port raises no fault");
        port.up = true;
        laser.restart();
        break;
    }
  }
  // Drain: every byte left is parsed; a bounded number of polls must consume it (no livelock).
  port.chunk = 1024;
  for (int i = 0; i < 64 && !port.pending.empty(); ++i) poll();
  check(port.pending.empty(), "driver stopped consuming input");
  poll();

  // The parser alone on the raw input: a reported telegram always has a valid CRC.
  hal_serial::SickParser parser;
  hal_serial::SickTelegram t;
  std::size_t off = 0;
  while (off < size) {
    const std::size_t k = parser.feed(data + off, size - off);
    off += k;
    bool any = false;
    while (parser.next(&t)) {
      any = true;
      std::uint8_t buf[hal_serial::kMaxTelegramBytes + 16];
      std::vector<std::uint8_t> payload = {t.command};
      payload.insert(payload.end(), t.data, t.data + (t.length ? t.length - 1 : 0));
      check(hal_serial::encode_sick_telegram(t.address, payload.data(), payload.size(), buf, sizeof buf) ==
                std::size_t(t.length) + 6, "parser reported a telegram that does not re-encode");
    }
    check(k > 0 || any || off >= size, "parser neither takes input nor yields a telegram");
    if (k == 0 && !any) break;
  }
  return 0;
}
