// mml-ctl's arguments → operator commands (hal/msg/command.h) and their frames as `cansend`
// arguments (issue 60). Separate from main() so the tests can feed it bad input.
#pragma once

#include <string>
#include <vector>

#include "hal/can_bus.h"
#include "hal/msg/command.h"

namespace sim {

struct CtlArgs {
  std::string iface = "can0";
  bool fd = false;
  bool print = false;     // --print: the frames as cansend arguments, nothing sent
  int timeout_ms = 1000;  // wait for COMMAND_REPLY
  hal::Command command;
};

// false with *err naming the argument (a NaN, a σ ≤ 0, an unknown command: never a frame).
bool parse_ctl_args(const std::vector<std::string>& args, CtlArgs* out, std::string* err);
std::string ctl_usage();
// "IFACE 140#0700..." (classic) or "IFACE 540##1...": what `cansend` takes.
std::string cansend_arg(const std::string& iface, const hal::CanFrame& f);
// The frames of the command (hal/can codec); false with *err when the encoder refuses it.
bool ctl_frames(const CtlArgs& a, std::vector<hal::CanFrame>* out, std::string* err);
// "seq 7 SET_POSE_HINT: accepted (active map 0)".
std::string describe_reply(const hal::CommandReply& r);

}  // namespace sim
