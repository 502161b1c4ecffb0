// mml-sickdev: a SICK LMS2xx device model on a serial port (e.g. one end of a socat pty pair).
// Waits (up to --wait S seconds) for the host's "continuous output" request, answers ACK + 0xA0,
// then streams the scans of a CARMEN log as 0xB0 measured-value telegrams (cm units, 0x1FFF = no
// return) at --rate Hz. --corrupt-every K flips a byte in every K-th telegram (bad CRC);
// --garbage-every K writes random bytes before every K-th telegram. Prints a JSON summary.
//   mml-sickdev --device PATH --dataset aces|--log PATH [--first N] [--count N] [--rate 75]
//               [--baud 500000] [--corrupt-every K] [--garbage-every K] [--wait 5]
//               [--pause-at K --pause-s S]   (silent for S seconds before telegram K)
#include <time.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "hal_serial/sick_telegram.h"
#include "hal_serial/termios_port.h"
#include "sim/io/carmen_log.h"
#include "sim/io/datasets.h"
#include "sim/common/cli_main.h"

namespace {
int usage(const std::string& m) {
  std::fprintf(stderr, "mml-sickdev: %s\n", m.c_str());
  return 2;
}
double now_s() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t.tv_sec + t.tv_nsec * 1e-9;
}
void sleep_until(double t) {
  for (;;) {
    const double d = t - now_s();
    if (d <= 0) return;
    timespec ts{static_cast<time_t>(d), static_cast<long>((d - std::floor(d)) * 1e9)};
    nanosleep(&ts, nullptr);
  }
}
}  // namespace

constexpr const char* kHelp =
    "mml-sickdev: a SICK LMS2xx device model on a serial port (e.g. one end of a socat pty pair).\n"
    "Waits for the host's continuous-output request, answers ACK + 0xA0, then streams the scans of\n"
    "a CARMEN log as 0xB0 measured-value telegrams at --rate Hz; prints a JSON summary.\n"
    "  mml-sickdev --device PATH --dataset aces|--log PATH [--first N] [--count N] [--rate 75]\n"
    "              [--baud 500000] [--corrupt-every K] [--garbage-every K] [--wait 5]\n"
    "              [--pause-at K --pause-s S]\n"
    "  --corrupt-every K   flip a byte in every K-th telegram (bad CRC)\n"
    "  --garbage-every K   random bytes before every K-th telegram\n"
    "  --pause-at K --pause-s S   silent for S seconds before telegram K\n";

