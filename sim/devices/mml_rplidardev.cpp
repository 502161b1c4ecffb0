// mml-rplidardev: a Slamtec RPLIDAR device model on a serial port (e.g. one end of a socat pty
// pair). Answers STOP / RESET / GET_HEALTH / GET_INFO / SCAN / FORCE_SCAN / EXPRESS_SCAN (legacy
// capsules) as --model does, then turns the head: one turn per CARMEN log scan at the model's rate
// (--rate overrides), its samples at angles not locked to the index (nearest beam of the log scan;
// outside the log's field of view: no measurement), sent in tenths of a turn. Faults:
//   --corrupt-every K     turn K: one sample's check bits broken (express: one byte, checksum)
//   --truncate-every K    turn K: two bytes of one sample lost (the framing shifts; express: half
//                         a capsule lost)
//   --garbage-every K     random bytes before turn K
//   --reset-at K          the device resets in the middle of turn K: its banner, then idle until
//                         the host asks again
//   --motor-stop-at K --motor-stop-s S   the motor stops in the middle of turn K for S seconds
//   --health-error 1      GET_HEALTH says error (code 0x8001) until a RESET
// Waits up to --wait S seconds for a request each time it is not streaming; prints a JSON summary
// (turns_sent: turns whose every sample and the next turn's start flag were sent).
//   mml-rplidardev --device PATH --dataset aces|--log PATH [--first N] [--count N] [--model a1]
//                  [--rate HZ] [--baud 115200] [faults] [--wait 5]
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "hal_serial/termios_port.h"
#include "sim/common/cli_main.h"
#include "sim/devices/device_cli.h"
#include "sim/devices/rplidar_device.h"

namespace {

int usage(const std::string& m) {
  std::fprintf(stderr, "mml-rplidardev: %s\n", m.c_str());
  return 2;
}

struct Faults {
  size_t corrupt = 0, truncate = 0, garbage = 0, reset_at = 0, stop_at = 0;
  double stop_s = 0.0;
};

struct Counts {
  size_t turns = 0, intact_turns = 0, corrupted = 0, truncated = 0, garbage = 0, resets = 0, motor_stops = 0, requests = 0;
};

// Damage to the bytes of one tenth of turn k (the middle tenth); true if it damaged them.
bool damage(const Faults& f, size_t k, bool express, std::mt19937* rng, std::string* bytes, Counts* c) {
  if (bytes->size() < 10) return false;
  if (f.corrupt && k % f.corrupt == 0) {
    const size_t rec = express ? 84 : 5;
    const size_t p = (bytes->size() / rec / 2) * rec;
    if (express) (*bytes)[p + 10] = static_cast<char>((*bytes)[p + 10] ^ 0x10);
    else (*bytes)[p] = static_cast<char>((*bytes)[p] | 0x3);  // S and !S both set
    ++c->corrupted;
    return true;
  }
  if (f.truncate && k % f.truncate == 0) {
    const size_t rec = express ? 84 : 5;
    const size_t p = (bytes->size() / rec / 2) * rec;
    bytes->erase(p, express ? 42 : 2);
    ++c->truncated;
    return true;
  }
  (void)rng;
  return false;
}

}  // namespace

