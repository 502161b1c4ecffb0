// bench_hal: the figures of the HAL/HIL issue in build/bench/hal.json. Runs the vcan HIL (in the guest
// tests/hil/run-in-guest.sh chooses: user-mode Linux, else QEMU; hil_vcan_guest says which) and the
// serial pty HIL scripts on this build directory, then the 75 Hz host replay with pinned workers
// (budget check), and merges everything into one flat JSON object.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "sim/common/bench_json.h"
#include "sim/common/flat_json_read.h"
#include "tests/hil/replay_budget.h"

using sim::copy_num;
using sim::json_value;
using sim::read_all;

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_hal OUT.json\n");
    return 2;
  }
  std::string exe = argv[0];
  const std::string bench_dir = exe.substr(0, exe.find_last_of('/') == std::string::npos ? 0 : exe.find_last_of('/'));
  const std::string build = (bench_dir.empty() ? std::string(".") : bench_dir) + "/..";
  const std::string src = MMLFW_SOURCE_DIR;
  sim::BenchJson j;

  std::printf("bench_hal: vcan HIL inside a guest (user-mode Linux, else QEMU) ...\n");
  std::fflush(stdout);
  const int vrc = std::system(("bash " + src + "/tests/hil/hil_vcan.sh " + build + " > " + build + "/hil_vcan.log 2>&1").c_str());
  const std::string v = read_all(build + "/hil/vcan/results.json");
  j.add_bool("hil_vcan_passed", vrc == 0);
  // The guest ("uml" | "qemu"; "none" when none could start) and QEMU's accelerator (tcg | kvm).
  std::string guest = read_all(build + "/hil/vcan/guest");
  while (!guest.empty() && (guest.back() == '\n' || guest.back() == ' ')) guest.pop_back();
  if (guest.empty()) guest = "none";
  const size_t dash = guest.find('-');
  j.add_string("hil_vcan_guest", guest.substr(0, dash));
  if (dash == std::string::npos) {
    j.add_raw("hil_vcan_guest_accel", "null");
  } else {
    j.add_string("hil_vcan_guest_accel", guest.substr(dash + 1));
  }
  for (const char* k : {"hil_vcan_scans_sent", "hil_vcan_scans_decoded", "hil_vcan_scans_processed", "hil_vcan_localized",
                        "hil_vcan_localized_scans", "hil_vcan_availability", "hil_vcan_pose_err_m", "hil_vcan_pose_err_all_m", "hil_fd_ok",
                        "hil_classic_ok", "hil_canplayer_ok", "hil_faults_passed", "hil_dbc_poses_decoded",
                        "hil_vcan_guest_seconds", "hil_vcan_first_localized_scan", "hil_classic_scans_decoded",
                        "corrupt_segments_counted", "fault_scans_faulty", "fault_crc_errors",
                        "fault_bus_off", "fault_wrong_localized"}) {
    copy_num(j, v, k);
  }
  std::printf("bench_hal: serial HIL over a socat pty pair ...\n");
  std::fflush(stdout);
  const int src_rc = std::system(("bash " + src + "/tests/hil/hil_serial.sh " + build + " > " + build + "/hil_serial.log 2>&1").c_str());
  const std::string s = read_all(build + "/hil/serial/results.json");
  std::string ok;
  j.add_bool("serial_pty_ok", src_rc == 0 && json_value(s, "serial_pty_ok", &ok) && ok == "true");
  copy_num(j, s, "serial_scans_sent");
  copy_num(j, s, "serial_scans_received");

  // Issue 59: Hokuyo and RPLIDAR over a pty (hil_serial_lidar.sh): clean streams with line faults
  // (every intact answer / turn a scan); the fault runs (truncation, reset mid-scan, clock wrap,
  // motor stop, health error) and unplug/replug: scans resume, no crash, no hang.
  for (const char* sensor : {"hokuyo", "rplidar"}) {
    bool faults_ok = true;
    for (const char* mode : {"clean", "faults", "replug"}) {
      std::printf("bench_hal: %s over a socat pty pair (%s) ...\n", sensor, mode);
      std::fflush(stdout);
      const std::string tag = std::string(sensor) + "-" + mode;
      const int rc = std::system(("bash " + src + "/tests/hil/hil_serial_lidar.sh " + build + " " + sensor + " " + mode +
                                  " > " + build + "/hil_serial_" + tag + ".log 2>&1").c_str());
      const std::string r = read_all(build + "/hil/serial-" + tag + "/results.json");
      std::string v;
      const bool ok = rc == 0 && json_value(r, std::string(sensor) + "_" + mode + "_ok", &v) && v == "true";
      if (std::string(mode) == "clean") {
        j.add_bool(std::string(sensor) + "_pty_ok", ok);
      } else {
        faults_ok = faults_ok && ok;
        j.add_bool(std::string(sensor) + "_" + mode + "_ok", ok);
      }
      for (const char* k : {"_units_sent", "_scans", "_checksum_errors", "_dropped", "_device_restarts"}) {
        copy_num(j, r, std::string(sensor) + "_" + mode + k);
      }
    }
    j.add_bool(std::string(sensor) + "_faults_passed", faults_ok);
  }

  std::printf("bench_hal: 75 Hz host replay (aces, mmlfw's default localizer, 2 pinned workers) ...\n");
  std::fflush(stdout);
  mmlfw_hil::ReplayOptions o;
  mmlfw_hil::ReplayResult r;
  std::string err;
  if (mmlfw_hil::run_replay(o, &r, &err)) {
    j.add("replay_75hz_step_ms_p50", r.step_p50_ms);
    j.add("replay_75hz_step_ms_p99", r.step_p99_ms);
    j.add_int("replay_75hz_deadline_misses", static_cast<long long>(r.deadline_misses));
    j.add_int("replay_75hz_scans_fed", static_cast<long long>(r.scans_fed));
    j.add_int("replay_75hz_scans_processed", static_cast<long long>(r.scans_processed));
    j.add("replay_75hz_processed_rate_hz", r.achieved_rate_hz);
    j.add("static_memory_mib", r.static_memory_mib);
    j.add_int("replay_75hz_localized", static_cast<long long>(r.localized));
    j.add("replay_75hz_availability", r.availability);
    j.add_int("replay_75hz_wrong_localized", static_cast<long long>(r.wrong_localized));
    std::map<std::string, double> budget;
    if (mmlfw_hil::read_budget(src + "/firmware/app/budget.txt", &budget, &err)) {
      j.add_int("budget_violations", static_cast<long long>(mmlfw_hil::check_budget(budget, r).size()));
    }
  } else {
    std::fprintf(stderr, "bench_hal: replay failed: %s\n", err.c_str());
    j.add("replay_75hz_step_ms_p99", std::nan(""));
  }
  return j.write(argv[1]) ? 0 : 1;
}
