#include "sim/cli/ctl_commands.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "hal_can/codec.h"

namespace sim {
namespace {

bool number(const std::string& what, const std::string& v, double lo, double hi, double* out, std::string* err) {
  char* end = nullptr;
  *out = std::strtod(v.c_str(), &end);
  if (v.empty() || *end != '\0' || !std::isfinite(*out) || *out < lo || *out > hi) {
    *err = what + ": '" + v + "' is not a number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    return false;
  }
  return true;
}

// X Y THETA_DEG [SIGMA_M SIGMA_DEG] from pos[k...].
bool parse_hint(const std::vector<std::string>& pos, std::size_t k, hal::PoseHint* h, std::string* err) {
  if (pos.size() != k + 3 && pos.size() != k + 5) {
    *err = "a hint is X Y THETA_DEG [SIGMA_M SIGMA_DEG]";
    return false;
  }
  double v[5] = {0, 0, 0, 0.2, 5.0};
  static const char* const kNames[] = {"x", "y", "theta", "sigma_m", "sigma_deg"};
  static const double kLo[] = {-2e6, -2e6, -360, 0.001, 0.01}, kHi[] = {2e6, 2e6, 360, 65, 360};
  for (std::size_t i = 0; k + i < pos.size(); ++i) {
    if (!number(kNames[i], pos[k + i], kLo[i], kHi[i], &v[i], err)) return false;
  }
  h->x = static_cast<float>(v[0]);
  h->y = static_cast<float>(v[1]);
  h->theta = static_cast<float>(v[2] * M_PI / 180.0);
  h->sigma_xy_m = static_cast<float>(v[3]);
  h->sigma_theta_rad = static_cast<float>(v[4] * M_PI / 180.0);
  return true;
}

bool flag_value(const std::vector<std::string>& args, std::size_t* i, std::string* v, std::string* err) {
  if (*i + 1 >= args.size()) {
    *err = args[*i] + " needs a value";
    return false;
  }
  *v = args[++*i];
  return true;
}

}  // namespace

std::string ctl_usage() {
  return "usage: mml-ctl [--iface can0] [--fd] [--seq N] [--timeout-ms MS] [--print] COMMAND\n"
         "  hint X Y THETA_DEG [SIGMA_M SIGMA_DEG] [--map ID]   SET_POSE_HINT (sigma default 0.2 m, 5 deg)\n"
         "  select-map ID [X Y THETA_DEG [SIGMA_M SIGMA_DEG]] [--reload]   SELECT_MAP, optionally with a hint;\n"
         "                                                      --reload: the firmware reads the map's image\n"
         "                                                      from disk again first (checked; a broken one is\n"
         "                                                      refused, the map in use stays)\n"
         "  dump-log                                            DUMP_LOG: write the black box now\n"
         "Sends the command on IFACE (SocketCAN) and prints the firmware's COMMAND_REPLY (exit 0 when\n"
         "accepted or done, 1 when refused or no reply within the timeout). --print: only print the\n"
         "frames as cansend arguments (hal/can/README.md \"Commands\").\n";
}

bool parse_ctl_args(const std::vector<std::string>& args, CtlArgs* out, std::string* err) {
  *out = CtlArgs();
  std::vector<std::string> pos;
  double map_id = 0, seq = 0, timeout = 1000;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    std::string v;
    if (a == "--fd") {
      out->fd = true;
    } else if (a == "--reload") {
      out->command.reload = true;
    } else if (a == "--print") {
      out->print = true;
    } else if (a == "--iface" || a == "--map" || a == "--seq" || a == "--timeout-ms") {
      if (!flag_value(args, &i, &v, err)) return false;
      if (a == "--iface") out->iface = v;
      if (a == "--map" && !number("--map", v, 0, 255, &map_id, err)) return false;
      if (a == "--seq" && !number("--seq", v, 0, 255, &seq, err)) return false;
      if (a == "--timeout-ms" && !number("--timeout-ms", v, 1, 60000, &timeout, err)) return false;
    } else if (a.size() > 1 && a[0] == '-' && !(a[1] >= '0' && a[1] <= '9') && a[1] != '.') {
      *err = "unknown option '" + a + "'";
      return false;
    } else {
      pos.push_back(a);
    }
  }
  if (pos.empty()) {
    *err = "no command (hint, select-map or dump-log)";
    return false;
  }
  hal::Command& c = out->command;
  if (c.reload && pos[0] != "select-map") {
    *err = "--reload goes with select-map only";
    return false;
  }
  c.seq = static_cast<std::uint8_t>(seq);
  out->timeout_ms = static_cast<int>(timeout);
  if (pos[0] == "hint") {
    c.kind = hal::CommandKind::kSetPoseHint;
    c.has_hint = true;
    c.hint.map_id = static_cast<std::uint8_t>(map_id);
    return parse_hint(pos, 1, &c.hint, err);
  }
  if (pos[0] == "select-map") {
    c.kind = hal::CommandKind::kSelectMap;
    if (pos.size() < 2 || !number("map id", pos[1], 0, 255, &map_id, err)) {
      if (err->empty()) *err = "select-map needs a map id";
      return false;
    }
    c.map_id = static_cast<std::uint8_t>(map_id);
    c.has_hint = pos.size() > 2;
    c.hint.map_id = c.map_id;
    return !c.has_hint || parse_hint(pos, 2, &c.hint, err);
  }
  if (pos[0] == "dump-log" && pos.size() == 1) {
    c.kind = hal::CommandKind::kDumpLog;
    return true;
  }
  *err = "unknown command '" + pos[0] + "' (hint, select-map, dump-log)";
  return false;
}

std::string cansend_arg(const std::string& iface, const hal::CanFrame& f) {
  char buf[200];
  int n = std::snprintf(buf, sizeof(buf), "%s %03X%s", iface.c_str(), static_cast<unsigned>(f.id),
                        f.fd ? (f.brs ? "##1" : "##0") : "#");
  for (int i = 0; i < f.len && n + 3 < static_cast<int>(sizeof(buf)); ++i) n += std::snprintf(buf + n, sizeof(buf) - n, "%02X", f.data[i]);
  return std::string(buf, static_cast<std::size_t>(n));
}

bool ctl_frames(const CtlArgs& a, std::vector<hal::CanFrame>* out, std::string* err) {
  hal::CanFrame f[hal_can::kMaxParts];
  std::size_t n = 0;
  const fw::Status s = hal_can::encode_command(a.command, a.fd, f, hal_can::kMaxParts, &n);
  if (!s.is_ok()) {
    *err = s.message();
    return false;
  }
  out->assign(f, f + n);
  return true;
}

std::string describe_reply(const hal::CommandReply& r) {
  return "seq " + std::to_string(r.seq) + " " + hal::command_name(r.kind) + ": " + hal::command_result_name(r.result) +
         " (active map " + std::to_string(r.detail) + ")";
}

}  // namespace sim
