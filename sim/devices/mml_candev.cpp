// mml-candev: the CAN side of the simulator for hardware-in-the-loop runs.
//   mml-candev log2can --dataset aces|--log PATH [--first N] [--count N] [--fd] [--iface vcan0]
//                      [--speed S] [--corrupt-every K] [--drop-every K] [--dup-every K]
//                      [--bus-off-at K --bus-off-burst N] [--invalid-every K] [--swap-every K]
//                      [--silence-at K --silence-s S] [--odom-jump-at K --odom-jump-m M]
//                      [--odom-reset-at K] [--time-jump-at K --time-jump-s S] --out replay.log
//       (fault campaign options: sim/devices/can_traffic.h)
//       → a candump log canplayer replays (`canplayer -I replay.log`); prints a JSON summary.
//   mml-candev live ... --iface vcan0 (same options, no --out): sends the frames onto the interface
//       with their timing (SocketCAN; needs a kernel with CAN).
//   mml-candev score --dataset aces|--log PATH --capture dump.log [--first N] [--count N]
//                    [--bound M] [--json out.json]
//       → decodes the firmware's pose/health frames from `candump -L` output and scores them
//         against the reference trajectory (reference_at_every_scan).
#include <time.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "hal_socketcan/socketcan_bus.h"
#include "sim/devices/can_traffic.h"
#include "sim/devices/candump_log.h"
#include "sim/io/datasets.h"
#include "sim/io/reference_trajectory.h"
#include "sim/common/cli_main.h"

namespace {

int usage(const char* msg) {
  std::fprintf(stderr, "mml-candev: %s\nusage: mml-candev log2can|live|score [options] (see the source header)\n", msg);
  return 2;
}

struct Args {
  std::map<std::string, std::string> kv;
  bool has(const std::string& k) const { return kv.count(k) != 0; }
  std::string get(const std::string& k, const std::string& d = "") const {
    auto it = kv.find(k);
    return it == kv.end() ? d : it->second;
  }
  bool num(const std::string& k, double* v, std::string* err) const {
    if (!has(k)) return true;
    char* e = nullptr;
    const std::string s = get(k);
    *v = std::strtod(s.c_str(), &e);
    if (e == s.c_str() || *e || !std::isfinite(*v) || *v < 0) {
      *err = "--" + k + ": '" + s + "' is not a non-negative number";
      return false;
    }
    return true;
  }
};

bool load_log(const Args& a, sim::CarmenLog* log, std::string* err, std::string* poses_path) {
  std::string path = a.get("log");
  if (a.has("dataset")) {
    const sim::Dataset* ds = sim::find_dataset(a.get("dataset"));
    if (!ds || ds->raw_log.empty()) {
      *err = "--dataset '" + a.get("dataset") + "': unknown or without a raw log";
      return false;
    }
    path = sim::data_path(ds->raw_log);
    if (poses_path && !ds->corrected_poses.empty()) *poses_path = sim::data_path(ds->corrected_poses);
  }
  if (a.has("poses") && poses_path) *poses_path = a.get("poses");
  if (path.empty()) {
    *err = "need --dataset NAME or --log PATH";
    return false;
  }
  sim::CarmenReadOptions ro;
  return sim::read_carmen_log(path, ro, log, err);
}

std::uint64_t mono_ns() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return static_cast<std::uint64_t>(t.tv_sec) * 1000000000ull + t.tv_nsec;
}

// Reads "--key value" pairs (and the flag --fd) after the command into *a. Set: the exit code of the
// usage error reported.
std::optional<int> parse_options(int argc, char** argv, Args* a) {
  for (int i = 2; i < argc; ++i) {
    std::string k = argv[i];
    if (k.rfind("--", 0) != 0) return usage(("unexpected argument '" + k + "'").c_str());
    k = k.substr(2);
    if (k == "fd") { a->kv[k] = "1"; continue; }
    if (i + 1 >= argc) return usage(("--" + k + " needs a value").c_str());
    a->kv[k] = argv[++i];
  }
  return std::nullopt;
}

