// mml-ctl: the operator's commands on the robot's bus (issue 60; ctl_commands.h, hal/can/README.md
// "Commands"): SET_POSE_HINT, SELECT_MAP, DUMP_LOG, then the firmware's COMMAND_REPLY.
#include <time.h>

#include <cstdio>
#include <string>
#include <vector>

#include "hal_can/codec.h"
#include "hal_socketcan/socketcan_bus.h"
#include "sim/cli/ctl_commands.h"
#include "sim/common/cli_main.h"

namespace {

double now_s() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

int run_main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.size() == 1 && (args[0] == "--help" || args[0] == "-h")) {
    std::fputs(sim::ctl_usage().c_str(), stdout);
    return 0;
  }
  sim::CtlArgs a;
  std::string err;
  std::vector<hal::CanFrame> frames;
  if (!sim::parse_ctl_args(args, &a, &err) || !sim::ctl_frames(a, &frames, &err)) {
    std::fprintf(stderr, "mml-ctl: %s\n%s", err.c_str(), sim::ctl_usage().c_str());
    return 2;
  }
  if (a.print) {
    for (const hal::CanFrame& f : frames) std::printf("cansend %s\n", sim::cansend_arg(a.iface, f).c_str());
    return 0;
  }
  hal_socketcan::SocketCanBus bus;
  hal_socketcan::SocketCanOptions o;
  o.want_fd = a.fd;
  o.require_fd = a.fd;
  o.filters[0] = {hal_can::kCommandReplyId, 0x7FF, false};
  o.num_filters = 1;
  const fw::Status st = bus.open(a.iface.c_str(), o);
  if (!st.is_ok()) {
    std::fprintf(stderr, "mml-ctl: %s\n", st.message());
    return 1;
  }
  for (const hal::CanFrame& f : frames) {
    if (!bus.send(f)) {
      std::fprintf(stderr, "mml-ctl: send on %s failed\n", a.iface.c_str());
      return 1;
    }
  }
  hal_can::Decoder d;
  const double deadline = now_s() + a.timeout_ms * 1e-3;
  hal::CanFrame f;
  while (now_s() < deadline) {
    if (!bus.receive(&f)) {
      const timespec nap{0, 2000000};
      nanosleep(&nap, nullptr);
      continue;
    }
    if (d.feed(f) == hal_can::Decoded::kReply && d.reply().seq == a.command.seq && d.reply().kind == a.command.kind) {
      std::printf("mml-ctl: %s\n", sim::describe_reply(d.reply()).c_str());
      const hal::CommandResult r = d.reply().result;
      return r == hal::CommandResult::kAccepted || r == hal::CommandResult::kDone ? 0 : 1;
    }
  }
  std::fprintf(stderr, "mml-ctl: no COMMAND_REPLY to seq %u on %s within %d ms\n", a.command.seq, a.iface.c_str(),
               a.timeout_ms);
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  return sim::guarded_main("mml-ctl", [&] { return run_main(argc, argv); });
}