static int run_main(int argc, char** argv) {
  if (argc == 2 && (std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h")) {
    std::fputs(kHelp, stdout);
    return 0;
  }
  std::map<std::string, std::string> kv;
  for (int i = 1; i < argc; ++i) {
    std::string k = argv[i];
    if (k.rfind("--", 0) != 0 || i + 1 >= argc) return usage("bad argument '" + k + "'");
    kv[k.substr(2)] = argv[++i];
  }
  auto num = [&](const char* k, double d) {
    auto it = kv.find(k);
    return it == kv.end() ? d : std::strtod(it->second.c_str(), nullptr);
  };
  if (!kv.count("device")) return usage("--device PATH is required");
  std::string path = kv.count("log") ? kv["log"] : "";
  if (kv.count("dataset")) {
    const sim::Dataset* ds = sim::find_dataset(kv["dataset"]);
    if (!ds || ds->raw_log.empty()) return usage("--dataset '" + kv["dataset"] + "' unknown or without raw log");
    path = sim::data_path(ds->raw_log);
  }
  if (path.empty()) return usage("need --dataset or --log");
  const size_t first = static_cast<size_t>(num("first", 0)), count = static_cast<size_t>(num("count", 100));
  const double rate = num("rate", 75);
  const size_t corrupt = static_cast<size_t>(num("corrupt-every", 0)), garbage = static_cast<size_t>(num("garbage-every", 0));
  if (!(rate > 0)) return usage("--rate must be positive");
  sim::CarmenLog log;
  std::string err;
  sim::CarmenReadOptions ro;
  ro.max_scans = first + count;
  if (!sim::read_carmen_log(path, ro, &log, &err)) return usage(err);
  if (first >= log.scans.size()) return usage("--first beyond the log");

  hal_serial::TermiosPort port;
  fw::Status st = port.open(kv["device"].c_str(), static_cast<std::uint32_t>(num("baud", 500000)));
  if (!st) return usage(st.message());
  // Wait for the request for continuous output.
  hal_serial::SickParser parser;
  hal_serial::SickTelegram t;
  std::uint8_t buf[hal_serial::kMaxTelegramBytes];
  bool requested = false;
  const double wait_until = now_s() + num("wait", 5);
  while (!requested && now_s() < wait_until) {
    port.wait_readable(20);
    const long n = port.read(buf, sizeof(buf));
    if (n > 0) parser.feed(buf, static_cast<size_t>(n));
    while (parser.next(&t))
      if (t.command == hal_serial::kCmdModeChange && t.data[0] == hal_serial::kModeContinuousAll) requested = true;
  }
  if (requested) {
    const std::uint8_t ack = hal_serial::kAck;
    port.write(&ack, 1);
    const std::uint8_t resp[] = {hal_serial::kRespModeChange, 0x00, 0x10};
    const size_t n = hal_serial::encode_sick_telegram(hal_serial::kDeviceAddressBit, resp, sizeof(resp), buf, sizeof(buf));
    port.write(buf, n);
  }
  std::mt19937 rng(1);
  size_t sent = 0, corrupted = 0, garbage_sent = 0;
  double t0 = now_s() + 0.05;
  // Laser silence (fault campaign): before telegram number pause_at the scanner says nothing for
  // pause_s seconds, then streams on at the rate.
  const size_t pause_at = static_cast<size_t>(num("pause-at", 0));
  const double pause_s = num("pause-s", 0);
  for (size_t i = first; i < log.scans.size() && sent < count; ++i) {
    const sim::CarmenScan& s = log.scans[i];
    hal_serial::MeasuredValues v;
    v.count = static_cast<std::uint16_t>(std::min<size_t>(s.ranges.size(), hal_serial::kMaxMeasuredValues));
    for (size_t b = 0; b < v.count; ++b) {
      const double cm = std::round(s.ranges[b] * 100.0);
      v.values[b] = (!(cm >= 0) || cm >= hal_serial::kSickNoReturn || s.ranges[b] >= s.max_range)
                        ? hal_serial::kSickNoReturn
                        : static_cast<std::uint16_t>(cm);
    }
    size_t n = hal_serial::encode_measured_values(v, buf, sizeof(buf));
    const size_t k = sent + 1;
    if (garbage && k % garbage == 0) {
      std::uint8_t g[17];
      for (auto& x : g) x = static_cast<std::uint8_t>(rng());
      g[3] = hal_serial::kStx;
      port.write(g, sizeof(g));
      ++garbage_sent;
    }
    if (corrupt && k % corrupt == 0) {
      buf[8 + rng() % (n - 10)] ^= 0x10;
      ++corrupted;
    }
    if (pause_at > 0 && k == pause_at && pause_s > 0) t0 += pause_s;
    sleep_until(t0 + static_cast<double>(sent) / rate);
    if (port.write(buf, n) != static_cast<long>(n)) return usage("write to " + kv["device"] + " failed");
    ++sent;
  }
  std::printf("{\"requested\": %s, \"telegrams_sent\": %zu, \"corrupted\": %zu, \"garbage_bursts\": %zu, \"rate_hz\": %.1f}\n",
              requested ? "true" : "false", sent, corrupted, garbage_sent, rate);
  return 0;
}

int main(int argc, char** argv) {
  return sim::guarded_main("mml-sickdev", [&] { return run_main(argc, argv); });
}