// The numeric options (non-negative; the signed ones are read where they are used).
struct Numbers {
  double first = 0, count = 0, speed = 1, corrupt = 0, drop = 0, dup = 0, boff_at = 0, boff_n = 0, bound = 1.0;
  double invalid = 0, swap = 0, silence_at = 0, silence_s = 0, jump_at = 0, reset_at = 0, tj_at = 0;
};

bool read_numbers(const Args& a, Numbers* n, std::string* err) {
  return a.num("first", &n->first, err) && a.num("count", &n->count, err) && a.num("speed", &n->speed, err) &&
         a.num("corrupt-every", &n->corrupt, err) && a.num("drop-every", &n->drop, err) &&
         a.num("dup-every", &n->dup, err) && a.num("bus-off-at", &n->boff_at, err) &&
         a.num("bus-off-burst", &n->boff_n, err) && a.num("bound", &n->bound, err) &&
         a.num("invalid-every", &n->invalid, err) && a.num("swap-every", &n->swap, err) &&
         a.num("silence-at", &n->silence_at, err) && a.num("silence-s", &n->silence_s, err) &&
         a.num("odom-jump-at", &n->jump_at, err) && a.num("odom-reset-at", &n->reset_at, err) &&
         a.num("time-jump-at", &n->tj_at, err);
}

// The traffic and its fault campaign (sim/devices/can_traffic.h).
sim::CanTrafficOptions traffic_options(const Args& a, const Numbers& n) {
  sim::CanTrafficOptions o;
  o.fd = a.has("fd");
  o.first_scan = static_cast<size_t>(n.first);
  o.num_scans = static_cast<size_t>(n.count);
  o.speed = n.speed > 0 ? n.speed : 1.0;
  o.corrupt_every = static_cast<size_t>(n.corrupt);
  o.drop_every = static_cast<size_t>(n.drop);
  o.duplicate_every = static_cast<size_t>(n.dup);
  o.bus_off_at = static_cast<size_t>(n.boff_at);
  o.bus_off_burst = static_cast<size_t>(n.boff_n);
  o.invalid_every = static_cast<size_t>(n.invalid);
  o.swap_every = static_cast<size_t>(n.swap);
  o.silence_at = static_cast<size_t>(n.silence_at);
  o.silence_s = n.silence_s;
  o.odom_jump_at = static_cast<size_t>(n.jump_at);
  o.odom_reset_at = static_cast<size_t>(n.reset_at);
  o.time_jump_at = static_cast<size_t>(n.tj_at);
  // Signed values (a.num accepts non-negative numbers only).
  if (a.has("odom-jump-m")) o.odom_jump_m = std::strtod(a.get("odom-jump-m").c_str(), nullptr);
  if (a.has("time-jump-s")) o.time_jump_s = std::strtod(a.get("time-jump-s").c_str(), nullptr);
  return o;
}

// live: sends the frames onto the interface at their times. 0, or the exit code of the failure
// reported.
int send_live(const std::string& iface, const std::vector<sim::TimedFrame>& frames) {
  hal_socketcan::SocketCanBus bus;
  fw::Status st = bus.open(iface.c_str());
  if (!st.is_ok()) {
    std::fprintf(stderr, "mml-candev: %s\n", st.message());
    return 1;
  }
  const std::uint64_t t0 = mono_ns();
  size_t failed = 0;
  for (const auto& tf : frames) {
    if (tf.error_frame) continue;  // error frames need can-utils (cansend) on the live path
    const std::uint64_t due = t0 + static_cast<std::uint64_t>((tf.t - frames.front().t) * 1e9);
    while (mono_ns() < due) {
      const std::uint64_t d = due - mono_ns();
      timespec ts{static_cast<time_t>(d / 1000000000ull), static_cast<long>(d % 1000000000ull)};
      nanosleep(&ts, nullptr);
    }
    if (!bus.send(tf.frame)) ++failed;
  }
  std::fprintf(stderr, "mml-candev live: %zu frames sent, %zu failed\n", frames.size() - failed, failed);
  return 0;
}

