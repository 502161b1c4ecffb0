#include "sim/cli/operator_sim.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <utility>

#include "hal_can/codec.h"
#include "sim/devices/candump_log.h"
#include "sim/devices/global_log_line.h"
#include "sim/devices/serial_log_line.h"

namespace sim {

hal::Command hint_command(const HintOptions& o, const fw::Se2d& truth, std::uint8_t seq) {
  hal::Command c;
  c.kind = hal::CommandKind::kSetPoseHint;
  c.seq = seq;
  c.has_hint = true;
  const fw::Se2d p = o.absolute ? o.pose : fw::Se2d(truth.x + o.pose.x, truth.y + o.pose.y, truth.theta + o.pose.theta);
  c.hint.x = static_cast<float>(p.x);
  c.hint.y = static_cast<float>(p.y);
  c.hint.theta = static_cast<float>(fw::wrap_angle(p.theta));
  c.hint.sigma_xy_m = static_cast<float>(o.sigma_m);
  c.hint.sigma_theta_rad = static_cast<float>(o.sigma_rad);
  return c;
}

bool DirectCommands::poll(hal::Command* out) {
  if (queue_.empty()) return false;
  *out = queue_.front();
  queue_.pop_front();
  return true;
}

void BlackBoxTee::publish(const hal::PoseEstimate& e) {
  hal::CanFrame f[hal_can::kMaxParts];
  std::size_t n = 0;
  if (hal_can::encode_pose(e, tag_++, false, f, hal_can::kMaxParts, &n).is_ok()) {
    for (std::size_t i = 0; i < n; ++i) box_->record(f[i], e.timestamp_ns / 1000 * 1000, true);
  }
  inner_->publish(e);
}

void BlackBoxTee::publish_reply(const hal::CommandReply& r) {
  hal::CanFrame f;
  hal_can::encode_reply(r, &f);
  box_->record(f, 0, true);
  inner_->publish_reply(r);
}

namespace {
// "(SEC.USEC)" as integer ns: a double loses the µs of an epoch-sized stamp.
bool parse_stamp_ns(const std::string& line, std::uint64_t* ns) {
  unsigned long long sec = 0, usec = 0;
  char close = 0;
  if (std::sscanf(line.c_str(), "(%llu.%6llu%c", &sec, &usec, &close) != 3 || close != ')') return false;
  *ns = (sec * 1000000ull + usec) * 1000ull;
  return true;
}
bool is_pose_frame(const hal::CanFrame& f) {
  return (f.id >= 0x120 && f.id <= 0x125) || f.id == (0x120 | 0x400);
}
}  // namespace

bool read_black_box(const std::string& path, std::vector<BlackBoxLine>* out, std::string* err) {
  out->clear();
  std::ifstream in(path);
  if (!in) {
    *err = "--replay-blackbox: cannot read '" + path + "'";
    return false;
  }
  std::string line;
  std::size_t no = 0;
  while (std::getline(in, line)) {
    ++no;
    if (line.empty()) continue;
    if (is_global_log_line(line)) {
      BlackBoxLine b;
      std::string why;
      if (!parse_global_log_line(line, &b.record, &why)) {
        *err = path + ":" + std::to_string(no) + ": not a black box line (" + why + ")";
        return false;
      }
      b.global = true;
      b.line_no = no;
      b.frame.timestamp_ns = b.record.scan_ns;
      out->push_back(std::move(b));
      continue;
    }
    if (is_serial_log_line(line)) {
      SerialLogLine sl;
      std::string why;
      if (!parse_serial_log_line(line, &sl, &why)) {
        *err = path + ":" + std::to_string(no) + ": not a black box line (" + why + ")";
        return false;
      }
      BlackBoxLine b;
      b.serial = true;
      b.tx = sl.tx;
      b.frame.timestamp_ns = sl.t_ns;
      b.bytes.swap(sl.bytes);
      b.line_no = no;
      out->push_back(std::move(b));
      continue;
    }
    CanLogLine l;
    std::string why;
    std::uint64_t ns = 0;
    if (!parse_candump_line(line, &l, &why) || !parse_stamp_ns(line, &ns) || (l.iface != "rx" && l.iface != "tx")) {
      *err = path + ":" + std::to_string(no) + ": not a black box line (" +
             (why.empty() ? "interface must be rx or tx" : why) + ")";
      return false;
    }
    BlackBoxLine b;
    b.frame = l.frame;
    b.frame.timestamp_ns = ns;
    b.tx = l.iface == "tx";
    b.line_no = no;
    out->push_back(b);
  }
  return true;
}

std::vector<hal::CanFrame> pose_frames(const std::vector<BlackBoxLine>& lines) {
  std::vector<hal::CanFrame> out;
  for (const BlackBoxLine& l : lines)
    if (l.tx && !l.serial && !l.global && is_pose_frame(l.frame)) out.push_back(l.frame);
  return out;
}

std::vector<hal::CanFrame> pose_frames(const hal_can::BlackBox& box) {
  std::vector<hal::CanFrame> out;
  for (std::size_t i = 0; i < box.size(); ++i) {
    const hal_can::BlackBoxEntry& e = box.entry(i);
    if (e.is_global()) continue;
    const hal::CanFrame f = hal_can::BlackBox::frame_of(e);
    if ((e.flags & hal_can::BlackBoxEntry::kTx) && is_pose_frame(f)) out.push_back(f);
  }
  return out;
}

bool same_frames(const std::vector<hal::CanFrame>& a, const std::vector<hal::CanFrame>& b,
                 std::size_t* first_difference) {
  const std::size_t n = a.size() < b.size() ? a.size() : b.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (a[i].id != b[i].id || a[i].len != b[i].len || a[i].fd != b[i].fd ||
        std::memcmp(a[i].data, b[i].data, a[i].len) != 0) {
      *first_difference = i;
      return false;
    }
  }
  *first_difference = n;
  return a.size() == b.size();
}

}  // namespace sim