static int run_main(int argc, char** argv) {
  sim::DeviceArgs a;
  std::string err;
  if (!a.parse(argc, argv, &err)) return usage(err);
  if (!a.has("device")) return usage("--device PATH is required");
  const sim::RplidarModel* model = sim::find_rplidar_model(a.str("model", "a1"));
  if (!model) return usage("--model '" + a.str("model", "") + "' unknown (" + sim::rplidar_model_names() + ")");
  sim::RplidarModel m = *model;
  if (a.has("rate")) m.rate_hz = a.num("rate", m.rate_hz);
  if (!(m.rate_hz > 0)) return usage("--rate must be positive");
  std::vector<sim::PolarScan> scans;
  if (!sim::load_device_scans(a, &scans, &err)) return usage(err);
  Faults f;
  f.corrupt = static_cast<size_t>(a.num("corrupt-every", 0));
  f.truncate = static_cast<size_t>(a.num("truncate-every", 0));
  f.garbage = static_cast<size_t>(a.num("garbage-every", 0));
  f.reset_at = static_cast<size_t>(a.num("reset-at", 0));
  f.stop_at = static_cast<size_t>(a.num("motor-stop-at", 0));
  f.stop_s = a.num("motor-stop-s", 0);
  const double wait_s = a.num("wait", 5);

  hal_serial::TermiosPort port;
  const fw::Status st = port.open(a.str("device", "").c_str(), static_cast<std::uint32_t>(a.num("baud", 115200)));
  if (!st) return usage(st.message());
  sim::RplidarDevice dev(m);
  if (a.num("health-error", 0) != 0) dev.set_health(hal_serial::kRplidarHealthError, 0x8001);
  std::mt19937 rng(1);
  Counts c;
  double next_t = 0, deadline = sim::device_now_s() + wait_s;
  bool was_streaming = false, damaged = false;
  size_t idx = 0, tenth = 0;  // turn (log scan) and tenth of it
  std::uint8_t buf[512];
  auto send = [&](const std::string& s) {
    return s.empty() || port.write(reinterpret_cast<const std::uint8_t*>(s.data()), s.size()) == static_cast<long>(s.size());
  };
  while (idx < scans.size()) {
    port.wait_readable(2);
    const long n = port.read(buf, sizeof(buf));
    if (n > 0) {
      std::string out;
      dev.receive(buf, static_cast<size_t>(n), &out);
      if (!send(out)) break;
    }
    const double now = sim::device_now_s();
    if (!dev.streaming()) {
      was_streaming = false;
      if (now > deadline) break;
      continue;
    }
    if (!was_streaming) {  // a new SCAN: the turns start again with a start flag
      was_streaming = true;
      ++c.requests;
      next_t = now + 0.02;
      tenth = 0;
      damaged = false;
    }
    deadline = now + wait_s;
    if (now < next_t) continue;
    const size_t k = idx + 1;
    const size_t per_turn = dev.samples_per_turn();
    const size_t chunk = dev.express() ? 32 * ((per_turn / 32 + 9) / 10) : (per_turn + 9) / 10;
    std::string bytes;
    if (tenth == 0 && f.garbage && k % f.garbage == 0) {
      for (int g = 0; g < 7; ++g) bytes += static_cast<char>(rng());
      ++c.garbage;
    }
    std::string samples;
    const size_t turns = dev.samples(scans[idx], chunk, &samples);
    if (tenth == 5) damaged = damage(f, k, dev.express(), &rng, &samples, &c) || damaged;
    bytes += samples;
    if (tenth == 5 && f.reset_at == k) {  // reset mid-turn: the banner, then idle
      std::string banner;
      dev.power_cycle(&banner);
      if (!send(bytes + banner)) break;
      ++c.resets;
      f.reset_at = 0;
      ++idx;
      continue;
    }
    if (!send(bytes)) return usage("write to " + a.str("device", "") + " failed");
    next_t += 1.0 / m.rate_hz / 10.0;
    if (tenth == 5 && f.stop_at == k && f.stop_s > 0) {  // the motor stops: nothing for stop_s
      next_t += f.stop_s;
      ++c.motor_stops;
      f.stop_at = 0;
    }
    if (turns > 0) {  // the head passed 0°: the log scan's turn is complete
      ++c.turns;
      if (!damaged) ++c.intact_turns;
      ++idx;
      damaged = false;
    }
    tenth = turns > 0 ? 0 : tenth + 1;
  }
  if (dev.streaming() && !scans.empty()) {  // the start flag that closes the last turn
    std::string last;
    dev.samples(scans.back(), dev.express() ? 32 : 1, &last);
    send(last);
  }
  std::printf("{\"model\": \"%s\", \"requests\": %zu, \"turns_sent\": %zu, \"intact_turns\": %zu, \"corrupted\": %zu, "
              "\"truncated\": %zu, \"garbage_bursts\": %zu, \"resets\": %zu, \"motor_stops\": %zu, \"commands\": %zu, "
              "\"rate_hz\": %.2f, \"express\": %s}\n",
              m.name, c.requests, c.turns, c.intact_turns, c.corrupted, c.truncated, c.garbage, c.resets,
              c.motor_stops, dev.commands(), m.rate_hz, dev.express() ? "true" : "false");
  return 0;
}

int main(int argc, char** argv) {
  return sim::guarded_main("mml-rplidardev", [&] { return run_main(argc, argv); });
}