void print_traffic_summary(const sim::CanTrafficSummary& s) {
  std::printf("{\"scans_sent\": %zu, \"scans_intact\": %zu, \"scans_corrupted\": %zu, \"scans_missing_segment\": %zu, "
              "\"scans_duplicated\": %zu, \"odometry_sent\": %zu, \"frames\": %zu, \"error_frames\": %zu, "
              "\"duration_s\": %.3f, \"scans_invalid\": %zu, \"scans_swapped\": %zu, \"scans_silenced\": %zu}\n",
              s.scans_sent, s.scans_intact, s.scans_corrupted, s.scans_missing_segment, s.scans_duplicated,
              s.odometry_sent, s.frames, s.error_frames, s.duration_s, s.scans_invalid, s.scans_swapped,
              s.scans_silenced);
}

// log2can (to a candump log) and live (onto the interface).
int run_traffic(const std::string& cmd, const Args& a, const Numbers& n, const sim::CarmenLog& log,
                const std::string& iface) {
  std::string err;
  std::vector<sim::TimedFrame> frames;
  sim::CanTrafficSummary s;
  if (!sim::build_can_traffic(log, traffic_options(a, n), &frames, &s, &err)) {
    std::fprintf(stderr, "mml-candev: %s\n", err.c_str());
    return 1;
  }
  if (cmd == "log2can") {
    if (!a.has("out")) return usage("log2can needs --out FILE");
    if (!sim::write_candump_log(a.get("out"), iface, frames, &err)) {
      std::fprintf(stderr, "mml-candev: %s\n", err.c_str());
      return 1;
    }
  } else {
    const int rc = send_live(iface, frames);
    if (rc != 0) return rc;
  }
  print_traffic_summary(s);
  return 0;
}

// The score as one JSON object (printed, and written to --json).
std::string score_json(const sim::PoseScore& s) {
  char buf[2048];
  std::snprintf(buf, sizeof(buf),
                "{\"frames\": %zu, \"poses\": %zu, \"health\": %zu, \"searching\": %zu, \"ambiguous\": %zu, "
                "\"localized\": %zu, \"outside_map\": %zu, \"fault\": %zu, \"wrong_localized\": %zu, "
                "\"scored\": %zu, \"mean_err_m\": %.4f, \"max_err_m\": %.4f, \"mean_err_localized_m\": %.4f, "
                "\"max_err_localized_m\": %.4f, \"first_localized_scan\": %zu, \"violations\": %zu, "
                "\"health_crc_errors\": %u, \"health_lost_segments\": %u, \"health_dropped_scans\": %u, "
                "\"health_timeouts\": %u, \"health_deadline_misses\": %u, \"health_bus_off\": %u, "
                "\"health_error_frames\": %u, \"health_rx_dropped\": %u, \"health_scans_processed\": %u, "
                "\"health_state\": %u, \"health_fault_bits\": %u, \"health_invalid_scans\": %u, "
                "\"fault_updates\": %zu, \"health_fault_bits_seen\": %u, \"health_fault_clears\": %zu}",
                s.frames, s.poses, s.health, s.status_counts[0], s.status_counts[1], s.status_counts[2],
                s.status_counts[3], s.status_counts[4], s.wrong_localized, s.scored, s.mean_err_m, s.max_err_m,
                s.mean_err_localized_m, s.max_err_localized_m, s.first_localized_scan, s.violations.size(),
                s.last_health.crc_errors, s.last_health.lost_segments, s.last_health.dropped_scans,
                s.last_health.timeouts, s.last_health.deadline_misses, s.last_health.bus_off,
                s.last_health.error_frames, s.last_health.rx_dropped, s.last_health.scans_processed,
                s.last_health.state, s.last_health.fault_bits, s.last_health.invalid_scans, s.fault_updates,
                s.health_fault_bits_seen, s.health_fault_clears);
  return buf;
}

// The frames of a `candump -L` capture, error frames left out. False with *err.
bool read_capture(const std::string& path, std::vector<hal::CanFrame>* frames, std::string* err) {
  std::vector<sim::CanLogLine> lines;
  if (!sim::read_candump_log(path, &lines, err)) return false;
  for (const auto& l : lines)
    if (!l.error_frame) frames->push_back(l.frame);
  return true;
}

