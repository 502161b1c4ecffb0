// mml-hokuyodev: a Hokuyo (SCIP 2.0) device model on a serial port (e.g. one end of a socat pty
// pair). Answers the host's SCIP2.0 / QT / VV / PP / II / BM / MD|ME with the PP geometry of
// --model, then streams the scans of a CARMEN log as MD/ME answers at --rate Hz (nearest beam per
// step; steps outside the log's field of view report the "no object" code). Faults:
//   --corrupt-every K   one data character of every K-th answer changed (its line sum is wrong)
//   --truncate-every K  every K-th answer stops after half its data lines (lost bytes)
//   --garbage-every K   a line of noise before every K-th answer
//   --reset-at K        the device resets in the middle of answer K: half of it, then silence
//                       until the host asks again (MD forgotten; its clock starts again at 0)
//   --pause-at K --pause-s S  silent for S seconds before answer K
//   --timestamp-start MS     the sensor clock's first value (16777000: wraps after 0.2 s)
// Waits up to --wait S seconds for a request each time it is not streaming. Prints a JSON summary.
//   mml-hokuyodev --device PATH --dataset aces|--log PATH [--first N] [--count N] [--rate 40]
//                 [--model utm-30lx] [--baud 115200] [faults] [--wait 5]
#include <cstdio>
#include <string>
#include <vector>

#include "hal_serial/termios_port.h"
#include "sim/common/cli_main.h"
#include "sim/devices/device_cli.h"
#include "sim/devices/hokuyo_device.h"

namespace {

int usage(const std::string& m) {
  std::fprintf(stderr, "mml-hokuyodev: %s\n", m.c_str());
  return 2;
}

struct Faults {
  size_t corrupt = 0, truncate = 0, garbage = 0, reset_at = 0, pause_at = 0;
  double pause_s = 0.0;
};

struct Counts {
  size_t answers = 0, intact = 0, corrupted = 0, truncated = 0, garbage = 0, resets = 0, requests = 0;
};

// The answer as the faults leave it; true when it is still intact.
bool apply_faults(const Faults& f, size_t k, std::string* ans, Counts* c) {
  if (f.corrupt && k % f.corrupt == 0) {
    // A character of a data line (after echo, status and time stamp lines), not a line feed.
    size_t p = ans->size() / 2;
    while (p < ans->size() && ((*ans)[p] == '\n' || (*ans)[p + 1] == '\n')) ++p;
    (*ans)[p] = (*ans)[p] == '0' ? '1' : '0';
    ++c->corrupted;
    return false;
  }
  if (f.truncate && k % f.truncate == 0) {
    // Keep whole lines: the echo of the next answer then tells the host this one was cut short.
    size_t lines = 0, p = 0;
    while (p < ans->size() && lines < 3 + (ans->size() / 66) / 2) {
      if ((*ans)[p] == '\n') ++lines;
      ++p;
    }
    ans->resize(p);
    ++c->truncated;
    return false;
  }
  return true;
}

}  // namespace

static int run_main(int argc, char** argv) {
  sim::DeviceArgs a;
  std::string err;
  if (!a.parse(argc, argv, &err)) return usage(err);
  if (!a.has("device")) return usage("--device PATH is required");
  const sim::HokuyoModel* model = sim::find_hokuyo_model(a.str("model", "utm-30lx"));
  if (!model) return usage("--model '" + a.str("model", "") + "' unknown (" + sim::hokuyo_model_names() + ")");
  const double rate = a.num("rate", 40);
  if (!(rate > 0)) return usage("--rate must be positive");
  std::vector<sim::PolarScan> scans;
  if (!sim::load_device_scans(a, &scans, &err)) return usage(err);
  Faults f;
  f.corrupt = static_cast<size_t>(a.num("corrupt-every", 0));
  f.truncate = static_cast<size_t>(a.num("truncate-every", 0));
  f.garbage = static_cast<size_t>(a.num("garbage-every", 0));
  f.reset_at = static_cast<size_t>(a.num("reset-at", 0));
  f.pause_at = static_cast<size_t>(a.num("pause-at", 0));
  f.pause_s = a.num("pause-s", 0);
  const double wait_s = a.num("wait", 5);
  std::uint32_t ts0 = static_cast<std::uint32_t>(a.num("timestamp-start", 0));

  hal_serial::TermiosPort port;
  const fw::Status st = port.open(a.str("device", "").c_str(), static_cast<std::uint32_t>(a.num("baud", 115200)));
  if (!st) return usage(st.message());
  sim::HokuyoDevice dev(*model);
  Counts c;
  double clock0 = sim::device_now_s(), next_t = 0, deadline = sim::device_now_s() + wait_s;
  bool was_streaming = false;
  size_t idx = 0;
  std::uint8_t buf[512];
  while (idx < scans.size()) {
    port.wait_readable(2);
    const long n = port.read(buf, sizeof(buf));
    if (n > 0) {
      std::string out;
      dev.receive(buf, static_cast<size_t>(n), &out);
      if (!out.empty() && port.write(reinterpret_cast<const std::uint8_t*>(out.data()), out.size()) < 0) break;
    }
    const double now = sim::device_now_s();
    if (!dev.streaming()) {
      was_streaming = false;
      if (now > deadline) break;  // nobody asks any more
      continue;
    }
    if (!was_streaming) {
      was_streaming = true;
      ++c.requests;
      next_t = now + 0.02;
    }
    deadline = now + wait_s;
    const size_t k = c.answers + 1;
    if (f.pause_at == k && f.pause_s > 0) {
      next_t += f.pause_s;
      f.pause_at = 0;
    }
    if (now < next_t) continue;
    const std::uint32_t ts = (ts0 + static_cast<std::uint32_t>((now - clock0) * 1000.0)) & 0xFFFFFF;
    std::string ans = dev.scan_answer(scans[idx], ts);
    if (f.garbage && k % f.garbage == 0) {
      ans = "#$%&'()*+,-./noise line\n" + ans;
      ++c.garbage;
    }
    ++c.answers;
    ++idx;
    next_t += 1.0 / rate;
    if (f.reset_at == k) {  // reset mid-answer: half of it, then a device that forgot MD
      ans.resize(ans.size() / 2);
      port.write(reinterpret_cast<const std::uint8_t*>(ans.data()), ans.size());
      dev.power_cycle();
      ++c.resets;
      clock0 = now;  // its clock starts again
      ts0 = 0;
      continue;
    }
    if (apply_faults(f, k, &ans, &c)) ++c.intact;
    if (port.write(reinterpret_cast<const std::uint8_t*>(ans.data()), ans.size()) != static_cast<long>(ans.size())) {
      return usage("write to " + a.str("device", "") + " failed");
    }
  }
  std::printf("{\"model\": \"%s\", \"requests\": %zu, \"answers_sent\": %zu, \"intact\": %zu, \"corrupted\": %zu, "
              "\"truncated\": %zu, \"garbage_lines\": %zu, \"resets\": %zu, \"commands\": %zu, \"rate_hz\": %.1f}\n",
              model->name, c.requests, c.answers, c.intact, c.corrupted, c.truncated, c.garbage, c.resets,
              dev.commands(), rate);
  return 0;
}

int main(int argc, char** argv) {
  return sim::guarded_main("mml-hokuyodev", [&] { return run_main(argc, argv); });
}
