// libFuzzer target: Hokuyo SCIP 2.0 line parser, scan / parameter decoders and the HokuyoLaser
// driver (handshake, timeouts, restarts) over an in-memory byte stream (hal/serial, issue 59).
// Oracle beyond "no crash, no hang": every scan the driver delivers is usable (beam count within
// capacity, finite geometry, readings within [0, range_max]), the driver consumes all input in a
// bounded number of polls, and a decoded scan never has more values than its capacity.
#include <string>
#include <vector>

#include "hal_serial/hokuyo_laser.h"
#include "hal_serial/scip.h"
#include "tests/fuzz/byte_reader.h"
#include "tests/fuzz/serial_fuzz_port.h"
#include "tests/fuzz/serial_lidar_fuzz_ops.h"

namespace {

constexpr const char* kTarget = "fuzz_scip";

void append(fuzz::StreamPort& port, const char* s, std::size_t n) { port.pending.insert(port.pending.end(), s, s + n); }

std::string text(const std::vector<std::uint8_t>& b, std::size_t max) {
  std::string s(b.begin(), b.end());
  if (s.size() > max) s.resize(max);
  return s;
}

void scan_op(fuzz::ByteReader& in, fuzz::StreamPort& port) {
  static const char* const kKinds[] = {"MD", "ME", "MS"};
  const char* kind = kKinds[in.u8() % 3];
  const unsigned start = in.u16() % 10000, end = in.u16() % 10000, cluster = in.u8() % 100;
  const std::uint32_t ts = in.u32();
  const std::size_t n = in.u16() % 1200;
  static std::uint32_t values[1200];
  for (std::size_t i = 0; i < n; ++i) values[i] = in.u32();
  char echo[32];
  std::snprintf(echo, sizeof echo, "%s%04u%04u%02u000", kind, start, end, cluster);
  static char out[20000];
  const std::size_t k = hal_serial::encode_scip_scan(echo, ts, values, kind[1] == 'E' ? values : nullptr, n,
                                                     kind[1] == 'S' ? 2 : 3, out, sizeof out);
  append(port, out, k);
}

void info_op(fuzz::ByteReader& in, fuzz::StreamPort& port) {
  const std::string echo = text(in.blob(), 20);
  const std::string body = text(in.blob(), 600);
  std::vector<std::string> lines;
  std::size_t p = 0;
  while (p <= body.size() && lines.size() < 12) {
    const std::size_t nl = body.find('\n', p);
    lines.push_back(body.substr(p, nl == std::string::npos ? std::string::npos : nl - p));
    if (nl == std::string::npos) break;
    p = nl + 1;
  }
  std::vector<const char*> ptrs;
  for (const std::string& l : lines) ptrs.push_back(l.c_str());
  static char out[4096];
  append(port, out, hal_serial::encode_scip_info(echo.c_str(), ptrs.data(), ptrs.size(), out, sizeof out));
}

void parser_alone(const std::uint8_t* data, std::size_t size) {
  hal_serial::ScipParser parser;
  static hal_serial::ScipResponse r;
  static hal_serial::ScipScan s;
  hal_serial::ScipParameters pp;
  std::size_t off = 0;
  while (off < size) {
    off += parser.feed(data + off, size - off);
    while (parser.next(&r)) {
      fuzz::serial_check(r.data_len <= hal_serial::kScipMaxData && r.echo_len <= hal_serial::kScipMaxLine, kTarget,
                         "answer beyond its buffers");
      if (hal_serial::decode_scip_scan(r, &s).is_ok()) {
        fuzz::serial_check(s.count <= hal_serial::kScipMaxSteps, kTarget, "decoded more values than steps");
      }
      if (hal_serial::decode_scip_parameters(r, &pp).is_ok()) {
        fuzz::serial_check(pp.ares > 0 && pp.amin <= pp.amax && pp.dmin_mm < pp.dmax_mm, kTarget, "impossible PP accepted");
      }
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::ByteReader in(data, size);
  fuzz::StreamPort port;
  fuzz::InputClock clock;
  static hal_serial::HokuyoLaser laser;
  hal_serial::HokuyoOptions o;
  o.intensity = (in.u8() & 1) != 0;
  laser.init(&port, &clock, o);
  laser.start();
  static hal::LaserScan scan;
  auto poll = [&] {
    if (laser.poll(&scan)) fuzz::check_delivered_scan(scan, kTarget);
  };
  while (!in.exhausted()) {
    switch (in.u8() % fuzz::kScipNumOps) {
      case fuzz::kScipRaw: {
        const std::vector<std::uint8_t> b = in.blob();
        port.pending.insert(port.pending.end(), b.begin(), b.end());
        break;
      }
      case fuzz::kScipStatus: {
        const std::string echo = text(in.blob(), 40);
        const char status[3] = {static_cast<char>(in.u8()), static_cast<char>(in.u8()), 0};
        char out[128];
        append(port, out, hal_serial::encode_scip_status(echo.c_str(), status, out, sizeof out));
        break;
      }
      case fuzz::kScipInfo: info_op(in, port); break;
      case fuzz::kScipScan: scan_op(in, port); break;
      case fuzz::kScipPoll:
        port.chunk = std::size_t(in.u8()) * 32 + 1;
        poll();
        break;
      case fuzz::kScipAdvance: clock.t += std::uint64_t(in.u16()) * 1'000'000; break;
      case fuzz::kScipReconnect:
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