// score: the firmware's pose/health frames of a capture against the reference trajectory.
int run_score(const Args& a, const Numbers& n, const sim::CarmenLog& log, const std::string& poses_path) {
  if (!a.has("capture")) return usage("score needs --capture FILE (candump -L output)");
  std::string err;
  std::vector<hal::CanFrame> frames;
  if (!read_capture(a.get("capture"), &frames, &err)) {
    std::fprintf(stderr, "mml-candev: %s\n", err.c_str());
    return 1;
  }
  std::vector<fw::Se2d> ref;
  if (!poses_path.empty()) {
    std::vector<sim::CorrectedPose> corrected;
    if (!sim::read_corrected_poses(poses_path, &corrected, &err)) {
      std::fprintf(stderr, "mml-candev: %s\n", err.c_str());
      return 1;
    }
    ref = sim::reference_at_every_scan(log, corrected);
  }
  sim::PoseScoreOptions so;
  so.first_scan = static_cast<size_t>(n.first);
  so.num_scans = static_cast<size_t>(n.count);
  so.localized_bound_m = n.bound;
  std::FILE* dump = nullptr;
  if (a.has("dump")) {
    dump = std::fopen(a.get("dump").c_str(), "w");
    if (!dump) return usage(("cannot write --dump " + a.get("dump")).c_str());
    so.dump = dump;
  }
  sim::PoseScore s = sim::score_pose_frames(frames, ref, so);
  if (dump) std::fclose(dump);
  const std::string json = score_json(s);
  std::printf("%s\n", json.c_str());
  for (const auto& v : s.violations) std::fprintf(stderr, "protocol violation: %s\n", v.c_str());
  if (a.has("json")) {
    std::ofstream(a.get("json")) << json << "\n";
  }
  return 0;
}

}  // namespace

constexpr const char* kHelp =
    "mml-candev: the CAN side of the simulator for hardware-in-the-loop runs.\n"
    "  mml-candev log2can --dataset aces|--log PATH [--first N] [--count N] [--fd] [--iface vcan0]\n"
    "                     [--speed S] [--corrupt-every K] [--drop-every K] [--dup-every K]\n"
    "                     [--bus-off-at K --bus-off-burst N] [--invalid-every K] [--swap-every K]\n"
    "                     [--silence-at K --silence-s S] [--odom-jump-at K --odom-jump-m M]\n"
    "                     [--odom-reset-at K] [--time-jump-at K --time-jump-s S] --out replay.log\n"
    "      a candump log that canplayer replays (canplayer -I replay.log); prints a JSON summary\n"
    "  mml-candev live ... --iface vcan0   (the same options, no --out): sends the frames onto the\n"
    "      SocketCAN interface with their timing\n"
    "  mml-candev score --dataset aces|--log PATH --capture dump.log [--first N] [--count N]\n"
    "                   [--bound M] [--json out.json]\n"
    "      decodes mmlfw's POSE/HEALTH frames from candump -L output and scores them against the\n"
    "      log's reference trajectory\n";

static int run_main(int argc, char** argv) {
  if (argc >= 2 && (std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h")) {
    std::fputs(kHelp, stdout);
    return 0;
  }
  if (argc < 2) return usage("missing command");
  const std::string cmd = argv[1];
  Args a;
  if (const std::optional<int> exit_code = parse_options(argc, argv, &a)) return *exit_code;
  std::string err;
  Numbers n;
  if (!read_numbers(a, &n, &err)) return usage(err.c_str());
  sim::CarmenLog log;
  std::string poses_path;
  if (!load_log(a, &log, &err, &poses_path)) {
    std::fprintf(stderr, "mml-candev: %s\n", err.c_str());
    return 1;
  }
  const std::string iface = a.get("iface", "vcan0");
  if (cmd == "log2can" || cmd == "live") return run_traffic(cmd, a, n, log, iface);
  if (cmd == "score") return run_score(a, n, log, poses_path);
  return usage(("unknown command '" + cmd + "'").c_str());
}

int main(int argc, char** argv) {
  return sim::guarded_main("mml-candev", [&] { return run_main(argc, argv); });
}
