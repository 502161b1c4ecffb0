// mml-sim: the simulator CLI. See sim_args.cpp for the options and sim_runner.h for what it does.
#include <cstdio>
#include <string>
#include <vector>

#include "firmware/base/fault.h"
#include "sim/cli/sim_args.h"
#include "sim/cli/sim_runner.h"
#include "sim/common/cli_main.h"

namespace {
void fatal_fault(fw::Fault fault, std::uint32_t bits) {
  // Bad programming is fatal in the simulator (ArduPilot's internal-error policy).
  std::fprintf(stderr, "mml-sim: FATAL firmware fault '%s' (bits 0x%x)\n", fw::fault_name(fault), bits);
  std::fflush(stderr);
  std::abort();
}
}  // namespace

static int run_main(int argc, char** argv) {
  fw::set_fault_handler(&fatal_fault);
  std::vector<std::string> args(argv + 1, argv + argc);
  sim::SimConfig cfg;
  sim::SimArgsAction action;
  std::string err;
  if (!sim::parse_sim_args(args, &cfg, &action, &err)) {
    std::fprintf(stderr, "mml-sim: %s\n", err.c_str());
    return 2;
  }
  if (action == sim::SimArgsAction::kHelp) {
    std::fputs(sim::sim_usage().c_str(), stdout);
    return 0;
  }
  if (action == sim::SimArgsAction::kList) {
    std::fputs(sim::sim_list().c_str(), stdout);
    return 0;
  }
  sim::SimResult result;
  if (!cfg.blackbox.replay_path.empty()) {  // issue 60: the black box fed back, poses compared
    sim::BlackBoxReplay replay;
    if (!sim::replay_black_box(cfg, &result, &replay, &err)) {
      std::fprintf(stderr, "mml-sim: %s\n", err.c_str());
      return 1;
    }
    if (!replay.global_mismatch.empty()) std::fprintf(stderr, "mml-sim: %s\n", replay.global_mismatch.c_str());
    std::string serial =
        replay.rx_serial_lines > 0 ? std::to_string(replay.rx_serial_lines) + " rx serial chunks, " : std::string();
    if (replay.global_records > 0) serial += std::to_string(replay.global_records) + " global records, ";
    std::printf("mml-sim replay-blackbox: %zu rx frames, %s%zu POSE frames recorded, %zu replayed: %s\n", replay.rx_frames,
                serial.c_str(),
                replay.recorded_pose_frames, replay.replayed_pose_frames,
                replay.identical ? "identical" : ("differ from frame " + std::to_string(replay.first_difference)).c_str());
    return replay.identical ? 0 : 1;
  }
  if (!sim::run_simulation(cfg, &result, &err)) {
    std::fprintf(stderr, "mml-sim: %s\n", err.c_str());
    return 1;
  }
  if (!cfg.out_dir.empty()) {
    std::fprintf(stderr, "mml-sim: wrote %s/steps.csv, summary.json%s\n", cfg.out_dir.c_str(),
                 cfg.pictures ? ", run.svg, run.png" : "");
  }
  // Last, on stdout (for scripts): fix, availability, integrity, protection level, kidnap, final error.
  std::fflush(stderr);
  std::printf("%s\n", sim::summary_line(result.summary).c_str());
  return 0;
}

int main(int argc, char** argv) {
  return sim::guarded_main("mml-sim", [&] { return run_main(argc, argv); });
}
